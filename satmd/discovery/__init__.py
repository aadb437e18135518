"""Missing-physics discovery: locate the mismatch, name the missing physics, model it.

>>> from satmd import simulate, effect, discover
>>> data = simulate(effects=[effect("time_delay", tau_s=3e-4)], noise=(0.01, 0.002), seed=1)
>>> discover(data).effect_names
['time_delay']

Steps (each module says how):
1. fit the nominal model globally (`satmd.identify`);
2. noise from the std columns, or estimated (`noise.py`);
3. locate and decide with calibrated χ² tests (`locate.py`);
4. explain: every registered effect is a candidate, started where its own
   declarations say (`candidates.py`); BIC model selection with backward
   elimination, swaps and equivalents (`select.py`). No effect is named here:
   what an effect is, how to search for it and how to say it in words lives
   in its class (`satmd.physics.effects`);
5. when the vocabulary cannot explain a significant mismatch: `unexplained`,
   with a smooth data-driven correction showing how much of it is structured
   (`discrepancy.py`);
6. typed findings (`findings.py`), formatted by the report (`report.py`).
"""
from __future__ import annotations

import time
from functools import partial
from numbers import Real
from typing import Sequence

from ..validation import LOAD_HINT, NAMES, Band, Interval, Whole, check_data, validate_params
from ..conventions import ACCEL_CHANNELS, DEFAULT_FREE, MIN_DELTA_BIC
from .._fleet import fleet_map
from ..identification import identify
from ..io.frfdata import FRFData, require_data
from ..physics import Rig
from .adequacy import (Reason, after_search, assess_fit, drop_stretched, implausible_within_noise, inadequate_report,
                       rescued_by_one_effect, withdraw_if_inadequate)
from .budget import bias_note, evidence_beyond_bias
from .candidates import default_candidates
from .discrepancy import fit_discrepancy
from .findings import UNEXPLAINED, EffectFinding, Judged, UnexplainedFinding
from .locate import test_mismatch
from .noise import estimate_std
from .report import SCHEMA, DiscoveryReport, describe_effect, describe_unexplained
from .select import Model, Search, equivalents
from .select import select as select_effects

__all__ = ["discover", "discover_many", "DiscoveryReport", "EffectFinding", "UnexplainedFinding",
           "SCHEMA"]


@validate_params({"rig": [None, Rig], "free": [NAMES], "candidates": [None, NAMES], "channels": [None, NAMES],
                  "alpha": [Interval(Real, 0, 1, "both")], "max_effects": [Interval(Whole, 0)],
                  "band_hz": [None, Band(open_ends=True)], "fit_joint": [bool]})
def discover(
    data,
    rig: Rig | None = None,
    free: Sequence[str] = DEFAULT_FREE,
    candidates: Sequence[str] | None = None,
    channels: Sequence[str] | None = None,
    alpha: float = 1e-3,
    max_effects: int = 3,
    band_hz=None,
    fit_joint: bool = True,
) -> DiscoveryReport:
    """Find what physics the nominal model leaves out of ``data``.

    Parameters
    ----------
    data : FRFData, Recording, or a list of them
        Measured FRFs, or a force/acceleration recording: its FRFs are then
        estimated by `satmd.signal.estimate_frf` (local polynomial method, std from
        the recording's own noise). For FRFs estimated from a recording the
        report adds ``estimator`` and the ``measurement`` findings of the chain,
        kept apart from physics. A recording is also tested for nonlinear
        distortion; a list of recordings (or FRFData) of one rig at several
        levels, or repeats, is judged together (`satmd.discovery.nonlinear.levels`): the
        report then has a ``nonlinear`` block (SPEC §9).
    rig : values of the fixed parameters (default: the paper's rig).
    free : parameters fitted in every model (default m2, kp, R, L).
    candidates : effect names to consider (default: every registered effect).
    channels : channels to fit (default a1, a2 when present, else all).
    alpha : level of the mismatch test (global and band-wise together).
    max_effects : most effects a model may hold.
    band_hz : (lo, hi) Hz, either None for open: the band a recording's FRFs are estimated in (default:
        the band the force excites); FRFData are cut to it.
    fit_joint : recordings of a structure at several levels: fit the located joint's model on every level
        (`satmd.structure.fit_structure`, minutes on two cores; default), else place and name it only (seconds;
        refused for one recording or FRFs, which have no joint to place).

    Returns
    -------
    DiscoveryReport
    """
    from dataclasses import replace

    from ..io.recording import Recording

    check_data(data, "data", (FRFData, Recording), "discover", many=True, hint=LOAD_HINT)
    several = isinstance(data, (list, tuple)) and sum(isinstance(x, Recording) for x in data) >= 2
    if not fit_joint and not several:
        from ..errors import SatmdError

        raise SatmdError("fit_joint=False places a structure's joint without its model: it applies to recordings at "
                         "two or more levels, not to one recording or to FRFs")
    if isinstance(data, (list, tuple)):  # several recordings of one rig: judged together (issue 26)
        from .nonlinear.levels import discover_recordings

        data = [_with_excitation(part) for part in data]
        return discover_recordings(data, discover, rig=rig, free=free, alpha=alpha, candidates=candidates,
                                   channels=channels, max_effects=max_effects, fit_joint=fit_joint)
    recording = data if isinstance(data, Recording) else None
    if recording is not None:
        from ..signal.estimate import estimate_frf
        from ..signal.excitation import received

        # the excitation is read once and travels with the recording: the FRF and the linearity test agree
        recording = data = received(data)
        data = estimate_frf(data, band_hz=band_hz)
    elif band_hz is not None:
        data = data.band(*band_hz)
    report = _discover_frf(data, rig, free, candidates, channels, alpha, max_effects)
    if not data.estimator:
        return report
    report = replace(report, estimator=dict(data.estimator),
                     notes=list(data.estimator.get("measurement", [])) + list(report.notes))
    if recording is not None:  # one recording: is it linear at all? (issue 26)
        from .nonlinear.levels import check_one

        report = check_one(report, recording, alpha, rig, free)
    return report


def _with_excitation(part):
    """A recording with its excitation read (FRFData as it is)."""
    from ..signal.excitation import received
    from ..io.recording import Recording

    return received(part) if isinstance(part, Recording) else part


def _discover_one(data, kwargs):
    return discover(data, **kwargs)


@validate_params({"progress": [bool], "chunksize": [Interval(Whole, 1)]})
def discover_many(datas: Sequence, executor=None, progress: bool = False, chunksize: int = 1,
                  **kwargs) -> list[DiscoveryReport]:
    """Run `discover` on every dataset in ``datas`` (same keyword arguments).

    Parameters
    ----------
    datas : sequence of FRFData or Recording
        One discovery each.
    executor : concurrent.futures.Executor or None
        A ProcessPoolExecutor spreads the fleet over cores, a Dask
        ``distributed.Client(address).get_executor()`` over machines; None runs
        in this process. The reports are the serial ones bit for bit (apart
        from their ``wall_time``).
    progress : show progress on stderr.
    chunksize : datasets sent to a worker as one task.
    **kwargs :
        Passed to `discover` (rig, free, candidates, channels, alpha, max_effects).

    Returns
    -------
    list of DiscoveryReport
        In input order.
    """
    from ..io.recording import Recording

    datas = list(datas)
    for i, d in enumerate(datas):
        for j, part in enumerate(d if isinstance(d, (list, tuple)) else [d]):
            require_data(part, f"datas[{i}]" + (f"[{j}]" if isinstance(d, (list, tuple)) else ""), FRFData, Recording)
    return fleet_map(partial(_discover_one, kwargs=kwargs), datas, executor, chunksize, progress, "discover",
                     "dataset")


def _discover_frf(data: FRFData, rig, free, candidates, channels, alpha, max_effects) -> DiscoveryReport:
    """`discover` on FRFData (parameters as `discover`): the steps of the module docstring."""
    t0 = time.perf_counter()
    rig = Rig() if rig is None else rig
    free = tuple(free)
    channels = tuple(channels) if channels else tuple(c for c in ACCEL_CHANNELS if c in data.channels) or data.names
    data = data.select(channels)
    candidates = tuple(candidates) if candidates else default_candidates()

    nominal_fit = identify(data, rig, free, channels, warn=False)
    verdict = assess_fit(nominal_fit)  # can the SATMD model describe these data at all? (adequacy.py)
    search = Search(data, rig, free, channels, candidates) if data.has_std else None
    if not verdict.adequate and not (search is not None and rescued_by_one_effect(verdict, search,
                                                                                  Model((), [], nominal_fit), rig)):
        return inadequate_report(verdict, nominal_fit, alpha, t0)
    noise, noise_dof = "given", None
    if data.estimator.get("noise_dof"):  # an estimated std (Welch averages, LPM residuals): F tests keep α
        noise_dof = data.estimator.get("noise_dof")
    if not data.has_std:
        noise = "estimated"
        data = data.with_std(estimate_std(data, nominal_fit))
        noise_dof = 2 * len(channels) * (len(data) - 2)
        nominal_fit = identify(data, rig, free, channels, start=nominal_fit.values, global_search=False, warn=False)
    test0 = test_mismatch(nominal_fit, alpha, noise_dof)
    before = _fit_summary(nominal_fit)
    p_values = {"global": test0.p_global, "band": test0.p_band}
    if not test0.significant:  # the nominal fit is the best fit: judged as `identify` judges it (one verdict)
        report = DiscoveryReport(significant_mismatch=False, noise=noise, mismatch_bands_hz=test0.bands_hz,
                                 judged=(), parameters=dict(nominal_fit.values), fit_before=before, fit_after=before,
                                 nominal_fit=nominal_fit, final_fit=nominal_fit, discrepancy=None, p_values=p_values,
                                 whiteness=test0.whiteness, wall_time=time.perf_counter() - t0)
        return withdraw_if_inadequate(report, implausible_within_noise(nominal_fit, rig))

    nominal = Model((), [], nominal_fit)
    if search is None or search.data is not data:  # the std was estimated: the search runs on the new data
        search = Search(data, rig, free, channels, candidates)

    def significant(fit):
        return test_mismatch(fit, alpha, noise_dof).significant

    final = select_effects(search, nominal, significant, max_effects)
    # a good, plausible nominal fit: a candidate the search stretches is left out, not held against the model
    search, final, stretched = drop_stretched(search, nominal, final, rig)
    judged = [Judged(name, "set_aside", tuple(reasons) or (Reason("implausible", "stretched past a plausible magnitude"),))
              for name, reasons in stretched.items()]
    if final.names:
        equiv = equivalents(search, final, nominal)
        without = {n: search.remove(final, n, nominal) for n in final.names}
        dbic = {n: m.bic - final.bic for n, m in without.items()}
        for name in sorted(final.names, key=lambda n: -dbic[n]):
            eff = final.effects[final.names.index(name)]
            # what accounting for this effect does to the free parameters (vs the model without it)
            ref = without[name].fit.values
            shifts = {k: final.fit.values[k] / ref[k] - 1 for k in free if ref[k]}
            finding = EffectFinding(name=name, parameters={k: float(v) for k, v in eff.params.items()
                                                           if search.measured(k)},
                                    equivalent=equiv[name], delta_bic=round(float(dbic[name]), 2),
                                    explanation=describe_effect(eff, rig, shifts), shifts=shifts)
            evidence = evidence_beyond_bias(final.fit, without[name].fit, data.bias_bound)
            if evidence <= MIN_DELTA_BIC:  # the estimator's own bias could make it: kept in the fit, not named
                note = bias_note(name, finding.explanation, evidence, data.bias_bound)
                judged.append(Judged(name, "measurement", (Reason("within_estimator_bias", note["explanation"],
                                                                  {"delta_bic_beyond_bias": evidence}),),
                                     finding, note))
            else:
                judged.append(Judged(name, finding=finding))
    after = _fit_summary(final.fit)
    test1 = test_mismatch(final.fit, alpha, noise_dof)
    disc = None
    if test1.significant:
        disc = _unexplained(final.fit)
        structured = disc.structured_fraction
        dof = max(final.fit.dof - disc.n_parameters, 1)
        after = {"chi2_reduced": disc.chi2_after / dof, "rel_error": _rel_error(final.fit, disc)}
        n_terms = sum(disc.terms.values())
        finding = UnexplainedFinding(
            name=UNEXPLAINED, parameters={}, equivalent=[],
            delta_bic=round(float(final.fit.chi2 - disc.chi2_after - disc.n_parameters * _log_n(final.fit)), 2),
            explanation=describe_unexplained(test1.bands_hz, structured, n_terms),
            bands_hz=test1.bands_hz, structured_fraction=structured, n_terms=n_terms)
        if structured < NOISE_LIKE:
            # no smooth structure left to take: a statement about the noise model, not about physics
            note = _noise_like(final.fit)
            judged.append(Judged(UNEXPLAINED, "measurement", (Reason("noise_like", note["explanation"],
                                                                     {"structured_fraction": structured}),),
                                 finding, note))
        else:
            judged.append(Judged(UNEXPLAINED, finding=finding))
    p_values.update({"global_after": test1.p_global, "band_after": test1.p_band})
    report = DiscoveryReport(significant_mismatch=True, noise=noise, mismatch_bands_hz=test0.bands_hz,
                             judged=tuple(judged), parameters={k: final.fit.values[k] for k in free},
                             fit_before=before, fit_after=after, nominal_fit=nominal_fit, final_fit=final.fit,
                             discrepancy=disc, p_values=p_values, whiteness=test0.whiteness,
                             wall_time=time.perf_counter() - t0)
    return withdraw_if_inadequate(report, after_search(final.fit, final.effects, rig, disc))


#: A residual whose smooth correction removes less than this share of the excess χ² is noise-like.
NOISE_LIKE = 0.05


def _noise_like(fit) -> dict:
    """The measurement note for a significant but noise-like residual: the std is too small."""
    ratio = float(fit.chi2_reduced) ** 0.5
    return {"name": "noise_underestimated",
            "explanation": f"the residual is significant (χ²_red {fit.chi2_reduced:.2f}) but noise-like: no smooth "
                           f"correction takes any of it, so the noise std looks about {100 * (ratio - 1):.0f} % "
                           "too small rather than physics missing",
            "remedy": "more averages or a longer record for the noise estimate; check the std columns",
            "corrected": False}


def _fit_summary(fit) -> dict:
    return {"chi2_reduced": float(fit.chi2_reduced), "rel_error": float(fit.rel_error)}


def _log_n(fit):
    import numpy as np

    return float(np.log(fit.n_data))


def _unexplained(fit):
    residual = {c: -r for c, r in fit.residuals().items()}  # data - model
    return fit_discrepancy(fit.freq_hz, residual, fit.sigma)


def _rel_error(fit, disc):
    import numpy as np

    model = fit.prediction()
    pred = np.stack([model[c] + disc.correction[c] for c in fit.channels])
    target = np.stack([fit.data[c] for c in fit.channels])
    return float(np.linalg.norm(pred - target) / np.linalg.norm(target))

"""`satmd.tune`: from a model of the rig (a Rig, a fit, a discovery report) to the best setting."""
from __future__ import annotations

import time
from numbers import Real
from typing import Sequence

import numpy as np

from ..validation import Interval, check
from ..conventions import DEFAULT_FREE
from ..errors import DataError
from ..physics.effects import Effect
from ..physics.rig import Rig
from .laws import OPEN_CIRCUIT_R, closed_forms
from .objective import Objective
from .optimiser import DesignSpace, minimise
from .result import TuneResult, db
from .robust import Draws, draws_from_covariance, draws_from_std, robust_optimum

DEFAULT_BAND = (20.0, 200.0)
RIG_FREE = DEFAULT_FREE  # what a Rig reports as its model parameters


def tune(
    model,
    objective: str = "hinf",
    output: str = "u1",
    band: tuple[float, float] = DEFAULT_BAND,
    bounds: dict | None = None,
    design: Sequence[str] = ("R", "L"),
    robust: bool = False,
    quantile: float = 0.95,
    *,
    effects: Sequence[Effect] = (),
    current: dict | None = None,
    uncertainty: dict | None = None,
    n_draws: int = 128,
    n_search: int | None = None,
    n_starts: int = 3,
    closed_form_check: bool = True,
    seed: int = 0,
    force: bool = False,
) -> TuneResult:
    """Best setting of the design variables (the shunt's R and L by default).

    Parameters
    ----------
    model : Rig, FitResult or DiscoveryReport
        The rig to tune. A FitResult is tuned at its fitted values (and its
        covariance serves robust tuning); a DiscoveryReport on its augmented
        model (nominal + the effects found) when it found a significant
        mismatch, else on the nominal fit.
    objective : "hinf" (the true peak of |output| over the band) or "h2"
        (its RMS over the band)
    output : "u1" (primary displacement) or "a1" (primary acceleration as measured)
    band : (lo, hi) in Hz
    bounds : {name: (lo, hi)}; defaults R ∈ [0.1, 1000] Ω, L ∈ [1e-3, 5] H,
        others a decade either side of the current value. Searched in log space.
    design : rig fields to design (any of R, L, kp, cp, m2, ...)
    robust : minimise the ``quantile`` of the objective over draws of the
        uncertain parameters (fit covariance, or ``uncertainty``) instead of
        the nominal objective
    quantile : the quantile minimised by robust tuning (default 0.95)
    effects : effects of the model when ``model`` is a Rig
    current : the current setting {name: value} (default: the model's values)
    uncertainty : {parameter: standard deviation}, independent Gaussian
        draws; overrides the fit covariance
    n_draws : draws for robust tuning (fixed draws: a deterministic objective)
    n_search : Sobol points of the global search (default 512·2^(D−1) for H∞, half that
        for H2, at most 4096)
    n_starts : local Nelder–Mead runs from the best distinct points
    closed_form_check : evaluate the classical closed forms on this rig
    seed : seeds the Sobol design and the draws
    force : tune even when the fit or discovery report says the SATMD model cannot describe the data
        (``model_adequate`` false); without it such a model is refused with a DataError

    Returns
    -------
    TuneResult
    """
    t0 = time.perf_counter()
    q = float(check("quantile", quantile, [Interval(Real, 0.5, 1, "hi")], "tune"))
    verdict = model_verdict(model)
    if verdict is not None and not verdict.adequate and not force:
        raise DataError(f"the SATMD model cannot describe these data: {verdict.summary}; not tuned "
                        "(force=True tunes anyway)")
    rig, effects, source, parameters, uncertain, notes, span = resolve_model(model, effects)
    if verdict is not None and not verdict.adequate:
        notes.append(f"tuned although the SATMD model cannot describe these data (forced): {verdict.summary}")
    obj = Objective(objective, output, tuple(band))
    if span and (obj.band[0] < span[0] or obj.band[1] > span[1]):
        notes.append(f"the band {obj.band[0]:g}–{obj.band[1]:g} Hz reaches beyond the measured "
                     f"{span[0]:.1f}–{span[1]:.1f} Hz: the model extrapolates there")
    design = tuple(design)
    now = {n: float(np.ravel(getattr(rig, n))[0]) for n in design if n in Rig.names()}
    if current:
        unknown = set(current) - set(design)
        if unknown:
            raise DataError(f"current setting given for {sorted(unknown)}, which are not design variables")
        now.update({k: float(v) for k, v in current.items()})
    space = DesignSpace.build(design, now, bounds)
    current_rig = rig.replace(**now)
    dim = space.dim
    if n_search is None:  # the H2 surface is smooth (no ridges): half the points find its basin
        n_search = min(4096, (512 if objective == "hinf" else 256) * 2 ** (dim - 1))
    n_search = int(n_search)

    def nominal_batch(u):
        return np.log(obj(space.apply(rig, space.values(u)), effects))

    def nominal_one(u):
        return float(np.log(obj(space.apply(rig, space.values(u)), effects)[0]))

    draws = make_draws(uncertain, uncertainty, rig, effects, space.names, n_draws, seed) if robust else None
    start_now = np.clip(space.unit([now[n] for n in space.names]), 0, 1)
    best = minimise(nominal_batch, nominal_one, dim, n_search, n_starts, seed, extra_starts=[start_now])
    nfev = best.nfev
    x_nominal = space.values(best.u)
    value = float(np.exp(best.fun))
    current_value = float(obj(current_rig, effects)[0])
    open_value = float(obj(current_rig.replace(R=OPEN_CIRCUIT_R), effects)[0])

    robust_summary = None
    x = x_nominal
    if robust:
        x, robust_summary, n = robust_optimum(obj, space, rig, effects, draws, q, [best.u, *best.starts[1:2]],
                                              now, x_nominal)
        nfev += n
        value = float(obj(space.apply(rig, x), effects)[0])
        notes.append(f"robust: the setting minimises the {100 * q:g} % quantile of the objective over "
                     f"{draws.n} draws; 'value' is the nominal model's at that setting")

    if _is_augmented(model):  # what finding the left-out physics is worth here
        naive = tune(model.nominal_fit, objective, output, obj.band, bounds, design, current=current,
                     n_search=n_search, n_starts=n_starts, closed_form_check=False, seed=seed, force=force)
        at_naive = obj(space.apply(rig, [naive.design[n] for n in space.names]), effects)[0]
        cost = db(float(at_naive) / value)
        notes.append("tuned on the nominal model instead, the setting would be "
                     + ", ".join(f"{k} = {v:.4g}" for k, v in naive.design.items())
                     + f": {cost:.2f} dB worse on the augmented model")
    _, fpk, vpk = obj.evaluate(space.apply(rig, x), effects)
    peaks = tuple(sorted({round(float(f), 4) for f, v in zip(fpk[0], vpk[0]) if v >= 0.1 * vpk[0].max()}))
    hit = space.on_bound(x)
    if hit:
        notes.append(f"{', '.join(hit)} ended on a bound of the search box: widen `bounds` to look further")
    forms = []
    if closed_form_check:
        for c in closed_forms(rig, effects, space.names, objective, obj.band):
            full = dict(now, **c["design"])
            v = float(obj(rig.replace(**full), effects)[0])
            forms.append({**c, "value": v, "gap_db": db(v / value)})
    return TuneResult(
        objective=objective, output=output, band_hz=obj.band, design=space.as_dict(x), value=value,
        current_design=dict(now), current_value=current_value, open_circuit_value=open_value,
        bounds=space.bounds_dict(),
        model_parameters={k: v for k, v in parameters.items() if k not in space.names},
        model_effects=[{"name": e.name, "parameters": {k: float(v) for k, v in e.params.items()}} for e in effects],
        model_source=source, peaks_hz=peaks, closed_forms=tuple(forms), robust=robust_summary, notes=tuple(notes),
        nfev=int(nfev), wall_time=time.perf_counter() - t0, _rig=space.apply(rig, x), _current_rig=current_rig,
        _effects=tuple(effects))


def model_verdict(model):
    """The adequacy verdict (`Adequacy`) a fit or discovery report carries; None for a Rig (a model by
    definition)."""
    from ..discovery.report import DiscoveryReport
    from ..identification.result import FitResult

    if isinstance(model, DiscoveryReport):
        from ..identification.adequacy import Adequacy

        return model.adequacy if model.adequacy is not None else Adequacy(True)
    if isinstance(model, FitResult):
        return model.adequacy
    return None


def _is_augmented(model) -> bool:
    from ..discovery.report import DiscoveryReport

    return (isinstance(model, DiscoveryReport) and model.significant_mismatch and model.final_fit is not None
            and model.final_fit is not model.nominal_fit and bool(model.final_fit.effects))


def resolve_model(model, effects=()):
    """(rig, effects, source, reported parameters, uncertainty (names, values, cov) or None, notes,
    measured frequency span or None)."""
    from ..discovery.findings import UNEXPLAINED
    from ..discovery.report import DiscoveryReport
    from ..identification.result import FitResult

    notes = []
    if isinstance(model, Rig):
        if model.batch_shape != ():
            raise DataError("tune takes a single rig, not a batch")
        model.validate()
        params = {k: float(getattr(model, k)) for k in RIG_FREE}
        return model, list(effects), "the given rig", params, None, notes, None
    if effects:
        raise DataError("effects= is for a Rig model; a fit or discovery report carries its own effects")
    if isinstance(model, DiscoveryReport):
        fit = model.final_fit if model.final_fit is not None else model.nominal_fit
        found = [e["name"] for e in model.effects if e["name"] != UNEXPLAINED]
        if model.significant_mismatch and found:
            source = f"augmented model (nominal + {', '.join(found)}): discovery found a significant mismatch"
            notes.append(f"tuned on the augmented model: {source.split(': ', 1)[1]} and modelled it with "
                         f"{', '.join(found)}")
        elif model.significant_mismatch:
            fit, source = model.nominal_fit, "nominal model (a significant mismatch was found but not explained)"
        else:
            source = "nominal model (discovery found no significant mismatch)"
        if UNEXPLAINED in model.effect_names:
            notes.append("part of the mismatch is unexplained by the vocabulary: the tuning cannot account for it")
        model = fit
        source_prefix = source
    elif isinstance(model, FitResult):
        source_prefix = "identified model"
    else:
        raise DataError(f"model must be a Rig, a FitResult or a DiscoveryReport, got {type(model).__name__}")
    fit = model
    params = {k: float(v) for k, v in fit.values.items()}
    uncertain = (tuple(fit.names), fit.theta, np.asarray(fit.covariance))
    f = fit.freq_hz
    notes.append(f"model identified from {len(f)} points over {f[0]:.1f}–{f[-1]:.1f} Hz; the current setting is "
                 "the identified one")
    return fit.rig, list(fit.effects), source_prefix, params, uncertain, notes, (float(f[0]), float(f[-1]))


def make_draws(uncertain, uncertainty, rig, effects, design, n, seed) -> Draws:
    if uncertainty:
        values = {}
        for name in uncertainty:
            from ..physics.model import resolve_parameter

            try:
                i, p = resolve_parameter(name, effects)
            except ValueError as exc:
                raise DataError(f"uncertainty: {exc}") from None
            if name in design:
                raise DataError(f"uncertainty given for design variable {name}")
            values[name] = float(getattr(rig, p)) if i < 0 else float(effects[i].params[p])
        return draws_from_std(uncertainty, values, n, seed)
    if uncertain is None:
        raise DataError("robust tuning needs parameter uncertainty: tune a FitResult (its covariance) "
                        "or pass uncertainty={name: std}")
    names, values, cov = uncertain
    return draws_from_covariance(names, values, cov, exclude=design, n=n, seed=seed)

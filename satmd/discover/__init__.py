"""Missing-physics discovery: locate the mismatch, name the missing physics, model it.

>>> from satmd import simulate, effect, discover
>>> data = simulate(effects=[effect("time_delay", tau_s=3e-4)], noise=(0.01, 0.002), seed=1)
>>> discover(data).effect_names
['time_delay']

Steps (each module says how):
1. fit the nominal model globally (`satmd.identify`);
2. noise from the std columns, or estimated (`noise.py`);
3. locate and decide with calibrated χ² tests (`locate.py`);
4. explain: candidates from the SPEC §8 vocabulary, BIC model selection
   with backward elimination, swaps and equivalents (`select.py`);
5. when the vocabulary cannot explain a significant mismatch: `unexplained`,
   with a smooth data-driven correction showing how much of it is structured
   (`discrepancy.py`);
6. report (`report.py`).
"""
from __future__ import annotations

import time
from typing import Sequence

from ..identify import identify
from ..io.frfdata import FRFData
from ..physics import Rig
from .candidates import default_candidates
from .discrepancy import fit_discrepancy
from .locate import test_mismatch
from .noise import estimate_std
from .report import SCHEMA, DiscoveryReport, explain
from .select import Model, Search, equivalents, select

__all__ = ["discover", "DiscoveryReport", "SCHEMA"]


def discover(
    data: FRFData,
    rig: Rig | None = None,
    free: Sequence[str] = ("m2", "kp", "R", "L"),
    candidates: Sequence[str] | None = None,
    channels: Sequence[str] | None = None,
    alpha: float = 1e-3,
    max_effects: int = 3,
) -> DiscoveryReport:
    """Find what physics the nominal model leaves out of ``data``.

    Parameters
    ----------
    data : FRFData with measured channels (a1, a2 by default).
    rig : values of the fixed parameters (default: the paper's rig).
    free : parameters fitted in every model (default m2, kp, R, L; their true
        values may be anywhere in the SPEC §9 ranges).
    candidates : effect names to consider (default: the whole vocabulary).
    alpha : level of the mismatch test (global and band-wise together).
    max_effects : most effects a model may hold.
    """
    t0 = time.perf_counter()
    rig = Rig() if rig is None else rig
    free = tuple(free)
    channels = tuple(channels) if channels else tuple(c for c in ("a1", "a2") if c in data.channels) or data.names
    data = data.select(channels)
    candidates = tuple(candidates) if candidates else default_candidates()

    nominal_fit = identify(data, rig, free, channels)
    noise, noise_dof = "given", None
    if not data.has_std:
        noise = "estimated"
        data = data.with_std(estimate_std(data, nominal_fit))
        noise_dof = 2 * len(channels) * (len(data) - 2)
        nominal_fit = identify(data, rig, free, channels, start=nominal_fit.values, global_search=False)
    test0 = test_mismatch(nominal_fit, alpha, noise_dof)
    before = _fit_summary(nominal_fit)
    p_values = {"global": test0.p_global, "band": test0.p_band}
    if not test0.significant:
        return DiscoveryReport(False, noise, test0.bands_hz, [], dict(nominal_fit.values), before, before,
                               nominal_fit, nominal_fit, None, p_values, test0.whiteness,
                               time.perf_counter() - t0)

    nominal = Model((), [], nominal_fit)
    search = Search(data, rig, free, channels, candidates)

    def significant(fit):
        return test_mismatch(fit, alpha, noise_dof).significant

    final = select(search, nominal, significant, max_effects)
    effects = []
    if final.names:
        equiv = equivalents(search, final, nominal)
        without = {n: search.remove(final, n, nominal) for n in final.names}
        dbic = {n: m.bic - final.bic for n, m in without.items()}
        for name in sorted(final.names, key=lambda n: -dbic[n]):
            eff = final.effects[final.names.index(name)]
            params = {k: float(v) for k, v in eff.params.items()}
            # what accounting for this effect does to the free parameters (vs the model without it)
            ref = without[name].fit.values
            shifts = {k: final.fit.values[k] / ref[k] - 1 for k in free if ref[k]}
            effects.append({"name": name, "parameters": params, "equivalent": equiv[name],
                            "delta_bic": round(float(dbic[name]), 2), "explanation": explain(name, params, rig, shifts)})
    after = _fit_summary(final.fit)
    test1 = test_mismatch(final.fit, alpha, noise_dof)
    disc = None
    if test1.significant:
        disc = _unexplained(final.fit)
        structured = disc.structured_fraction
        dof = max(final.fit.dof - disc.n_parameters, 1)
        after = {"chi2_reduced": disc.chi2_after / dof, "rel_error": _rel_error(final.fit, disc)}
        bands = ", ".join(f"{a:.1f}–{b:.1f} Hz" for a, b in test1.bands_hz) or "the whole band"
        effects.append({"name": "unexplained", "parameters": {}, "equivalent": [],
                        "delta_bic": round(float(final.fit.chi2 - disc.chi2_after
                                                 - disc.n_parameters * _log_n(final.fit)), 2),
                        "explanation": (f"significant mismatch remains at {bands} that no vocabulary effect "
                                        f"explains; a smooth data-driven correction removes "
                                        f"{100 * structured:.0f} % of the remaining χ² "
                                        f"({sum(disc.terms.values())} Chebyshev terms), so the missing "
                                        f"physics is {'mostly structured' if structured > 0.5 else 'mostly sharp or noise-like'}")})
    p_values.update({"global_after": test1.p_global, "band_after": test1.p_band})
    return DiscoveryReport(True, noise, test0.bands_hz, effects, {k: final.fit.values[k] for k in free}, before,
                           after, nominal_fit, final.fit, disc, p_values, test0.whiteness,
                           time.perf_counter() - t0)


def _fit_summary(fit) -> dict:
    return {"chi2_reduced": float(fit.chi2_reduced), "rel_error": float(fit.rel_error)}


def _log_n(fit):
    import numpy as np

    return float(np.log(fit.n_data))


def _unexplained(fit):
    p = fit._problem
    pred = p.prediction(fit.theta)
    residual = {c: p.target[k] - pred[k] for k, c in enumerate(p.channels)}
    sigma = {c: p.sigma[k] for k, c in enumerate(p.channels)}
    return fit_discrepancy(p.omega_hz, residual, sigma)


def _rel_error(fit, disc):
    import numpy as np

    p = fit._problem
    pred = p.prediction(fit.theta) + np.stack([disc.correction[c] for c in p.channels])
    return float(np.linalg.norm(pred - p.target) / np.linalg.norm(p.target))

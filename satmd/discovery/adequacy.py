"""The model-adequacy verdict of a discovery (SPEC §9 ``model_adequate``, ``adequacy_reasons``).

Decided before any effect is named, in two steps:

1. on the nominal fit (`satmd.identification.adequacy.assess_fit`): a fit that
   reproduces less than half of the data, or needs absurd parameter values, is
   no SATMD rig as measured; the data are read again as the usual mistakes
   would have left them (conjugated, in g, mm/s², displacement, velocity, dB and
   phase, a dead or copied channel, noise) to name what is wrong. No effect
   search is run on such data: no vocabulary effect of a plausible size
   changes an FRF by that much.
2. on the best augmented fit of the search: an effect that ends at the edge of
   its own search range, a free parameter pinned at an absurd value, or a large
   structured misfit left after the best vocabulary model (relative error
   ≥ ``STRUCTURE_REL_ERROR`` with most of it smooth) mean that the vocabulary
   does not describe these data: the effects are withdrawn and the verdict
   says why.
"""
from __future__ import annotations

from ..conventions import TINY

import math

from ..identification.adequacy import Adequacy, Reason, implausible_values
from ..identification.adequacy import assess_fit as assess_one
from ..identification.statistics import POOR_REL_ERROR

__all__ = ["Adequacy", "Reason", "assess_fit", "after_search", "effects_at_edge", "inadequate_report",
           "withdraw_if_inadequate", "STRUCTURE_REL_ERROR"]

STRUCTURE_REL_ERROR = 0.15  # misfit left by the best vocabulary model beyond which it is another structure
EDGE = 0.005  # share of a search range (log width for ranges over a decade) that counts as its edge


def assess_fit(fit) -> Adequacy:
    """The verdict of the nominal fit before the search: inadequate only when it reproduces little of the
    data (then `FitResult.adequacy`, with the readings that name a mistake). Implausible values alone are
    left to the search: a missing effect can push the nominal model's free parameters anywhere; the best
    augmented fit is judged again (`after_search`). A channel that copies another is absent whatever the fit."""
    quick = assess_one(fit, readings=False)
    if any(r.kind == "channel" for r in quick.reasons):
        return quick
    if quick.adequate or not any(r.kind == "poor_fit" for r in quick.reasons):
        return Adequacy(True)
    if fit.adequacy is not None:
        return fit.adequacy
    from ..identification import identify

    return assess_one(fit, refit=identify)


def effects_at_edge(effects, rig) -> list:
    """A `Reason` for each fitted effect parameter at the edge of its own search range (not at its neutral)."""
    out = []
    for eff in effects:
        neutral = eff.neutral
        for p, (lo, hi) in eff.bounds(rig).items():
            v = float(eff.params[p])
            if p in neutral and v == float(neutral[p]):
                continue
            # a bound at the neutral value is where the effect vanishes (a light mode, a small loss), not
            # where it is stretched: only the other edges count
            for b in (x for x in (lo, hi) if not (p in neutral and x == float(neutral[p]))):
                if _near(v, b, lo, hi):
                    side = "lower" if b == lo else "upper"
                    out.append(Reason("effect_at_bound", f"{eff.name} needs {p} = {v:.4g}, at the {side} edge of its "
                                                         f"search range [{lo:g}, {hi:g}]: the vocabulary effect is "
                                                         "stretched to fit something else",
                                      {"effect": eff.name, "parameter": p, "value": v, "range": [lo, hi]}))
                    break
    return out


def _near(v, b, lo, hi) -> bool:
    if not (math.isfinite(b) and math.isfinite(lo) and math.isfinite(hi)):
        return False
    if lo > 0 and hi / lo >= 10:  # a range over decades: its edge in log terms
        return abs(math.log(max(v, TINY) / b)) <= EDGE * math.log(hi / lo)
    return abs(v - b) <= EDGE * (hi - lo)


def after_search(fit, effects, rig, discrepancy=None) -> list:
    """Evidence against the model from the best augmented fit of the search (see the module docstring).

    Parameters
    ----------
    fit : FitResult of the best vocabulary model.
    effects : its fitted effects.
    rig : the rig of fixed values (for the effects' search ranges).
    discrepancy : the smooth correction fitted to what is left, when the mismatch remained significant.

    Returns
    -------
    list of Reason
        Empty when the augmented model describes the data.
    """
    out = effects_at_edge(effects, rig)
    absurd = implausible_values(fit)
    if absurd:
        out.append(Reason("implausible", "the best augmented fit needs " + "; ".join(absurd.values()),
                          {"parameters": {n: float(fit.values[n]) for n in sorted(absurd)}}))
    rel = float(fit.rel_error)
    if rel >= POOR_REL_ERROR:
        out.append(Reason("poor_fit", f"the best augmented fit reproduces little of the data (relative FRF error "
                                      f"{rel:.3g})", {"rel_error": rel}))
    elif discrepancy is not None and rel >= STRUCTURE_REL_ERROR and discrepancy.structured_fraction > 0.5:
        out.append(Reason("structure_left", f"after the best vocabulary model {100 * rel:.0f} % of the data is still "
                                            f"unexplained, {100 * discrepancy.structured_fraction:.0f} % of it "
                                            "smooth: another structure, not a missing effect",
                          {"rel_error": rel, "structured_fraction": float(discrepancy.structured_fraction)}))
    return out


def inadequate_report(verdict, fit, alpha: float, t0: float):
    """The discovery report of data the model cannot describe: no effects, the verdict and its evidence.

    Parameters
    ----------
    verdict : Adequacy (not adequate).
    fit : the nominal FitResult.
    alpha : level of the mismatch test (run when the data carry a std).
    t0 : `time.perf_counter()` at the start of the discovery.

    Returns
    -------
    DiscoveryReport
    """
    import time

    from .locate import test_mismatch
    from .report import DiscoveryReport

    summary = {"chi2_reduced": float(fit.chi2_reduced), "rel_error": float(fit.rel_error)}
    significant, bands, p_values, white = True, [], {}, {}  # no std: a model that reproduces little misses
    if fit.weighted:
        test = test_mismatch(fit, alpha, fit.data.estimator.get("noise_dof") or None)
        significant, bands, white = test.significant, test.bands_hz, test.whiteness
        p_values = {"global": test.p_global, "band": test.p_band}
    return DiscoveryReport(significant_mismatch=bool(significant), noise="given" if fit.weighted else "estimated",
                           mismatch_bands_hz=bands, effects=[], parameters=dict(fit.values), fit_before=summary,
                           fit_after=summary, nominal_fit=fit, final_fit=fit, discrepancy=None, p_values=p_values,
                           whiteness=white, wall_time=time.perf_counter() - t0, adequacy=verdict)


def withdraw_if_inadequate(report, reasons):
    """``report`` unchanged when ``reasons`` is empty; else without effects, with the verdict and its evidence
    (the nominal parameters; ``fit_after`` still says how far the best augmented model got)."""
    from dataclasses import replace

    if not reasons:
        return report
    fit = report.nominal_fit
    return replace(report, effects=[], parameters={k: fit.values[k] for k in report.parameters},
                   final_fit=fit, discrepancy=None, adequacy=Adequacy(False, tuple(reasons)))

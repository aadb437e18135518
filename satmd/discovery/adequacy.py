"""The model-adequacy verdict of a discovery (SPEC §9 ``model_adequate``, ``adequacy_reasons``).

Decided before any effect is named, in two steps:

1. on the nominal fit (`satmd.identification.adequacy.assess_fit`): a fit that
   reproduces less than half of the data, or needs absurd parameter values, is
   no SATMD rig as measured; the data are read again as the usual mistakes
   would have left them (conjugated, in g, mm/s², displacement, velocity, dB and
   phase, a dead or copied channel, noise) to name what is wrong. No effect
   search is run on such data, with one exception (`rescued_by_one_effect`): when
   no mistake of the data is named and one vocabulary effect alone makes the fit
   describe the data with plausible values (as a light host mode at a resonance
   does, carrying most of the FRF's energy), the search runs.
2. on the best augmented fit of the search: an effect that ends at the edge of
   its own search range, a free parameter pinned at an absurd value, or a large
   structured misfit left after the best vocabulary model (relative error
   ≥ ``STRUCTURE_REL_ERROR`` with most of it smooth) mean that the vocabulary
   does not describe these data: the effects are withdrawn and the verdict
   says why.

Between the two, `drop_stretched`: when the nominal fit already describes the
data with plausible values (relative error below ``STRUCTURE_REL_ERROR``, no
parameter implausible), a candidate that the search stretches (an effect at the
edge of its range, or one that drives the free parameters to absurd values)
says nothing against the model: such a candidate only trades a small misfit
for absurd values. It is dropped (not named, not held against the model) and
the effects that remain acceptable are kept. A
nominal fit that is poor or implausible gets no such benefit: step 2 judges
its best augmented fit as it stands.
"""
from __future__ import annotations

from ..conventions import TINY

import math

from ..identification.adequacy import (Adequacy, Reason, implausible_reason, implausible_values,
                                       rel_error_beyond_noise)
from ..identification.adequacy import assess_fit as assess_one
from ..identification.statistics import POOR_REL_ERROR

__all__ = ["Adequacy", "Reason", "MISTAKES", "assess_fit", "rescued_by_one_effect", "implausible_within_noise",
           "after_search", "effects_at_edge", "inadequate_report",
           "withdraw_if_inadequate", "trusted", "stretched", "drop_stretched", "STRUCTURE_REL_ERROR"]

STRUCTURE_REL_ERROR = 0.15  # misfit left by the best vocabulary model beyond which it is another structure
EDGE = 0.005  # share of a search range (log width for ranges over a decade) that counts as its edge

#: Evidence that names what is wrong with the data themselves: no vocabulary effect can answer it.
MISTAKES = ("sign_convention", "units", "db_phase", "channel", "noise_like")


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


def rescued_by_one_effect(verdict, search, nominal, rig) -> bool:
    """Whether a poor nominal fit is missing physics rather than other data: the verdict names no mistake of
    the data themselves (`MISTAKES`) and one vocabulary effect alone makes the fit `trusted` (relative error
    beyond the noise under ``STRUCTURE_REL_ERROR``, every value plausible), not stretched to its search
    range's edge. A light host mode at a resonance does that; a file that is no FRF of a rig, or another
    structure that one effect cannot make the rig, does not, and is refused without the whole search (the
    later rules judge a rescued fit like any other: `after_search`). The single-effect fits stay in
    ``search``'s cache for the search that follows.

    Parameters
    ----------
    verdict : the nominal fit's `Adequacy` (not adequate).
    search : `select.Search` on the data.
    nominal : `select.Model` of the nominal fit.
    rig : the rig of fixed values (for the effects' search ranges).

    Returns
    -------
    bool
    """
    if any(r.kind in MISTAKES for r in verdict.reasons):
        return False
    for c in search.options(nominal):
        one = search.add(nominal, c)
        if trusted(one.fit) and not effects_at_edge(one.effects, rig):
            return True
    return False


def implausible_within_noise(fit, rig) -> list:
    """The verdict on a nominal fit within the noise (no mismatch, so no search): `identify`'s (absurd values:
    not adequate). The values may stand in for an effect the data cannot tell apart from them (a concealed
    shunt capacitance fits as R ~ 1 kΩ and L ~ 5 H within the noise): the message says so. Empty when the
    values are plausible.

    Parameters
    ----------
    fit : the nominal FitResult.
    rig : the rig of fixed values.

    Returns
    -------
    list of Reason
    """
    reasons = after_search(fit, [], rig, who="the fit")
    tail = (": another structure, data in other units, or an effect these values stand in for that the data "
            "cannot tell apart from them (a shunt capacitance, say)")
    return [Reason(r.kind, r.message + tail, r.evidence) if r.kind == "implausible" else r for r in reasons]


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


def after_search(fit, effects, rig, discrepancy=None, who: str = "the best augmented fit") -> list:
    """Evidence against the model from the best augmented fit of the search (see the module docstring).

    Parameters
    ----------
    fit : FitResult of the best vocabulary model.
    effects : its fitted effects.
    rig : the rig of fixed values (for the effects' search ranges).
    discrepancy : the smooth correction fitted to what is left, when the mismatch remained significant.
    who : how the messages name the fit.

    Returns
    -------
    list of Reason
        Empty when the augmented model describes the data.
    """
    out = effects_at_edge(effects, rig)
    absurd = implausible_reason(fit, who)
    if absurd:
        out.append(absurd)
    rel = rel_error_beyond_noise(fit)
    if rel >= POOR_REL_ERROR:
        out.append(Reason("poor_fit", f"{who} reproduces little of the data (relative FRF error "
                                      f"{rel:.3g})", {"rel_error": rel}))
    elif discrepancy is not None and rel >= STRUCTURE_REL_ERROR and discrepancy.structured_fraction > 0.5:
        out.append(Reason("structure_left", f"after the best vocabulary model {100 * rel:.0f} % of the data is still "
                                            f"unexplained, {100 * discrepancy.structured_fraction:.0f} % of it "
                                            "smooth: another structure, not a missing effect",
                          {"rel_error": rel, "structured_fraction": float(discrepancy.structured_fraction)}))
    return out


def trusted(fit) -> bool:
    """True when ``fit`` describes the data with plausible values: relative FRF error (beyond the noise,
    `rel_error_beyond_noise`) below ``STRUCTURE_REL_ERROR`` and no parameter implausible (`implausible_values`)."""
    rel = rel_error_beyond_noise(fit)
    return math.isfinite(rel) and rel < STRUCTURE_REL_ERROR and not implausible_values(fit)


def stretched(model, rig) -> list:
    """The evidence that ``model`` (a `select.Model`) is stretched: its effects at the edge of their own search
    ranges, and an ``implausible`` reason when its free parameters sit at absurd values (empty when neither)."""
    out = effects_at_edge(model.effects, rig)
    absurd = implausible_reason(model.fit, "the augmented fit")
    if absurd:
        out.append(absurd)
    return out


def _blame(search, model, nominal, rig, reasons) -> list:
    """The effects of ``model`` that stretch it: those at the edge of their range; for absurd free parameters,
    the one whose removal gives a plausible fit at the lowest BIC, or all of them when no single removal does."""
    edge = [r.evidence["effect"] for r in reasons if r.kind == "effect_at_bound"]
    if edge:
        return list(dict.fromkeys(n for n in model.names if n in edge))
    without = {n: search.remove(model, n, nominal) for n in model.names}
    fine = [n for n, m in without.items() if not implausible_values(m.fit) and not effects_at_edge(m.effects, rig)]
    if fine:
        return [min(fine, key=lambda n: without[n].bic)]
    return list(model.names)


def drop_stretched(search, nominal, final, rig) -> tuple:
    """Drop the effects the search stretched, when the nominal fit is `trusted` (module docstring).

    Each stretched effect (`_blame`) leaves the model, which is refitted without it; an effect left that no
    longer earns its place (removing it costs at most ``MIN_DELTA_BIC``) leaves too. No new effect is added:
    the candidates the selection passed over stay passed over (a chain of stretched stand-ins for one
    missing thing is no licence to name the next one). What is still unexplained afterwards is the
    mismatch test's business (an ``unexplained`` finding, or a noise note).

    Parameters
    ----------
    search : `select.Search` of the discovery.
    nominal : `select.Model` of the nominal fit.
    final : `select.Model` the selection ended at.
    rig : the rig of fixed values (for the effects' search ranges).

    Returns
    -------
    (search, final, dropped)
        The search without the dropped candidates (for the equivalents), the model that remains
        (``final`` itself when nothing was dropped) and, per dropped effect, the evidence against it
        ({name: [Reason, ...]}).
    """
    from dataclasses import replace

    from .select import backward

    dropped: dict = {}
    if not final.names or not trusted(nominal.fit):
        return search, final, dropped
    while final.names:
        reasons = stretched(final, rig)
        if not reasons:
            break
        for n in _blame(search, final, nominal, rig, reasons):
            dropped[n] = [r for r in reasons if r.kind != "effect_at_bound" or r.evidence.get("effect") == n]
            final = search.remove(final, n, nominal)
        final = backward(search, final, nominal)  # what is left must still earn its place
    if dropped:  # the equivalents are sought among the candidates that were not stretched
        search = replace(search, candidates=tuple(c for c in search.candidates if c not in dropped))
    return search, final, dropped


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
                           mismatch_bands_hz=bands, judged=(), parameters=dict(fit.values), fit_before=summary,
                           fit_after=summary, nominal_fit=fit, final_fit=fit, discrepancy=None, p_values=p_values,
                           whiteness=white, wall_time=time.perf_counter() - t0, adequacy=verdict)


def withdraw_if_inadequate(report, reasons):
    """``report`` unchanged when ``reasons`` is empty; else its named candidates withdrawn for them, with the
    verdict and its evidence (the nominal parameters; ``fit_after`` still says how far the best augmented model
    got)."""
    if not reasons:
        return report
    fit = report.nominal_fit
    return report.rejudged(lambda j: True, "withdrawn", reasons,
                           parameters={k: fit.values[k] for k in report.parameters}, final_fit=fit, discrepancy=None,
                           adequacy=Adequacy(False, tuple(reasons)))

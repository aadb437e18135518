"""Assemble the ``nonlinear`` block: tests of every recording, the level test, and the named finding.

`analyse_recordings` is the SATMD path (force, acc1, acc2 at one or several
levels); `analyse_generic` the path for any input→output record (one output,
e.g. the Silverbox circuit), where the finding is read from a one-mode fit per
level and no SATMD element is named.
"""
from __future__ import annotations

import numpy as np

from ...errors import SatmdError
from ...numerics import force_level

from ...conventions import ACCEL_CHANNELS, DEFAULT_FREE, MIN_DELTA_BIC, TINY
from .distortion import (
    EXPERIMENT_LEVEL,
    EXPERIMENT_MULTISINE,
    UNEXPLAINED_NL,
    NonlinearReport,
    concentrated_bands,
    distortion_test,
    multisine_test,
)
from ...signal.periodic import is_multisine
from ...signal.several import common_frfs, on_common_grid
from ..findings import NonlinearFinding
from .stats import NonlinearTest, level_dependence

_REGRESSOR_WORDS = {"u1:cube": "u1³ of the host's displacement", "d:cube": "d³ of the absorber's stroke",
                    "v:cube": "v³ of the absorber's relative velocity (a damping that grows with level?)",
                    "v:absv": "|v|v of the absorber's relative velocity", "v:sign": "sign(v) of the absorber's relative velocity"}


def regressor_hint(regressor: str) -> str | None:
    """The regressor in words, with the registered elements that it stands for (their ``regressor``)."""
    from ...physics.nonlinear import NONLINEAR

    words = _REGRESSOR_WORDS.get(regressor)
    if words is None:
        return None
    elements = [f"{cls.description.split(':')[0]} ({name})" for name, cls in NONLINEAR.items()
                if cls.regressor == regressor]
    return f"{words} ({', or '.join(elements)}?)" if elements else words


def force_levels(recordings) -> list:
    """RMS of each recording's force (the level figure the findings are read against)."""
    return [force_level(r["force"]) for r in recordings]


def _distortion_tests(recordings, alpha):
    """One distortion test per recording at level alpha / k (Bonferroni), with its bands located."""
    from ...signal.excitation import excitation_of

    k = len(recordings)
    tests = []
    for i, r in enumerate(recordings):
        kind = excitation_of(r).kind
        if kind in ("impact", "sweep") and not is_multisine(r):  # no broadband force at every moment: says so
            tests.append(NonlinearTest("distortion" if k == 1 else f"distortion#{i + 1}", 1.0, [], alpha / k,
                                       {"reason": f"a{'n' if kind == 'impact' else ''} {kind} record: the distortion "
                                                  "test needs a random or periodic force"}))
            continue
        t = multisine_test(r, alpha / k) if is_multisine(r) else distortion_test(r, alpha=alpha / k)
        name = t.name if k == 1 else f"{t.name}#{i + 1}"
        p = min(1.0, t.p_value)
        tests.append(NonlinearTest(name, p, concentrated_bands(t), alpha / k, t.details))
    return tests


def _few_dof(datas):
    """The noise dof of periodic or impact estimates (few periods or hits: F, not χ², tests); None otherwise."""
    if all(d.estimator.get("method") in ("periodic", "impact", "realisations") and d.estimator.get("noise_dof")
           for d in datas):
        return float(min(d.estimator["noise_dof"] for d in datas))
    return None


def _inner(freq, share: float = 0.05):
    """Points of ``freq`` away from its two ends by ``share`` of the span."""
    lo, hi = freq[0], freq[-1]
    return (freq >= lo + share * (hi - lo)) & (freq <= hi - share * (hi - lo))


def _hint(test: NonlinearTest) -> str:
    """Where the distortion is and what carries it, in words."""
    where = ", ".join(f"{a:.1f}–{b:.1f} Hz" for a, b in test.bands_hz) or "the band"
    ratios = [(c, d) for c, d in test.details.items() if isinstance(d, dict) and "odd_ratio" in d]
    if ratios:
        parts = ", ".join(f"{c}: odd {d['odd_ratio']:.3g}x, even {d['even_ratio']:.3g}x the noise" for c, d in ratios)
        return f"distortion at {where}; at the detection lines {parts} (odd: a symmetric nonlinearity)"
    expl = test.details.get("explained", {})
    if test.name.startswith("level_dependence"):
        return f"the FRFs of the recordings differ beyond their noise at {where}"
    if not expl:
        return f"distortion at {where}"
    chans = ", ".join(f"{c} {100 * v:.0f} %" for c, v in expl.items())
    text = f"distortion at {where}; nonlinear functions of the responses explain {chans} of the local residual"
    regs = test.details.get("regressors") or []
    hint = regressor_hint(regs[0]) if test.details.get("per_regressor") and regs else None
    if hint:
        text += f"; the regressor that holds it best is {hint} (a hint, not a name)"
    return text


def analyse_recordings(recordings, rig=None, free=DEFAULT_FREE, alpha: float = 1e-3, datas=None,
                       strength: bool = True) -> NonlinearReport:
    """Detect, locate and name nonlinearity in SATMD recordings of one rig (see the module docstring).

    Parameters
    ----------
    recordings : list of Recording (force, acc1, acc2), levels or repeats, in any order
    rig : fixed values (default: the paper's rig)
    free : free parameters of the linear model
    alpha : overall level (half for the distortion tests, half for the level test)
    datas : their FRFData on one grid, if already estimated (`common_frfs`)
    strength : fit a named element's strength in the time domain now (`fit_nonlinear`); False leaves it to
        `with_strength`, for a caller that first asks whether the recordings are a SATMD rig at all (a structure
        with many sensors is not, and the fit would be thrown away: 12 s of a 32 s `discover`)

    Returns
    -------
    NonlinearReport
    """
    from functools import partial

    from ...physics import Rig

    rig = Rig() if rig is None else rig
    k = len(recordings)
    levels = force_levels(recordings)
    a_dist = alpha / 2 if k > 1 else alpha
    tests = _distortion_tests(recordings, a_dist)
    findings, experiments = [], []
    level_test = None
    if k > 1:
        datas = datas or common_frfs(recordings)
        grid = on_common_grid(datas)
        if grid is not None:
            freq, datas = grid
            inner = _inner(freq)  # the band edges, where the force falls off, carry the estimator's own errors
            lt = level_dependence(freq[inner], [{c: v[inner] for c, v in d.channels.items()} for d in datas],
                                  [{c: v[inner] for c, v in d.std.items()} for d in datas], alpha / 4,
                                  dof_noise=_few_dof(datas),
                                  model_errors=[{c: np.asarray(v)[inner] for c, v in (d.meta.get("model_error")
                                                                                      or {}).items()}
                                                for d in datas])
            level_test = NonlinearTest(lt.name, lt.p_value, concentrated_bands(lt), lt.alpha, lt.details)
            cmp = _hypotheses(datas, rig, free, levels)
            from .naming import parameter_test

            pt = parameter_test(cmp, alpha / 4)
            tests += [level_test, NonlinearTest(pt.name, pt.p_value, level_test.bands_hz, pt.alpha, pt.details)]
    detected = any(t.significant for t in tests)
    spread = max(levels) / max(min(levels), TINY)
    moved = level_test is not None and (level_test.significant or tests[-1].significant)
    deferred = None
    if detected and moved and spread > 1.5:
        findings.append(_name_from_levels(datas, rig, free, levels, recordings, cmp, strength))
        if not strength:
            deferred = partial(_name_from_levels, datas, rig, free, levels, recordings, cmp)
    elif detected:
        worst = min(tests, key=lambda t: t.p_value)
        findings.append(NonlinearFinding(UNEXPLAINED_NL, explanation=_hint(worst) + "; one level cannot say which "
                                         "element (which linear parameter moves with level)"))
        experiments.append(EXPERIMENT_LEVEL)
    if detected and not any(t.name.startswith("distortion_lines") for t in tests):
        experiments.append(EXPERIMENT_MULTISINE)
    experiments += [f"record 3 or more periods at the level of {name}: with 2, a start-up transient in the first "
                    "cannot be told from the noise, so it is averaged in and counted as noise, and the tests see "
                    "less" for name in two_periods(recordings)]
    return NonlinearReport(detected, tests, findings, experiments, levels, deferred=deferred)


def two_periods(recordings) -> list:
    """The names of the recordings whose periodic force has two periods only (both averaged: a start-up transient
    in the first cannot be told from the noise; a shorter top level, cut to spare the structure, had a chain's
    cubic joint found at 1 and 8 N RMS with five periods each and not with two at 8 N)."""
    from ...signal.excitation import excitation_of
    from ...signal.periodic import excitation_findings

    out = []
    for i, r in enumerate(recordings, start=1):
        try:
            found = excitation_findings(excitation_of(r))  # its ``two_periods`` finding: the one definition
        except SatmdError:
            continue
        if any(f.name == "two_periods" for f in found):
            out.append(str(r.meta.get("source", f"recording {i}")))
    return out


def with_strength(report: NonlinearReport) -> NonlinearReport:
    """``report`` with the strength `analyse_recordings` left for later (``strength=False``) fitted now."""
    from dataclasses import replace

    if report.deferred is None:
        return report
    return replace(report, findings=[report.deferred(), *report.findings[1:]], deferred=None)


def _hypotheses(datas, rig, free, levels) -> dict:
    """`compare_hypotheses` started from the identified lowest level."""
    from ...identification import identify
    from .naming import compare_hypotheses

    lo = int(np.argmin(levels))
    fit0 = identify(datas[lo], rig, free, tuple(c for c in ACCEL_CHANNELS if c in datas[lo].channels), warn=False)
    channels = tuple(c for c in ACCEL_CHANNELS if all(c in d.channels for d in datas))
    return compare_hypotheses(datas, rig, tuple(free), channels, dict(fit0.values), levels)


def _name_from_levels(datas, rig, free, levels, recordings, cmp=None, strength: bool = True) -> NonlinearFinding:
    """The finding for a significant level dependence: moving parameter, direction, element, strength.

    The element is the one whose equivalent linearisation's trend with level fits best (BIC over every
    registered element that moves that parameter that way, `rank_elements`); those within
    ``MIN_DELTA_BIC`` of it, and the elements of equally good moving parameters, are its equivalents.
    """
    from .naming import candidates, element_for, rank_elements

    cmp = cmp or _hypotheses(datas, rig, free, levels)
    p, direction = cmp["best"], cmp["direction"]
    fit = cmp["fits"][p]
    eq_lin = {p: [float(v) for v in fit.per_record]}
    found = candidates(p, direction)
    others = []
    for q in cmp["equivalent"]:
        c = element_for(q, "up" if np.diff(np.asarray(cmp["fits"][q].per_record)[cmp["order"]]).sum() > 0 else "down")
        others.append(c.name if c else f"{UNEXPLAINED_NL} ({q})")
    change = fit.per_record[cmp["order"][-1]] / fit.per_record[cmp["order"][0]] - 1
    moved = f"{p} {100 * change:+.1f} % from the lowest to the highest level ({abs(cmp['z']):.0f} σ)"
    if not found:
        return NonlinearFinding(UNEXPLAINED_NL, equivalent=others, equivalent_linear=eq_lin,
                                explanation=f"the rig changes with level, but no element explains it: {moved}")
    if recordings is None:
        return NonlinearFinding(found[0].name, equivalent=[c.name for c in found[1:]] + others,
                                equivalent_linear=eq_lin, moving=p, direction=direction,
                                explanation=f"{found[0].description}; measured: {moved} (FRFs only: no force level, "
                                            "no strength)")
    ranked = rank_elements(found, fit.per_record, fit.per_record_std, fit.rigs, [r["force"] for r in recordings],
                           [r.fs_hz for r in recordings], fit.chi2, fit.n_data)
    cls = ranked[0]["cls"] if ranked else found[0]
    others = [r["cls"].name for r in ranked[1:] if r["bic"] - ranked[0]["bic"] < MIN_DELTA_BIC] + others
    nominal = float(fit.per_record[cmp["order"][0]])  # the lowest level's value, until the strength fit says
    if ranked:
        sf = ranked[0]["fit"]
        params, ci, nominal = {k: float(v) for k, v in sf.element.params.items()}, sf.ci95, sf.nominal
        text = f"{sf.element.explain(rig.replace(**{p: nominal}))}; measured: {moved}"
    else:  # the name stands even when the strength cannot be fitted
        params, ci = {}, {}
        text = f"{cls.description}; measured: {moved} (strength not fitted)"
    fitted_in_time = _time_domain_strength(recordings, cls.name, rig) if strength else None
    if fitted_in_time is not None:  # the time-domain fit's coefficient and interval: they cover (issue 36 item 7)
        params, ci, fitted = fitted_in_time
        text = f"{fitted.explain(rig.replace(**{p: nominal}))}; measured: {moved}" if params else text
    elif params:
        text += " (strength from the equivalent linearisation, whose own error the interval does not carry)"
    return NonlinearFinding(cls.name, params, ci, others, eq_lin, text, moving=p, direction=direction)


def _time_domain_strength(recordings, name, rig):
    """(parameters, ci95, element) from `fit_nonlinear` on the recordings, or None when it cannot run.

    The equivalent linearisation's strength comes with an interval from that fit's noise alone, which
    misses the linearisation's own error; the time-domain output-error fit does not linearise.
    """
    from ...errors import SatmdError
    from ...identification.nonlinear.fit import fit_nonlinear
    from ...physics.nonlinear import kernel

    if not kernel.available:  # the numpy integrator is ~100x slower: not inside discover
        return None
    import warnings

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # its internal linear start's notes are not the user's findings
            fit = fit_nonlinear(recordings, name, rig=rig)
    except (SatmdError, ArithmeticError, ValueError, np.linalg.LinAlgError):
        return None
    names = [k for k in fit.element.params]
    values = {k: float(fit.values[k]) for k in names if k in fit.values}
    ci = {k: [float(a) for a in fit.ci95[k]] for k in names if k in fit.ci95}
    if not values or not all(np.isfinite(v) for v in values.values()):
        return None
    return values, ci, fit.element


def analyse_frfs(datas, rig=None, free=DEFAULT_FREE, alpha: float = 1e-3, levels=None) -> NonlinearReport:
    """The level-dependence test and naming for FRFData with std on one grid (no time data: no distortion test).

    Parameters
    ----------
    datas : list of FRFData on one grid
    rig, free, alpha : as `analyse_recordings`
    levels : level figure per FRF (default: the metadata's ``force_rms``, else the order given is increasing)

    Returns
    -------
    NonlinearReport
    """
    from ...physics import Rig

    rig = Rig() if rig is None else rig
    if levels is None:
        try:
            levels = [float(d.meta["force_rms"]) for d in datas]
        except (KeyError, TypeError, ValueError):
            levels = [float(i + 1) for i in range(len(datas))]
    from .naming import parameter_test

    freq = datas[0].freq_hz
    lt = level_dependence(freq, [d.channels for d in datas], [d.std for d in datas], alpha / 2)
    test = NonlinearTest(lt.name, lt.p_value, concentrated_bands(lt), lt.alpha, lt.details)
    cmp = _hypotheses(datas, rig, free, levels)
    pt = parameter_test(cmp, alpha / 2)
    tests = [test, NonlinearTest(pt.name, pt.p_value, test.bands_hz, pt.alpha, pt.details)]
    detected = any(t.significant for t in tests)
    findings = [_name_from_levels(datas, rig, free, levels, None, cmp)] if detected else []
    return NonlinearReport(detected, tests, findings, [EXPERIMENT_MULTISINE] if findings else [], levels)


# --- generic input→output records --------------------------------------------------------------------------
def analyse_generic(frfs: list, stds: list, freq, levels, tests=(), alpha: float = 1e-3,
                    output: str = "y") -> NonlinearReport:
    """Level dependence and a one-mode reading for a generic single-output system (no SATMD element named).

    Parameters
    ----------
    frfs, stds : per level {output: (M,) complex} and {output: (M,) std} on the grid ``freq``
    freq : (M,) Hz
    levels : one level figure per record
    tests : distortion tests already made (kept in the report)
    alpha : level of the level-dependence test
    output : the output channel's name

    Returns
    -------
    NonlinearReport
        A finding ``nonlinear_unexplained`` with ``character`` hardening /
        softening, the one-mode natural frequency and damping per record, and ``modes``: every
        resonance that moves with level, from a multi-mode fit per record (SPEC §9).
    """
    from .periodic import one_mode_fit

    tests = list(tests)
    findings, experiments = [], []
    if len(frfs) > 1:
        lt = level_dependence(freq, frfs, stds, alpha)
        tests.append(NonlinearTest(lt.name, lt.p_value, concentrated_bands(lt), lt.alpha, lt.details))
    detected = any(t.significant for t in tests)
    if detected and len(frfs) > 1:
        fits = [one_mode_fit(freq, f[output], s[output]) for f, s in zip(frfs, stds)]
        peaks = [float(freq[np.argmax(np.abs(f[output]))]) for f in frfs]
        order = np.argsort(levels)
        fn = [m["f_n_hz"] for m in fits]
        dz = (fn[order[-1]] - fn[order[0]]) / max(np.hypot(fits[order[-1]]["f_n_std"], fits[order[0]]["f_n_std"]),
                                                    TINY)
        character = "hardening" if dz > 3 else "softening" if dz < -3 else "level-dependent damping"
        bands: list = next((t.bands_hz for t in tests if t.name == "level_dependence"), [])
        where = ", ".join(f"{a:.1f}–{b:.1f} Hz" for a, b in bands)
        from .modes import level_modes

        modes = [t.to_dict() for t in level_modes(freq, frfs, stds, levels) if t.moves]  # every resonance
        findings.append(NonlinearFinding(
            UNEXPLAINED_NL, character=character, modes=modes,
            equivalent_linear={"f_n_hz": fn, "zeta": [m["zeta"] for m in fits], "peak_hz": peaks},
            explanation=(f"{character} at the resonance: a one-mode fit per level puts the natural frequency at "
                         + ", ".join(f"{fn[i]:.2f}" for i in order) + " Hz (damping "
                         + ", ".join(f"{100 * fits[i]['zeta']:.1f}" for i in order) + " %) from the lowest to "
                         f"the highest level; the level dependence lies at {where}. Not a SATMD rig: no SATMD "
                         "element is named (a Duffing-like stiffness fits this pattern)")))
    elif detected:
        findings.append(NonlinearFinding(UNEXPLAINED_NL, explanation=_hint(min(tests, key=lambda t: t.p_value))))
        experiments.append(EXPERIMENT_LEVEL)
    return NonlinearReport(detected, tests, findings, experiments, list(levels))

"""Name a level dependence: which linear parameter moves with level, which way, and which element that is.

A nonlinear element seen by a linear fit at one level is its equivalent linear
value (SPEC §8b): a cubic absorber spring moves kp, a cubic host spring k1,
friction lowers cp with level, velocity-squared damping raises it, a saturating
inductor lowers L. With recordings at several levels, every hypothesis "only p
moves" (p in kp, k1, cp, L) is a joint fit of all recordings with the free
parameters shared and p free per recording (`joint_fit`); the hypothesis with
the lowest BIC names the parameter, the sign of its change with level the
element; hypotheses within ``MIN_DELTA_BIC`` of BIC are reported as equivalents (the data
cannot tell them apart). Then the element's own equivalent linearisation at
each level's signal RMS (`satmd.physics.nonlinear.response_rms`) is inverted for
its strength with a 95 % interval (`fit_strength`).
"""
from __future__ import annotations

from ..conventions import MIN_DELTA_BIC, TINY

from dataclasses import dataclass, field

import numpy as np

from ..numerics import jacobian_covariance
from ..physics import frf
from ..physics.nonlinear import NONLINEAR, response_rms

MOVING = ("kp", "k1", "cp", "L")
LOG_REACH = 50.0  # the farthest a joint fit moves a parameter from its start, in log units


@dataclass(frozen=True)
class JointFit:
    """A joint fit of several recordings with one parameter free per recording.

    Attributes
    ----------
    moving : the parameter free per recording (None: all shared)
    shared : {name: value} of the shared free parameters
    per_record : list of the moving parameter's value per recording ([] when none)
    per_record_std : its standard deviations
    chi2, bic, n_data : fit figures
    rigs : the equivalent linear rig of each recording
    """

    moving: object
    shared: dict
    per_record: list
    per_record_std: list
    chi2: float
    bic: float
    n_data: int
    rigs: list = field(default_factory=list, repr=False)


def _stack(datas, channels):
    """Data and weights of all recordings as one real vector."""
    ys, ws = [], []
    for d in datas:
        for c in channels:
            ys.append(np.concatenate([d[c].real, d[c].imag]))
            s = d.std[c]
            ws.append(1.0 / np.concatenate([s, s]))
    return np.concatenate(ys), np.concatenate(ws)


def joint_fit(datas, rig, free, channels, moving, start: dict, moving_start=None) -> JointFit:
    """Fit all recordings together: ``free`` shared, ``moving`` free per recording (see the module docstring).

    Parameters
    ----------
    datas : list of FRFData with std
    rig : Rig of the fixed values
    free : shared free parameter names
    channels : channels to fit
    moving : a name from `MOVING`, or None
    start : {name: value} start of every free and moving parameter
    moving_start : optional list of per-recording starts of the moving parameter

    Returns
    -------
    JointFit
    """
    from scipy.optimize import least_squares

    shared = [p for p in free if p != moving]
    k = len(datas)
    names = shared + ([f"{moving}#{r}" for r in range(k)] if moving else [])
    base = {p: float(start.get(p, getattr(rig, p))) for p in shared}
    if moving:
        ms = moving_start or [float(start.get(moving, getattr(rig, moving)))] * k
        base.update({f"{moving}#{r}": float(ms[r]) for r in range(k)})
    x0 = np.zeros(len(names))
    y, w = _stack(datas, channels)

    def rigs_of(x):
        # a search on data the model cannot describe may run off: beyond e^±50 of its start a value is absurd
        vals = {n: base[n] * np.exp(np.clip(x[i], -LOG_REACH, LOG_REACH)) for i, n in enumerate(names)}
        common = {p: vals[p] for p in shared}
        return [rig.replace(**common, **({moving: vals[f"{moving}#{r}"]} if moving else {})) for r in range(k)]

    def residual(x):
        out = []
        with np.errstate(all="ignore"):  # absurd values give non-finite FRFs: least_squares steps back from them
            for r, (d, rg) in enumerate(zip(datas, rigs_of(x))):
                resp = frf(d.freq_hz, rg, outputs=tuple(channels), validate=False)
                for c in channels:
                    m = resp.channel(c)
                    out.append(np.concatenate([m.real, m.imag]))
            return (np.concatenate(out) - y) * w

    sol = least_squares(residual, x0, method="trf", x_scale="jac", xtol=1e-10, ftol=1e-10, max_nfev=200)
    chi2 = float(np.sum(sol.fun ** 2))
    n = y.size
    bic = chi2 + len(names) * np.log(n)
    cov = jacobian_covariance(sol.jac)
    vals = {nm: base[nm] * np.exp(np.clip(sol.x[i], -LOG_REACH, LOG_REACH)) for i, nm in enumerate(names)}
    per, per_std = [], []
    if moving:
        for r in range(k):
            i = names.index(f"{moving}#{r}")
            per.append(float(vals[names[i]]))
            per_std.append(float(vals[names[i]] * np.sqrt(max(cov[i, i], 0.0))))
    return JointFit(moving, {p: float(vals[p]) for p in shared}, per, per_std, chi2, float(bic), n, rigs_of(sol.x))


def compare_hypotheses(datas, rig, free, channels, start: dict, levels) -> dict:
    """Joint fits for "nothing moves" and for each parameter of `MOVING`; the moving one ranked by BIC.

    Parameters
    ----------
    datas, rig, free, channels, start : as `joint_fit`
    levels : one level figure per recording (e.g. force RMS), to read "with level"

    Returns
    -------
    dict
        ``fits`` {hypothesis: JointFit} ("none" for all shared), ``best`` (a
        name of `MOVING`), ``equivalent`` (others within ``MIN_DELTA_BIC``),
        ``direction`` ("up"/"down" with level), ``z`` (change high − low over
        its std), ``order`` (recordings sorted by level).
    """
    fits = {"none": joint_fit(datas, rig, free, channels, None, start)}
    base = fits["none"].shared
    for p in MOVING:
        st = dict(start, **base)
        fits[p] = joint_fit(datas, rig, free, channels, p, st)
    ranked = sorted(MOVING, key=lambda p: fits[p].bic)
    best = ranked[0]
    equivalent = [p for p in ranked[1:] if fits[p].bic - fits[best].bic < MIN_DELTA_BIC]
    order = list(np.argsort(np.asarray(levels, float)))
    lo, hi = order[0], order[-1]
    fb = fits[best]
    diff = fb.per_record[hi] - fb.per_record[lo]
    z = diff / max(np.hypot(fb.per_record_std[hi], fb.per_record_std[lo]), TINY)
    return {"fits": fits, "best": best, "equivalent": equivalent, "direction": "up" if diff > 0 else "down",
            "z": float(z), "order": order}


def parameter_test(cmp: dict, alpha: float = 1e-3):
    """Do the recordings' equivalent linear parameters differ beyond their uncertainty? (Wald test)

    For each hypothesis of `compare_hypotheses`, the per-recording values of its
    parameter against their weighted mean give χ²(k − 1) under "one linear
    system" (stds scaled up by √χ²_red when the fit is worse than its noise);
    the smallest p-value over the hypotheses is Bonferroni-corrected.

    Parameters
    ----------
    cmp : the result of `compare_hypotheses`
    alpha : level

    Returns
    -------
    NonlinearTest
        ``level_dependence_parameters``; ``details`` holds the χ² per parameter.
    """
    from scipy import stats

    from .nonlinear_stats import NonlinearTest

    chi, pvals = {}, {}
    for p in MOVING:
        fit = cmp["fits"][p]
        v = np.asarray(fit.per_record, float)
        n_par = len(fit.shared) + v.size
        scale = max(fit.chi2 / max(fit.n_data - n_par, 1), 1.0)
        var = np.maximum(np.asarray(fit.per_record_std, float) ** 2 * scale, TINY)
        mean = np.sum(v / var) / np.sum(1.0 / var)
        chi[p] = float(np.sum((v - mean) ** 2 / var))
        pvals[p] = float(stats.chi2.sf(chi[p], v.size - 1))
    worst = min(pvals, key=pvals.__getitem__)
    p_value = min(1.0, pvals[worst] * len(MOVING))
    return NonlinearTest("level_dependence_parameters", p_value, [], alpha,
                         {"chi2": chi, "p": pvals, "parameter": worst})


def element_for(parameter: str, direction: str):
    """The element class whose equivalent linearisation moves ``parameter`` that way (None if none does).

    Parameters
    ----------
    parameter : kp, k1, cp or L
    direction : "up" or "down" with level

    Returns
    -------
    type or None
    """
    for cls in NONLINEAR.values():
        if cls.linear_parameter != parameter:
            continue
        probe = _probe_direction(cls)
        if probe in (direction, "either"):
            return cls
    return None


def _probe_direction(cls) -> str:
    """Which way the element's equivalent value moves with level at a typical strength ("either": sign of k3)."""
    if cls.strength == "k3":
        return "either"
    from ..physics import Rig

    rig = Rig()
    el = cls(**{cls.strength: cls.parameter_specs[0].starts[-1] if cls.strength != "isat" else 0.01})
    lo = el.equivalent_value(rig, {s: 1e-3 for s in cls.reads})
    hi = el.equivalent_value(rig, {s: 1e-2 for s in cls.reads})
    return "up" if float(hi) > float(lo) else "down"


def fit_strength(cls, values, stds, rigs, forces, fs_hz):
    """The element's strength (and small-signal value) from its equivalent value at each level.

    Parameters
    ----------
    cls : element class
    values, stds : the moving parameter per recording and its std
    rigs : equivalent linear rig per recording (for the signals' RMS at its level)
    forces : force samples per recording
    fs_hz : sample rate per recording

    Returns
    -------
    (element, ci95, nominal, rms) : the element with its fitted strength,
    {strength: [lo, hi]}, the small-signal value of the parameter, and the
    read signal's RMS per recording.
    """
    from scipy.optimize import least_squares

    rms = [response_rms(rg, force=f, fs_hz=fs) for rg, f, fs in zip(rigs, forces, fs_hz)]
    values, stds = np.asarray(values, float), np.maximum(np.asarray(stds, float), 1e-12 * np.abs(values).max())
    p = cls.linear_parameter
    extra = {}
    if cls.strength == "Fc":  # v0 well below the slowest level's velocity: Coulomb-like, as a rub is
        extra["v0"] = 0.05 * min(float(r["v"]) for r in rms)
    base_rig = rigs[0]
    positive = cls.strength != "k3"  # k3 takes either sign; Fc, c2, isat are fitted on a log scale

    def strength(raw):
        return float(np.exp(raw)) if positive else float(raw)

    def model(theta):
        rig0 = base_rig.replace(**{p: theta[0]})
        el = cls(**{cls.strength: strength(theta[1])}, **extra)
        return np.array([float(el.equivalent_value(rig0, r)) for r in rms])

    best = None
    nominal0 = float(values.min() if p != "L" else values.max())
    for s0 in _strength_starts(cls, rms, values):
        raw0 = np.log(max(s0, TINY)) if positive else s0
        lo_b = [1e-6 * abs(nominal0), np.log(1e-10) if positive else -np.inf]
        hi_b = [1e3 * abs(nominal0), np.log(1e10) if positive else np.inf]
        raw0 = float(np.clip(raw0, lo_b[1] + 1, hi_b[1] - 1))
        sol = least_squares(lambda t: (model(t) - values) / stds, [nominal0, raw0], bounds=(lo_b, hi_b),
                            x_scale="jac", max_nfev=400)
        if best is None or sol.cost < best.cost:
            best = sol
    sd = float(np.sqrt(max(jacobian_covariance(best.jac)[1, 1], 0.0)))  # NaN stays NaN: max(nan, 0) is nan
    raw = float(best.x[1])
    el = cls(**{cls.strength: strength(raw)}, **extra)
    ci = [strength(raw - 1.96 * sd), strength(raw + 1.96 * sd)]
    sig = cls.reads[0]
    return el, {cls.strength: ci}, float(best.x[0]), [float(r[sig]) for r in rms]


def _strength_starts(cls, rms, values):
    """A few starting strengths from the change between the extreme levels."""
    sig = cls.reads[0]
    r = np.array([float(x[sig]) for x in rms])
    dv = values[np.argmax(r)] - values[np.argmin(r)]
    if cls.strength == "k3":
        return [dv / (3 * max(r.max() ** 2 - r.min() ** 2, TINY))]
    if cls.strength == "c2":
        return [max(dv / (np.sqrt(8 / np.pi) * max(r.max() - r.min(), TINY)), 1e-6)]
    if cls.strength == "Fc":
        return [max(-dv / (np.sqrt(2 / np.pi) * max(1 / r.min() - 1 / r.max(), TINY)), 1e-6)]
    return [r.max() * f for f in (1.0, 2.0, 4.0, 10.0, 30.0)]

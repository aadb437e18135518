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

from ...conventions import MIN_DELTA_BIC, TINY

import itertools
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from ...errors import SatmdError
from ...numerics import jacobian_covariance
from ...physics import frf
from ...physics.nonlinear import NONLINEAR, response_rms

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


class StrengthFit(NamedTuple):
    """An element fitted to the trend of its equivalent value with level (`fit_strength`).

    Attributes
    ----------
    element : the element with its fitted strength (and other fitted parameters)
    ci95 : {strength: [lo, hi]}
    nominal : the small-signal value of the linear parameter it moves
    rms : the read signal's RMS per recording
    chi2 : the trend's χ²
    n_fitted : parameters fitted (the nominal value included)
    """

    element: Any
    ci95: dict
    nominal: float
    rms: list
    chi2: float
    n_fitted: int


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

    from .stats import NonlinearTest

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
    """The first registered element class whose equivalent linearisation moves ``parameter`` that way.

    Naming ranks every such element by its trend (`rank_elements`); this is the FRF-only answer, where
    no level's signals are known.

    Parameters
    ----------
    parameter : kp, k1, cp or L
    direction : "up" or "down" with level

    Returns
    -------
    type or None
    """
    found = candidates(parameter, direction)
    return found[0] if found else None


def candidates(parameter: str, direction: str) -> list:
    """Every registered element class that moves ``parameter`` in ``direction`` with level (its ``moves``).

    Parameters
    ----------
    parameter : kp, k1, cp or L
    direction : "up" or "down"

    Returns
    -------
    list of type
    """
    return [cls for cls in NONLINEAR.values()
            if cls.linear_parameter == parameter and cls.moves in (direction, "either")]


def rank_elements(classes, values, stds, rigs, forces, fs_hz, joint_chi2: float, n_data: int) -> list:
    """Each candidate's trend fit (`fit_strength`) ranked by BIC: the joint fit's χ² plus the trend's.

    A level's equivalent value is the element's equivalent linearisation at that level's RMS; an element
    whose law bends the trend the wrong way leaves a χ² the others do not. Candidates whose strength cannot
    be fitted are left out.

    Parameters
    ----------
    classes : candidate element classes.
    values, stds, rigs, forces, fs_hz : as `fit_strength`.
    joint_chi2 : χ² of the joint fit that gave ``values``.
    n_data : number of data in that fit (BIC's log n).

    Returns
    -------
    list of dict
        {"cls", "bic", "fit": a `StrengthFit`}, best first (registration order breaks ties).
    """
    out = []
    for order, cls in enumerate(classes):
        try:
            fit = fit_strength(cls, values, stds, rigs, forces, fs_hz)
        except (SatmdError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            continue  # a candidate whose trend cannot be fitted is not ranked
        out.append({"cls": cls, "fit": fit, "order": order,
                    "bic": joint_chi2 + fit.chi2 + fit.n_fitted * np.log(max(n_data, 2))})
    return sorted(out, key=lambda r: (r["bic"], r["order"]))


def fit_strength(cls, values, stds, rigs, forces, fs_hz):
    """The element's strength (and small-signal value) from its equivalent value at each level.

    The strength and, where the levels leave a degree of freedom for each, the element's other parameters
    (those it does not hold fixed, `trend_fixed`) are fitted in the element's own coordinates.

    Parameters
    ----------
    cls : element class
    values, stds : the moving parameter per recording and its std
    rigs : equivalent linear rig per recording (for the signals' RMS at its level)
    forces : force samples per recording
    fs_hz : sample rate per recording

    Returns
    -------
    StrengthFit
    """
    from scipy.optimize import least_squares

    rms = [response_rms(rg, force=f, fs_hz=fs) for rg, f, fs in zip(rigs, forces, fs_hz)]
    values, stds = np.asarray(values, float), np.maximum(np.asarray(stds, float), 1e-12 * np.abs(values).max())
    p = cls.linear_parameter
    base_rig = rigs[0]
    top = rms[int(np.argmax([float(r[cls.reads[0]]) for r in rms]))]
    probe = cls.at_rest(base_rig)
    fixed = probe.trend_fixed(rms)
    probe = probe.replace(**fixed)
    coords = [c for c in probe.coordinates(base_rig, top) if c.name not in fixed]
    if len(values) < 2 + len(coords):  # too few levels for every parameter: the strength alone
        coords = [c for c in coords if c.name == cls.strength]
    nominal0 = float(values.min() if p != "L" else values.max())
    scale = abs(nominal0) or 1.0

    def element_at(theta):
        return probe.replace(**{c.name: float(c.decode(x)) for c, x in zip(coords, theta[1:])})

    def model(theta):
        rig0 = base_rig.replace(**{p: theta[0] * scale})
        el = element_at(theta)
        return np.array([float(np.mean(el.equivalent_value(rig0, r))) for r in rms])

    lo_b = [1e-6] + [c.bounds[0] for c in coords]
    hi_b = [1e3] + [c.bounds[1] for c in coords]
    best = None
    for start in itertools.product(*(c.starts for c in coords)):
        x0 = np.clip([nominal0 / scale, *start], np.array(lo_b) + 1e-9, np.array(hi_b) - 1e-9)
        with np.errstate(all="ignore"):
            sol = least_squares(lambda t: (model(t) - values) / stds, x0, bounds=(lo_b, hi_b), x_scale="jac",
                                max_nfev=400)
        if best is None or sol.cost < best.cost:
            best = sol
    if best is None or not np.isfinite(best.cost):
        raise ValueError(f"{cls.name}: no strength fits the trend")
    el = element_at(best.x)
    i = 1 + [c.name for c in coords].index(cls.strength)
    sd = float(np.sqrt(max(jacobian_covariance(best.jac)[i, i], 0.0)))  # NaN stays NaN: max(nan, 0) is nan
    c = coords[i - 1]
    ends = sorted(float(c.decode(best.x[i] + z * sd)) for z in (-1.96, 1.96))
    sig = cls.reads[0]
    return StrengthFit(el, {cls.strength: ends}, float(best.x[0] * scale), [float(r[sig]) for r in rms],
                       2 * float(best.cost), 1 + len(coords))

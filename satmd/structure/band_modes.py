"""The modes in the force's band refined with the joint's law, by output error in time.

The linear part's poles come from the lowest level's FRF (or, for the structure under the joint, from every
level's spectra), and the output-error fits move the joint alone. But the lowest level already holds the joint
linearised: a friction contact that slips a little there damps and softens the modes it takes part in, and the
joint's linear terms (``d``, ``v``) can take that back only through its one path, not mode by mode. The fitted
levels then show it as a misfit at the resonances, largest at the lowest level. Here the in-band modes'
frequencies and damping ratios and the law's coefficients are fitted together on every recording, every
channel's residues, joint's column and feed-through solved inside each step (`outputs.Projection`); the path
κ and the shape constants are held. On independent ground vibration tests (`benchmarks/structures_gvt.py`,
place and law found), a wing's friction joint went from worst NRMSE 0.060, 0.042, 0.026 (level 1 fitted, levels 2
and 6 held out) to 0.013, 0.014, 0.016 (its noise 0.012), a beam's friction support from 0.046, 0.036, 0.036 to
0.016, 0.016, 0.033 (its noise 0.011). On the F-16 (levels 1, 3, 7 fitted) the fitted levels' worst came from
0.19, 0.20, 0.44 to 0.17, 0.16, 0.42 and held-out level 5 from 0.284, 0.279, 0.394 to 0.261, 0.282, 0.402.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .output_error import half_widths
from .outputs import Projection
from .simulations import drives_of

MAX_NFEV = 8            # steps of the fit: most of what it gains, it gains in the first few
#: ... fewer where a step (a simulation of every record per parameter) would simulate more samples than this over
#: them all: the F-16's four levels (131 072 samples, ten modes and three coefficients) get 5 steps, 40 s, so that
#: `discover` stays within 5 minutes; a ground vibration test's 32 768 samples, 8 steps up to 30 parameters
SAMPLE_EVALUATIONS = 16_000_000
STEP = 2                # every STEP-th sample of the residuals (the records are band-limited well below Nyquist)
FREQUENCY_SPAN = 0.2    # a mode's frequency moves at most this far (in log) from the start: it stays the mode it was
ZETA = (1e-4, 0.9)      # the damping ratios are held within these


def in_band(poles, band_hz) -> np.ndarray:
    """Indices of the poles whose natural frequency lies in the force's band (``band_hz`` (lo, hi) Hz).

    Parameters
    ----------
    poles : (P,) complex, rad/s
    band_hz : (lo, hi) Hz

    Returns
    -------
    (k,) int
    """
    f = np.abs(np.asarray(poles)) / (2 * np.pi)
    return np.flatnonzero((f >= band_hz[0]) & (f <= band_hz[1]))


def with_band_modes_refined(model, recordings, measured, span, band_hz, max_nfev: int = MAX_NFEV):
    """``model`` with its in-band modes' poles and its law's coefficients fitted on the records' first ``span``
    samples, every channel solved inside; None where it has no joint or no mode in the band, a step runs away, or
    the fit gains nothing.

    Parameters
    ----------
    model : StructureModel with a joint (its path and channels fitted)
    recordings : the Recordings it was fitted on
    measured : (C, span) responses of each recording, in the model's channel order
    span : samples of each recording the fit uses (`simulations.fit_span`)
    band_hz : (lo, hi) Hz of the force's band (`fit.fitted_band`)
    max_nfev : steps of the least squares at most (fewer for long records, `SAMPLE_EVALUATIONS`)

    Returns
    -------
    StructureModel (the law's coefficients' intervals widened by the poles' uncertainty) or None
    """
    from scipy.optimize import least_squares

    j, lin = model.joint, model.linear
    if j is None:
        return None
    idx = in_band(lin.poles, band_hz)
    if idx.size == 0:
        return None
    n_c, p0 = j.coefficients.size, lin.poles[idx]

    def build(theta):
        f, zeta = np.exp(theta[n_c::2]), np.exp(theta[n_c + 1::2])
        poles = lin.poles.copy()
        poles[idx] = 2 * np.pi * f * (-zeta + 1j * np.sqrt(1 - zeta ** 2))
        return replace(model, linear=replace(lin, poles=poles), joint=replace(j, coefficients=theta[:n_c]))

    def projected(theta):
        trial = build(theta)
        return Projection(trial, drives_of(trial, recordings, measured, span), STEP), trial.joint

    def residual(theta):
        projection, joint = projected(theta)
        answer = projection.solve(joint)
        return failed if answer is None or not np.all(np.isfinite(answer[0])) else answer[0]

    log_f, log_zeta = np.log(np.abs(p0) / (2 * np.pi)), np.log(np.clip(-p0.real / np.abs(p0), *ZETA))
    theta0 = np.concatenate([j.coefficients, np.column_stack([log_f, log_zeta]).ravel()])
    projection, joint = projected(theta0)
    start = projection.solve(joint)
    if start is None or not np.all(np.isfinite(start[0])):
        return None
    failed = np.full(start[0].size, 1e3 / np.sqrt(start[0].size))
    lower = np.concatenate([np.full(n_c, -np.inf), np.column_stack([log_f - FREQUENCY_SPAN,
                                                                    np.full(idx.size, np.log(ZETA[0]))]).ravel()])
    upper = np.concatenate([np.full(n_c, np.inf), np.column_stack([log_f + FREQUENCY_SPAN,
                                                                   np.full(idx.size, np.log(ZETA[1]))]).ravel()])
    scale = np.concatenate([np.maximum(np.abs(j.coefficients), 1e-3 * float(np.abs(j.coefficients).max() or 1.0)),
                            np.tile([0.01, 0.3], idx.size)])
    steps = min(max_nfev, max(2, SAMPLE_EVALUATIONS // ((theta0.size + 1) * sum(span))))
    sol = least_squares(residual, np.clip(theta0, lower + 1e-12, upper - 1e-12), x_scale=scale, diff_step=1e-5,
                        bounds=(lower, upper), max_nfev=steps)
    if not 2 * sol.cost < float(start[0] @ start[0]):
        return None
    projection, joint = projected(sol.x)
    answer = projection.solve(joint)
    if answer is None:
        return None
    fitted = answer[1]
    return replace(fitted, joint=replace(fitted.joint, ci95=_intervals(j, fitted.joint, half_widths(
        sol.jac, sol.fun, projection.runs))))


def _intervals(before, after, half) -> dict:
    """The coefficients' 95 % intervals about their new values: this fit's half-widths (the poles' uncertainty)
    and the ones they had (the path's, which this fit holds), added in quadrature; none where either is unknown."""
    ci, names = {}, list(after.parameters())
    for i, c in enumerate(after.coefficients):
        had = before.ci95.get(names[i])
        if had is not None and half is not None and np.isfinite(half[i]):
            h = float(np.hypot(half[i], 0.5 * (had[1] - had[0])))
            ci[names[i]] = [float(c) - h, float(c) + h]
    ci.update({k: v for k, v in before.ci95.items() if k not in names[:after.coefficients.size]})  # shapes: held
    return ci

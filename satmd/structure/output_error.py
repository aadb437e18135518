"""The output-error fit of a structure's joint: least squares of its simulated responses on every recording."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import TINY
from ..numerics import jacobian_covariance
from .laws import SHAPE_GRID
from .model import StructureModel
from .outputs import Projection

#: how far (in log, either way) a shape constant may move from its start: a factor of 1e13, wider than anything a
#: stroke or a velocity can tell apart, yet a step of the least squares never reaches 0 or inf (on a structure with
#: no joint a saturating spring's stroke was stepped to exp(-1421) = 0, and the law divided by it)
LOG_SHAPE_SPAN = 30.0


def output_error(model, drives, ref, max_nfev, fixed_path=False, solved=True) -> StructureModel:
    """Least squares of the simulated responses on every recording: the law's coefficients, its shape constants
    (in log: a gap, a friction's smoothing) and, unless ``fixed_path``, the path κ (then the law's first
    coefficient is held: it fixes the scale the path shares).

    With the path free, every channel's residues, joint's column and feed-through are solved inside each step
    (`outputs.Projection`) and returned so: the path then moves for the joint's force and its feedback alone.
    Moved with every channel's coefficients tied to it (the column the force's times κ, re-solved only after), on
    independent ground vibration tests (place and law given) the worst held-out NRMSE of ten near misses was
    0.074, 0.131, 0.038, 0.041 where solved inside the fit it is 0.050, 0.083, 0.022, 0.032 (a chain's cubic
    joint, a beam's friction support, a chain's cubic, a beam's saturating support); 7 of the 10 fell, two moved
    under 0.001, one rose (a wing's friction joint, 0.042 to 0.050 at level 2). Freed from the channels, the path
    can also reach a loop that gathers energy over more periods than the fit sees (on the F-16 at level 7, from
    its eighth period): ``solved=False`` ties them again."""

    from scipy.optimize import least_squares

    j = model.joint
    n_c = j.coefficients.size
    shaped = [i for i, t in enumerate(j.terms) if t in SHAPE_GRID]
    log_aux = np.log(j.aux[shaped])
    step = max(1, int(ref.fs_hz / (8 * ref.freq_hz[-1])))  # the responses are band-limited well below Nyquist
    scales = [m.std(axis=1, keepdims=True) for _, m in drives]

    n_free = n_c if fixed_path else n_c - 1  # with the path free, the law's first term's size fixes the scale
    projection = None if fixed_path or not solved else Projection(model, drives, step)

    def unpack(theta):
        c = theta[:n_c] if fixed_path else np.concatenate([j.coefficients[:1], theta[:n_c - 1]])
        aux = j.aux.copy()
        aux[shaped] = shape_constants(theta[n_free:n_free + len(shaped)], log_aux)
        if fixed_path:
            return replace(j, coefficients=c, aux=aux)
        k = theta[n_free + len(shaped):]
        return replace(j, coefficients=c, aux=aux, coupling=k[0::2] + 1j * k[1::2])

    def residual(theta):
        trial = unpack(theta)
        if projection is not None:
            answer = projection.solve(trial)
            return np.full(projection.size, 1e3 / np.sqrt(projection.size)) if answer is None else answer[0]
        out = []
        for (drive, measured), sd in zip(drives, scales):
            e = (drive.outputs(trial, step) - measured[:, ::step]) / sd
            e = np.clip(np.nan_to_num(e, nan=1e3), -1e3, 1e3)  # a run-away: large, finite, smooth enough to step
            out.append(e.ravel() / np.sqrt(e.size))
        return np.concatenate(out)

    k0 = np.zeros(0) if fixed_path else np.column_stack([j.coupling.real, j.coupling.imag]).ravel()
    theta0 = np.concatenate([j.coefficients if fixed_path else j.coefficients[1:], log_aux, k0])
    scale = np.maximum(np.abs(theta0), 1e-3 * (np.abs(theta0).max() or 1.0))
    scale[scale == 0] = 1.0
    scale[n_free:n_free + len(shaped)] = 1.0  # a log: steps of order one
    sol = least_squares(residual, theta0, x_scale=scale, diff_step=1e-4, max_nfev=max_nfev)
    start = residual(theta0)
    if sol.cost > 0.5 * float(start @ start):  # never worse than where it started
        return replace(model, joint=unpack(theta0))
    joint = unpack(sol.x)
    if projection is not None:
        answer = projection.solve(joint)
        model = model if answer is None else answer[1]
        joint = model.joint if answer is not None else joint
    half = half_widths(sol.jac, sol.fun, [m[:, ::step].shape[1] for _, m in drives for _channel in m])
    if half is None:
        return replace(model, joint=joint)
    names = list(joint.parameters())
    ci = {}
    for i, c in enumerate(joint.coefficients):  # (with the path free, the first is held: no interval)
        if fixed_path or i > 0:
            h = float(half[i if fixed_path else i - 1])
            ci[names[i]] = [float(c) - h, float(c) + h]
    for k, i in enumerate(shaped):  # a shape constant was fitted in log: its interval is a factor either side
        h = float(half[n_free + k])
        with np.errstate(over="ignore"):  # a shape the records leave open: its interval is unbounded, [0, inf]
            ci[names[n_c + k]] = [float(joint.aux[i] * np.exp(-h)), float(joint.aux[i] * np.exp(h))]
    return replace(model, joint=replace(joint, ci95=ci))


def shape_constants(log_trial, log_start) -> np.ndarray:
    """The shape constants of a step of the least squares (their logs), kept within `LOG_SHAPE_SPAN` of the start."""
    return np.exp(np.clip(log_trial, log_start - LOG_SHAPE_SPAN, log_start + LOG_SHAPE_SPAN))


def half_widths(jac, residuals, sizes):
    """95 % half-widths of the fitted parameters: (JᵀJ)⁻¹ scaled by the residuals' variance, inflated by
    (1 + ρ)/(1 − ρ) for their lag-one correlation ρ in time (a simulation's misfit is smooth, not white: without it
    the intervals would count every sample as news); ``sizes``: the residuals' runs in time, one per channel and
    recording. None when JᵀJ is singular (`numerics.jacobian_covariance`)."""
    jac = np.asarray(jac, float)
    n, p = jac.shape
    if n <= p:
        return None
    edges = np.cumsum([0, *sizes])
    pairs = [(residuals[a:b - 1], residuals[a + 1:b]) for a, b in zip(edges[:-1], edges[1:]) if b - a > 2]
    rho = float(sum(x @ y for x, y in pairs) / max(sum(x @ x for x, _ in pairs), TINY)) if pairs else 0.0
    rho = min(max(rho, 0.0), 0.999)
    cov = jacobian_covariance(jac, float(residuals @ residuals) / (n - p) * (1 + rho) / (1 - rho))
    var = np.diag(cov)
    if not np.all(np.isfinite(var)):
        return None
    return np.where(var >= 0, 1.96 * np.sqrt(np.abs(var)), np.nan)

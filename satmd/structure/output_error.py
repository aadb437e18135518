"""The output-error fits of a structure's joint: least squares of its simulated responses on every recording.

`output_error` moves the joint (its law's coefficients and shape constants, and its path). `with_band_modes_refined`,
the fit's last stage, moves the modes in the force's band with the law's coefficients, then those above it too:

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
0.19, 0.20, 0.44 to 0.17, 0.16, 0.42 and held-out level 5 from 0.284, 0.279, 0.394 to 0.268, 0.273, 0.395.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import TINY
from ..numerics import jacobian_covariance, threaded_differences
from .laws import SHAPE_GRID
from .model import StructureModel
from .outputs import Projection
from .simulations import drives_of

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
    fun, jac = threaded_differences(residual, 1e-4)
    sol = least_squares(fun, theta0, jac=jac, x_scale=scale, max_nfev=max_nfev)
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


BAND_STEPS = 8          # steps of the band's refit: most of what it gains, it gains in the first few
#: ... fewer where a step (a simulation of every record per parameter) would simulate more samples than this over
#: them all: the F-16's four levels (131 072 samples, ten modes and three coefficients) get 5 steps, 40 s, so that
#: `discover` stays within 5 minutes; a ground vibration test's 32 768 samples, 8 steps up to 30 parameters
SAMPLE_EVALUATIONS = 16_000_000
BAND_STEP = 2           # every BAND_STEP-th sample of the residuals (the records are band-limited well below Nyquist)
FREQUENCY_SPAN = 0.2    # a mode's frequency moves at most this far (in log) from the start: it stays the mode it was
ZETA = (1e-4, 0.9)      # the damping ratios are held within these
TOP = 0.95              # of the Nyquist frequency: a mode above the band stays below it


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


def with_band_modes_refined(model, recordings, measured, span, band_hz, max_nfev: int = BAND_STEPS):
    """``model`` with the poles of its modes in ``band_hz`` (below `TOP` of the Nyquist frequency) and its law's
    coefficients fitted on the records' first ``span`` samples, every channel solved inside; None where it has no
    joint or no such mode, a step runs away, or the fit gains nothing.

    Parameters
    ----------
    model : StructureModel with a joint (its path and channels fitted)
    recordings : the Recordings it was fitted on
    measured : (C, span) responses of each recording, in the model's channel order
    span : samples of each recording the fit uses (`simulations.fit_span`)
    band_hz : (lo, hi) Hz of the modes to move: the force's band (`fit.fitted_band`), or from its foot up
    max_nfev : steps of the least squares at most (fewer for long records, `SAMPLE_EVALUATIONS`)

    Returns
    -------
    StructureModel (the law's coefficients' intervals widened by the poles' uncertainty) or None
    """
    j, lin = model.joint, model.linear
    if j is None:
        return None
    nyquist = float(recordings[0].fs_hz) / 2
    idx = in_band(lin.poles, (band_hz[0], min(band_hz[1], TOP * nyquist)))
    if idx.size == 0:
        return None
    n_c, p0 = j.coefficients.size, lin.poles[idx]
    top = np.log(TOP * nyquist)

    def build(theta):
        f, zeta = np.exp(theta[n_c::2]), np.exp(theta[n_c + 1::2])
        poles = lin.poles.copy()
        poles[idx] = 2 * np.pi * f * (-zeta + 1j * np.sqrt(1 - zeta ** 2))
        return replace(model, linear=replace(lin, poles=poles), joint=replace(j, coefficients=theta[:n_c]))

    log_f, log_zeta = np.log(np.abs(p0) / (2 * np.pi)), np.log(np.clip(-p0.real / np.abs(p0), *ZETA))
    theta0 = np.concatenate([j.coefficients, np.column_stack([log_f, log_zeta]).ravel()])
    lower = np.concatenate([np.full(n_c, -np.inf), np.column_stack([log_f - FREQUENCY_SPAN,
                                                                    np.full(idx.size, np.log(ZETA[0]))]).ravel()])
    upper = np.concatenate([np.full(n_c, np.inf), np.column_stack([np.minimum(log_f + FREQUENCY_SPAN, top),
                                                                   np.full(idx.size, np.log(ZETA[1]))]).ravel()])
    problem = ProjectedFit(build, (recordings, measured, span), BAND_STEP, (lower, upper), 1e-5)
    start = problem.answer(theta0)
    if start is None:
        return None
    scale = np.concatenate([np.maximum(np.abs(j.coefficients), 1e-3 * float(np.abs(j.coefficients).max() or 1.0)),
                            np.tile([0.01, 0.3], idx.size)])
    steps = min(max_nfev, max(2, SAMPLE_EVALUATIONS // ((theta0.size + 1) * sum(span))))
    sol = problem.least_squares(np.clip(theta0, lower + 1e-12, upper - 1e-12), scale, steps)
    if not 2 * sol.cost < float(start[0] @ start[0]):
        return None
    result = problem.result(sol)
    if result is None:
        return None
    fitted, half = result
    return replace(fitted, joint=replace(fitted.joint, ci95=_intervals(j, fitted.joint, half)))


class ProjectedFit:
    """A bounded least squares over trial models ``build(θ)``, each with every channel's residues, joint's column
    and feed-through solved inside (`outputs.Projection`): the shape `with_band_modes_refined` and
    `loop.with_loop_modes` share (they move poles with the law's coefficients). Its Jacobian's columns run on
    threads (`numerics.threaded_differences`, least squares' own steps of ``rel_step``); a trial whose joint runs
    away answers a large constant misfit, so that least squares steps back.

    Parameters
    ----------
    build : callable(θ) -> StructureModel
    records : (recordings, measured, span) as `simulations.drives_of` takes them
    step : every step-th sample of the residuals
    bounds : (lower, upper) of θ
    rel_step : the forward differences' relative step
    """

    def __init__(self, build, records, step: int, bounds, rel_step: float):
        self.build, self.records, self.step, self.bounds = build, records, int(step), bounds
        self.failed: np.ndarray | None = None  # the misfit of a trial that ran away: sized by the first that did not
        self.fun, self.jac = threaded_differences(self.residuals, rel_step, bounds)

    def projection(self, theta):
        """(`outputs.Projection` of the trial model at θ, its joint)."""
        trial = self.build(theta)
        return Projection(trial, drives_of(trial, *self.records), self.step), trial.joint

    def answer(self, theta):
        """(weighted residuals, the trial model with every channel solved) at θ; None where the joint ran away."""
        projection, joint = self.projection(theta)
        answer = projection.solve(joint)
        if answer is None or not np.all(np.isfinite(answer[0])):
            return None
        if self.failed is None:
            self.failed = np.full(answer[0].size, 1e3 / np.sqrt(answer[0].size))
        return answer

    def residuals(self, theta) -> np.ndarray:
        answer = self.answer(theta)
        if answer is not None:
            return answer[0]
        if self.failed is None:  # the callers answer a start first: a fit never starts from a run-away
            raise ValueError("no trial of this fit has answered yet: nothing to size a run-away's misfit by")
        return self.failed

    def least_squares(self, theta, x_scale, max_nfev: int):
        """`scipy.optimize.least_squares` from θ (within the bounds), at most ``max_nfev`` steps."""
        from scipy.optimize import least_squares

        return least_squares(self.fun, theta, jac=self.jac, x_scale=x_scale, bounds=self.bounds, max_nfev=max_nfev)

    def result(self, sol):
        """(the model at the fit's θ, its parameters' 95 % half-widths or None); None where its joint ran away."""
        projection, joint = self.projection(sol.x)
        answer = projection.solve(joint)
        if answer is None:
            return None
        return answer[1], half_widths(sol.jac, sol.fun, projection.runs)


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

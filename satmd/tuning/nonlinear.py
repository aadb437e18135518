"""Tune the shunt for a nonlinear rig across drive levels (issue 27 item 4).

Objective: the worst case over the stated drive levels of the H∞ peak of |U1/F| (or |A1/F|)
over the band, where the FRF at a level is what a test at that level measures: the H1 of
the response to a band-limited random force of that RMS (the best linear approximation).

1. Equivalent linearisation gives each level's FRF in closed form (`equivalent_rig`);
   the minimax over levels of its peak is minimised over (log R, log L) (Nelder-Mead,
   from the low-level linear optimum). Cheap: FRF calls only.
2. Direct simulation settles it: two rounds of a 5 x 5 grid in (log R, log L) around the
   best point, every candidate and level simulated by the integrator (one batched call per
   level, the same force for all: common random numbers), the peak read from H1.
3. The low-level linear tuning (the linear rig's minimax) is simulated the same way: its
   worst case minus the nonlinear tuning's is the cost of ignoring the nonlinearity.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from numbers import Integral, Real
from typing import cast

import numpy as np
from scipy.optimize import minimize
from scipy.signal import csd, welch

from ..errors import DataError
from ..physics import Rig, frf
from ..physics.nonlinear import equivalent_rig, integrate
from ..physics.nonlinear.excitation import random_force
from ..validation import Band, Interval, Options, validate_params
from ..conventions import PAPER_BAND_HZ


@dataclass(frozen=True)
class NonlinearTuneResult:
    """Shunt design for a nonlinear rig across drive levels.

    Parameters
    ----------
    design : {"R", "L"} minimising the worst-case peak over levels (direct simulation).
    peaks_db : peak of |U1/F| (dB re 1 m/N) per level at ``design``, by direct simulation.
    worst_db : max of ``peaks_db``.
    linear_design : {"R", "L"} of the low-level linear tuning.
    linear_peaks_db : its peaks per level, by direct simulation.
    cost_of_linear_db : worst case of the linear tuning minus ``worst_db``.
    equivalent_design : the equivalent-linearisation minimax (step 1).
    levels : drive levels (force RMS, N).
    settings : band, output, record, seed.
    wall_time : seconds.
    """

    design: dict
    peaks_db: list
    worst_db: float
    linear_design: dict
    linear_peaks_db: list
    cost_of_linear_db: float
    equivalent_design: dict
    levels: list
    settings: dict = field(default_factory=dict)
    wall_time: float = 0.0

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return {k: getattr(self, k) for k in ("design", "peaks_db", "worst_db", "linear_design", "linear_peaks_db",
                                              "cost_of_linear_db", "equivalent_design", "levels", "settings",
                                              "wall_time")}

    def report(self) -> str:
        """Designs and their worst cases in words."""
        lv = ", ".join(f"{x:g}" for x in self.levels)
        return (f"tuned across drive levels {lv} N: R = {self.design['R']:.4g} Ω, L = {self.design['L']:.4g} H, "
                f"worst-case peak {self.worst_db:.2f} dB (direct simulation)\n"
                f"the low-level linear tuning (R = {self.linear_design['R']:.4g} Ω, L = {self.linear_design['L']:.4g} H) "
                f"reaches {max(self.linear_peaks_db):.2f} dB: it costs {self.cost_of_linear_db:.2f} dB at the worst level")


def _grid(band_hz, n=1500):
    return np.linspace(band_hz[0], band_hz[1], n)


def equivalent_peaks(rig, elements, R, L, levels, band_hz, output="u1") -> np.ndarray:
    """Peak |output/F| per level from the equivalent-linear rig at each level (R, L scalars).

    Parameters
    ----------
    rig, elements : the nonlinear rig.
    R, L : shunt design.
    levels : force RMS values [N] (band-limited white force over ``band_hz``).
    band_hz : (lo, hi).
    output : "u1" or "a1".

    Returns
    -------
    ndarray (len(levels),)
    """
    r = rig.replace(R=float(R), L=float(L))
    f = _grid(band_hz)
    out = []
    for lev in levels:
        eq = equivalent_rig(r, elements, band_hz, lev, iterations=30, rtol=1e-5, n_grid=2500)[0] if elements else r
        out.append(np.max(np.abs(frf(f, eq, outputs=(output,)).channel(output))))
    return np.array(out)


def simulated_peaks(rig, elements, R, L, levels, band_hz, output="u1", duration_s=40.0, fs_hz=1024.0,
                    seed=0) -> np.ndarray:
    """Peak |H1(output/F)| per design and level by direct simulation (the same force for every design).

    Parameters
    ----------
    rig, elements : the nonlinear rig.
    R, L : arrays of designs (same length P).
    levels : force RMS values [N].
    band_hz : (lo, hi) of the force and of the peak search.
    output : "u1" or "a1".
    duration_s, fs_hz : the simulated test.
    seed : seed of the force.

    Returns
    -------
    ndarray (P, len(levels))
    """
    R, L = np.atleast_1d(np.asarray(R, float)), np.atleast_1d(np.asarray(L, float))
    n = int(duration_s * fs_hz)
    unit = random_force(n, fs_hz, band_hz, np.random.default_rng(seed))
    skip = int(2.0 * fs_hz)
    nper = int(4 * fs_hz)
    f, pff = welch(unit[skip:], fs_hz, nperseg=nper)
    keep = (f >= band_hz[0]) & (f <= band_hz[1])
    out = np.empty((R.size, len(levels)))
    batch = rig.replace(R=R, L=L)
    for j, lev in enumerate(levels):
        els = list(elements)
        r = integrate(batch, lev * unit, fs_hz, els, outputs=(output,), oversample=2 if els else 1)
        y = np.atleast_2d(r.signals[output])
        _, pfy = csd(unit[skip:] * lev, y[:, skip:], fs_hz, nperseg=nper, axis=-1)
        out[:, j] = np.max(np.abs(pfy[:, keep] / (lev * lev * pff[keep])), axis=1)
    return out


def _db(x):
    return 20 * np.log10(x)


@validate_params({"rig": [Rig], "band_hz": [Band()], "output": [Options(("u1", "a1"))],
                  "duration_s": [Interval(Real, 0, open="lo")], "fs_hz": [Interval(Real, 0, open="lo")],
                  "seed": [Interval(Integral, 0)]})
def tune_nonlinear(rig: Rig, elements, levels, band_hz=PAPER_BAND_HZ, output: str = "u1",
                   duration_s: float = 40.0, fs_hz: float = 1024.0, seed: int = 0,
                   bounds=((0.1, 1000.0), (1e-3, 5.0))) -> NonlinearTuneResult:
    """R, L that keep the peak of |output/F| lowest over a range of drive levels (see the module docstring).

    Parameters
    ----------
    rig : the (fitted) linear part of the rig.
    elements : its nonlinear elements (e.g. ``[fit.element]`` from `fit_nonlinear`).
    levels : drive levels, force RMS [N] (e.g. ``[1, 3, 10]``).
    band_hz : (lo, hi) of the force and of the peak.
    output : "u1" (displacement, SPEC §10 default) or "a1".
    duration_s, fs_hz, seed : the simulated test that judges each design.
    bounds : ((R_lo, R_hi), (L_lo, L_hi)).

    Returns
    -------
    NonlinearTuneResult
    """
    t0 = time.perf_counter()
    levels = [float(x) for x in levels]
    if not levels or min(levels) <= 0:
        raise DataError("tune across levels needs at least one drive level > 0")
    lo = np.log([bounds[0][0], bounds[1][0]])
    hi = np.log([bounds[0][1], bounds[1][1]])

    def minimax(fun, x0):
        best = None
        for start in x0:
            res = minimize(lambda x: fun(np.clip(x, lo, hi)), start, method="Nelder-Mead",
                           options={"xatol": 1e-4, "fatol": 1e-7, "maxiter": 400})
            if best is None or res.fun < best.fun:
                best = res
        return np.clip(best.x, lo, hi)

    def rl(x) -> tuple[float, float]:  # (R, L) at (log R, log L); cast: mypy cannot size an array's unpacking
        return cast("tuple[float, float]", np.exp(x))

    starts = [np.log([float(rig.R), float(rig.L)]), np.log([40.0, 0.2]), np.log([20.0, 0.08])]
    x_lin = minimax(lambda x: _db(np.max(equivalent_peaks(rig, [], *rl(x), [1.0], band_hz, output))), starts)
    x_eq = minimax(lambda x: _db(np.max(equivalent_peaks(rig, elements, *rl(x), levels, band_hz, output))),
                   [x_lin])
    sim = dict(band_hz=band_hz, output=output, duration_s=duration_s, fs_hz=fs_hz, seed=seed)
    x = x_eq
    for span in (0.12, 0.03):  # two rounds of a 5 x 5 grid in (log R, log L)
        gr, gl = np.meshgrid(np.linspace(-1, 1, 5) * span, np.linspace(-1, 1, 5) * span / 3, indexing="ij")
        X = np.clip(x + np.stack([gr.ravel(), gl.ravel()], axis=1), lo, hi)
        worst = _db(simulated_peaks(rig, elements, np.exp(X[:, 0]), np.exp(X[:, 1]), levels, **sim)).max(axis=1)
        x = X[int(np.argmin(worst))]
    peaks = _db(simulated_peaks(rig, elements, *rl(x), levels, **sim))[0]
    lin_peaks = _db(simulated_peaks(rig, elements, *rl(x_lin), levels, **sim))[0]
    return NonlinearTuneResult(
        design={"R": float(np.exp(x[0])), "L": float(np.exp(x[1]))}, peaks_db=[float(p) for p in peaks],
        worst_db=float(peaks.max()), linear_design={"R": float(np.exp(x_lin[0])), "L": float(np.exp(x_lin[1]))},
        linear_peaks_db=[float(p) for p in lin_peaks], cost_of_linear_db=float(lin_peaks.max() - peaks.max()),
        equivalent_design={"R": float(np.exp(x_eq[0])), "L": float(np.exp(x_eq[1]))}, levels=levels,
        settings={**sim, "band_hz": list(band_hz), "peak": f"H1 of {output}/force, dB re 1 unit/N"},
        wall_time=time.perf_counter() - t0)

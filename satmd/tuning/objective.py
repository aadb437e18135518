"""Tuning objectives: H∞ (true peak) and H2 (band RMS) of |U1| or |A1| over a band (SPEC §10).

Both are computed for a whole batch of rigs at once (designs, or parameter
draws for robust tuning), through the physics' own `terms`/`solve`:

- a log-spaced base grid over the band (relative step ``rel_step``);
- every local maximum of the sampled magnitude (the ``N_PEAKS`` highest) is
  refined by a vectorised bracketing search in frequency: 17 points across the
  bracket, keep the two neighbours of the best, four times (the bracket
  shrinks to ~2e-6 of the frequency), then one exact evaluation at the vertex
  of the parabola through the best three. H∞ is the largest refined peak or
  band edge, so it is the true peak, not a grid sample;
- H2 = sqrt(∫|H|² df / (hi − lo)) by the trapezoid rule on the base grid,
  except in a window around each refined peak (half-power half-width w),
  where it is the trapezoid rule in t with f = f_p + w·sinh(t), 101 points:
  there a resonance's |H|² df is ~ sech(t) dt, smooth and well sampled, so the
  sharpest peak is resolved whatever its width.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ..conventions import TINY
from ..errors import DataError
from ..physics.effects import Effect
from ..physics.model import solve, terms
from ..physics.rig import Rig

OBJECTIVES = ("hinf", "h2")
OUTPUTS = ("u1", "a1")
N_PEAKS = 3  # local maxima refined per rig
ZOOM_POINTS = 17  # the bracket shrinks by 8 per pass
ZOOM_PASSES = 4  # 0.8 % of f -> 2e-6 of f, then a parabolic step
WINDOW = 0.05  # H2: each peak's window reaches ±5 % of its frequency (less where peaks are closer)
_T = np.linspace(0.0, 1.0, ZOOM_POINTS)
_S = np.linspace(0.0, 1.0, 101)  # points per peak window


def band_grid(band_hz: tuple[float, float], rel_step: float = 0.004) -> np.ndarray:
    """Log-spaced frequencies over a band.

    Parameters
    ----------
    band_hz : (lo, hi) in Hz
    rel_step : relative spacing of neighbouring points (at least 64 points)

    Returns
    -------
    ndarray of frequencies in Hz, both ends included
    """
    lo, hi = band_hz
    n = max(64, int(np.ceil(np.log(hi / lo) / rel_step)) + 1)
    return np.geomspace(lo, hi, n)


def as_batch(rig: Rig, effects: Sequence[Effect]) -> tuple[Rig, list, int]:
    """Rig and effects with every array field as a column (B, 1), so they broadcast against
    frequencies of shape (B, M) or (M,); B = 1 when everything is scalar."""
    sizes = {np.size(v) for v in rig.as_dict().values() if np.ndim(v)}
    sizes |= {np.size(v) for e in effects for v in e.params.values() if np.ndim(v)}
    if len(sizes) > 1:
        raise DataError(f"rig and effect batches must have one length, got {sorted(sizes)}")
    if not sizes:
        return rig, list(effects), 1

    def col(v):
        return np.asarray(v, float).reshape(-1, 1) if np.ndim(v) else v

    rig = Rig(**{k: col(v) for k, v in rig.as_dict().items()})
    effects = [e.replace(**{k: col(v) for k, v in e.params.items()}) for e in effects]
    return rig, effects, sizes.pop()


def magnitude(freq_hz, rig: Rig, effects: Sequence[Effect], output: str) -> np.ndarray:
    """|output| from the physics' closed-form solve (no validation: the callers keep inside bounds).

    Parameters
    ----------
    freq_hz : array in Hz, any shape broadcasting with the rig's fields
    rig, effects : the model
    output : a channel name (u1, a1, ...)

    Returns
    -------
    ndarray of magnitudes, the broadcast shape
    """
    omega = 2.0 * np.pi * np.asarray(freq_hz, float)
    return np.abs(solve(terms(omega, rig, effects))[output])


@dataclass(frozen=True)
class Objective:
    """H∞ or H2 of |U1| or |A1| over a band, for batches of rigs.

    Parameters
    ----------
    kind : "hinf" (peak) or "h2" (RMS over the band)
    output : "u1" (displacement, m/N) or "a1" (measured acceleration, m/s²/N)
    band : (lo, hi) in Hz
    rel_step : relative spacing of the base grid (default 0.004 for H∞, whose
        peaks are refined anyway, 0.002 for H2: its trapezoid error between
        peaks is then ~5e-5)
    """

    kind: str
    output: str
    band: tuple
    rel_step: float | None = None
    grid: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if self.kind not in OBJECTIVES:
            raise DataError(f"objective must be one of {', '.join(OBJECTIVES)}, got {self.kind!r}")
        if self.output not in OUTPUTS:
            raise DataError(f"output must be one of {', '.join(OUTPUTS)}, got {self.output!r}")
        try:
            lo, hi = (float(b) for b in self.band)
        except (TypeError, ValueError):
            raise DataError(f"band must be (lo, hi) in Hz, got {self.band!r}") from None
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
            raise DataError(f"band must satisfy 0 < lo < hi (finite), got {self.band!r}")
        object.__setattr__(self, "band", (lo, hi))
        if self.rel_step is None:
            object.__setattr__(self, "rel_step", 0.004 if self.kind == "hinf" else 0.002)
        object.__setattr__(self, "grid", band_grid((lo, hi), self.rel_step))

    def __call__(self, rig: Rig, effects: Sequence[Effect] = ()) -> np.ndarray:
        """Objective for each rig of the batch: shape (B,)."""
        return self.evaluate(rig, effects)[0]

    def evaluate(self, rig: Rig, effects: Sequence[Effect] = ()):
        """(values (B,), peak frequencies (B, K), peak magnitudes (B, K))."""
        rig, effects, b = as_batch(rig, effects)

        def mag(f):
            return np.broadcast_to(magnitude(f, rig, effects, self.output), (b,) + np.shape(f)[-1:])

        grid = self.grid
        m = mag(grid)
        fpk, vpk = refine_peaks(grid, m, mag)
        if self.kind == "hinf":
            value = np.maximum(vpk.max(axis=1), np.maximum(m[:, 0], m[:, -1]))
        else:
            value = self._rms(grid, m, fpk, vpk, mag)
        return value, fpk, vpk

    def _rms(self, grid, m, fpk, vpk, mag):
        lo, hi = self.band
        seg = 0.5 * (m[:, 1:] ** 2 + m[:, :-1] ** 2) * np.diff(grid)
        cum = np.concatenate([np.zeros((len(m), 1)), np.cumsum(seg, axis=1)], axis=1)
        power = cum[:, -1].copy()
        # around each distinct peak, replace the grid's trapezoid by one in t, f = f_p + w sinh(t)
        order = np.argsort(fpk, axis=1)
        fp, vp = np.take_along_axis(fpk, order, 1), np.take_along_axis(vpk, order, 1)
        width = half_power_width(grid, m, fp, vp)
        k = fp.shape[1]
        for j in range(k):
            left = np.full(len(m), lo) if j == 0 else 0.5 * (fp[:, j - 1] + fp[:, j])
            right = np.full(len(m), hi) if j == k - 1 else 0.5 * (fp[:, j] + fp[:, j + 1])
            distinct = np.ones(len(m), bool) if j == 0 else fp[:, j] > fp[:, j - 1] * (1 + 1e-9)
            a = np.maximum(left, fp[:, j] * (1 - WINDOW))
            b = np.minimum(right, fp[:, j] * (1 + WINDOW))
            ia = np.searchsorted(grid, a, "left")
            ib = np.searchsorted(grid, b, "right") - 1
            use = distinct & (ib > ia)
            if not use.any():
                continue
            ia, ib = np.where(use, ia, 0), np.where(use, ib, 1)
            w = width[:, j]
            ta = np.arcsinh((grid[ia] - fp[:, j]) / w)
            tb = np.arcsinh((grid[ib] - fp[:, j]) / w)
            t = ta[:, None] + (tb - ta)[:, None] * _S
            g = mag(fp[:, j, None] + w[:, None] * np.sinh(t)) ** 2 * (w[:, None] * np.cosh(t))
            fine = np.sum(0.5 * (g[:, 1:] + g[:, :-1]), axis=1) * (tb - ta) / (len(_S) - 1)
            coarse = np.take_along_axis(cum, ib[:, None], 1)[:, 0] - np.take_along_axis(cum, ia[:, None], 1)[:, 0]
            power += np.where(use, fine - coarse, 0.0)
        return np.sqrt(np.maximum(power, 0.0) / (hi - lo))


def refine_peaks(grid: np.ndarray, mag: np.ndarray, fun, k: int = N_PEAKS):
    """Refine the ``k`` highest local maxima of sampled magnitudes in frequency.

    Parameters
    ----------
    grid : (F,) frequencies of the samples
    mag : (B, F) magnitudes on the grid, one row per rig
    fun : callable, frequencies (B, M) -> magnitudes (B, M)
    k : maxima refined per row (rows with fewer repeat their highest one)

    Returns
    -------
    (frequencies (B, k), magnitudes (B, k)) of the refined peaks
    """
    b, n = mag.shape
    inner = mag[:, 1:-1]
    is_max = (inner >= mag[:, :-2]) & (inner >= mag[:, 2:])
    score = np.where(is_max, inner, -np.inf)
    idx = np.argsort(-score, axis=1)[:, :k]
    ok = np.take_along_axis(score, idx, 1) > -np.inf
    fallback = np.clip(np.argmax(mag, axis=1), 1, n - 2)[:, None] - 1  # no interior maximum: near the top
    first = np.where(ok[:, :1], idx[:, :1], fallback)
    idx = np.where(ok, idx, first) + 1
    lo, hi = grid[idx - 1], grid[idx + 1]
    for _ in range(ZOOM_PASSES):
        pts = lo[..., None] + (hi - lo)[..., None] * _T  # (B, k, P)
        vals = fun(pts.reshape(b, -1)).reshape(b, k, ZOOM_POINTS)
        j = np.clip(np.argmax(vals, axis=-1), 1, ZOOM_POINTS - 2)[..., None]
        lo = np.take_along_axis(pts, j - 1, -1)[..., 0]
        hi = np.take_along_axis(pts, j + 1, -1)[..., 0]
    three = np.take_along_axis(vals, j + np.array([-1, 0, 1]), -1)  # best and its neighbours
    y0, y1, y2 = three[..., 0], three[..., 1], three[..., 2]
    curv = y0 - 2 * y1 + y2
    with np.errstate(divide="ignore", invalid="ignore"):
        shift = np.where(curv < 0, 0.25 * (y0 - y2) / curv, 0.0)  # vertex, in units of the bracket width
    mid = 0.5 * (lo + hi)
    f_vertex = mid + np.clip(shift, -0.5, 0.5) * (hi - lo)
    v_vertex = fun(f_vertex)
    better = v_vertex >= y1
    return np.where(better, f_vertex, mid), np.where(better, v_vertex, y1)


def half_power_width(grid, mag, fpk, vpk) -> np.ndarray:
    """Half-power half-width of each refined peak, from the nearest grid sample below it
    (Lorentzian shape: |H|² = P² / (1 + (Δf/w)²)); at most the band width."""
    span = grid[-1] - grid[0]
    j = np.clip(np.searchsorted(grid, fpk), 1, len(grid) - 1)
    widths = []
    for side in (j - 1, j):
        df = np.abs(grid[side] - fpk)
        ratio = (vpk / np.maximum(np.take_along_axis(mag, side, 1), TINY)) ** 2 - 1.0
        with np.errstate(divide="ignore", invalid="ignore"):
            widths.append(np.where(ratio > 1e-12, df / np.sqrt(np.maximum(ratio, 1e-12)), span))
    w = np.minimum(widths[0], widths[1])
    return np.clip(w, 1e-9 * fpk, span)

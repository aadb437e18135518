"""`follow_modes`: the modes of one structure measured at several levels, fitted level by level from one set.

Fitting every level on its own (`fit_modes`) and matching the modes afterwards (`track_modes`) loses a
resonance exactly where the structure changes most: a joint that slips damps its mode so much at the top
level that the pole search no longer shows it, and a resonance whose best linear approximation is
distorted by the nonlinearity is split into two poles there. Both are read as "no trend". Here:

1. every level is fitted on its own (`fit_modes`, poles from the stabilisation diagram, BIC pruning);
2. the set of modes: the well-determined modes of the lowest level, then those of each higher level
   that lie beyond the reach of every mode already in the set (`reach`): a pole within a resonance's
   reach is that resonance moved or split, not another mode;
3. every level, from the lowest up, is fitted again with exactly that set, each pole started from its
   value at the level below (continuation): one pole per resonance at every level, its best linear
   approximation's, its uncertainty scaled by the misfit (χ²_red) as in `fit_modes`;
4. the trends of the modes present at every level (`read_trends`).

An FRF's std from few periods (``dof`` below `MIN_STD_DOF`) is first averaged over neighbouring lines
(`smoothed_std`), and the trend tests read Student's t at the degrees of freedom that gives.
"""
from __future__ import annotations

from numbers import Real

import numpy as np

from ..validation import Band, Interval, validate_params

from .fit import Z95, Mode, fit_modes
from .tracking import MAX_MOVE, MOVE_SHARE, read_trends


def determined(mode: Mode) -> bool:
    """Whether a mode is a mode: finite intervals, a damping interval above zero, a frequency interval
    narrower than `MAX_MOVE` of its frequency."""
    return (bool(np.isfinite(mode.f_std) and np.isfinite(mode.zeta_std))
            and mode.zeta - Z95 * mode.zeta_std > 0 and Z95 * mode.f_std < MAX_MOVE * mode.f_hz)


def reach(f_hz: float, zeta: float, others, steps: int = 1) -> float:
    """How far (Hz) a resonance at ``f_hz`` may move or split between levels and still be itself: its
    half-power width, or farther, `MOVE_SHARE` of the distance to the nearest other mode (``others``, Hz)
    and at most `MAX_MOVE` of its frequency per level ``steps`` apart."""
    gaps = [abs(g - f_hz) for g in others if g != f_hz]
    return max(2.0 * zeta * f_hz, min([MOVE_SHARE * g for g in gaps] + [MAX_MOVE * f_hz * steps]))


def mode_set(fits) -> list:
    """[(f_hz, zeta), ...]: the determined modes of ``fits`` (lowest level first) that are not another's."""
    return [(f, z) for f, z, _ in mode_origins(fits)]


def mode_origins(fits) -> list:
    """`mode_set` with the index in ``fits`` of the fit each mode was taken from: [(f_hz, zeta, index), ...]."""
    out: list = []
    for j, fit in enumerate(fits):
        new = []
        for m in fit.modes:
            if not determined(m):
                continue
            fs = [f for f, _, _ in out]
            if all(abs(m.f_hz - f) > reach(f, z, fs) for f, z, _ in out):
                new.append((m.f_hz, m.zeta, j))
        out += new
    return sorted(out)


#: Degrees of freedom the std of an FRF needs before it weights a fit as it is (6 periods give 10): a std
#: from a few periods (4 degrees of freedom from 3) is itself so uncertain that the lines where it came
#: out small carry the fit, and the fit's intervals come out too narrow: on a linear structure measured
#: at two levels with 3 periods each, a damping ratio "fell" by 0.5 % at 4 of its standard errors.
MIN_STD_DOF = 10.0


def smoothed_std(std, dof):
    """``std`` ({channel: (M,)}) with its variance averaged over the fewest neighbouring lines (an odd number)
    that give it `MIN_STD_DOF` degrees of freedom, and those degrees of freedom; unchanged when it has them."""
    if std is None or dof is None or not np.isfinite(dof) or dof >= MIN_STD_DOF:
        return std, dof
    n = 2 * int(np.ceil((MIN_STD_DOF / max(dof, 1.0) - 1) / 2)) + 1
    kernel = np.ones(n) / n
    out = {}
    for c, s in std.items():
        v = np.asarray(s, float) ** 2
        mean = np.convolve(np.pad(v, n // 2, mode="edge"), kernel, mode="valid")
        out[c] = np.sqrt(mean)
    return out, dof * n


@validate_params({"alpha": [Interval(Real, 0, 1, open="both")], "band_hz": [None, Band()],
                  "dof": [None, Interval(Real, 0, open="lo")]})
def follow_modes(freq_hz, frfs, stds=None, levels=None, alpha: float = 0.05, band_hz=None, dof=None) -> list:
    """The modes of several levels of one structure, fitted from one set level by level, and their trends.

    Parameters
    ----------
    freq_hz : (M,) Hz, the grid of every level
    frfs : per level {channel: (M,) complex} (or FRFData)
    stds : per level {channel: (M,) std} or None
    levels : one level figure per FRF (default: the order given is increasing)
    alpha : family-wise level of the trend tests (Bonferroni over modes and both quantities)
    band_hz : (lo, hi) Hz to fit (default: all of ``freq_hz``)
    dof : degrees of freedom of ``stds`` (None: many); below `MIN_STD_DOF` their variances are averaged
        over neighbouring lines (`smoothed_std`) and the trend tests read Student's t at the degrees of
        freedom that gives

    Returns
    -------
    list of TrackedMode
        The modes of the set fitted at every level with a finite uncertainty, by frequency.

    Raises
    ------
    ValueError
        When the band holds too few frequencies for a modal fit.
    """
    n = len(frfs)
    stds = list(stds) if stds is not None else [None] * n
    pairs = [smoothed_std(s, dof) for s in stds]
    stds, dof = [p[0] for p in pairs], (pairs[0][1] if pairs else dof)
    order = list(np.argsort(levels, kind="stable")) if levels is not None else list(range(n))
    fits = [fit_modes(freq_hz, frfs[i], stds[i], band_hz) for i in order]
    origins = mode_origins(fits)
    if not origins:
        return []
    current = [(f, z) for f, z, _ in origins]
    # a pole taken at a higher level (lightly damped, it was determined only there) is first met at a lower
    # one it may lie several levels' moves from: its reach counts the levels between (`reach`'s steps)
    since = [j for _, _, j in origins]
    per_level: dict = {}
    for p, i in enumerate(order):
        fit = fit_modes(freq_hz, frfs[i], stds[i], band_hz, start=current)
        got = assign(fit.modes, current, [max(1, abs(j - p)) for j in since])
        per_level[i] = got
        since = [p if m is not None and determined(m) else j for m, j in zip(got, since)]
        current = [(m.f_hz, m.zeta) if m is not None and determined(m) else c for m, c in zip(got, current)]
    tracks = [[per_level[i][k] for i in range(n)] for k in range(len(current))]
    kept = [t for t in tracks if all(m is not None and np.isfinite(m.f_std) and np.isfinite(m.zeta_std) for m in t)]
    return read_trends(kept, levels, alpha, dof if any(s is not None for s in stds) else None)


def assign(modes, start, steps=None) -> list:
    """The fitted ``modes`` in the order of the poles ``start`` they were started from (None for a pole the
    fit dropped): the pairing nearest in frequency overall, each within the start's `reach` (over its
    ``steps`` levels, one each by default)."""
    from scipy.optimize import linear_sum_assignment

    out: list = [None] * len(start)
    if not modes:
        return out
    fs = [f for f, _ in start]
    cost = np.array([[(m.f_hz - f) ** 2 for m in modes] for f, _ in start])
    for a, b in zip(*linear_sum_assignment(cost)):
        f, z = start[a]
        if abs(modes[b].f_hz - f) <= reach(f, z, fs, steps[a] if steps is not None else 1):
            out[a] = modes[b]
    return out

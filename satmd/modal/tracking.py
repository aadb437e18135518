"""`track_modes`: the modes of fits at several levels followed over the levels, and whether they move.

A mode is matched to the nearest one at the next level up: within a half-power width plus the
uncertainty of their difference, or, farther, within `MOVE_SHARE` of the distance to the nearest
other mode of either fit (and `MAX_MOVE` of its frequency): a lightly damped mode that moves by more
than its own bandwidth is still the same mode while no other lies near. Its frequency and damping
move when the change from the lowest to the highest level exceeds its combined std, two-sided, at
``alpha`` for all modes and both quantities together (Bonferroni).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .fit import Z95, Mode

#: A mode may move between levels by this share of the distance to the nearest other mode of either fit ...
MOVE_SHARE = 0.3
#: ... and by no more than this share of its frequency.
MAX_MOVE = 0.1


@dataclass(frozen=True)
class TrackedMode:
    """One mode followed over several fits (levels), values in the order the fits were given.

    Attributes
    ----------
    f_hz, f_std, zeta, zeta_std : per fit
    trend : ``hardening``, ``softening`` or ``none`` (frequency, lowest to highest level)
    damping_trend : ``rising``, ``falling`` or ``none`` (damping ratio, lowest to highest level)
    """

    f_hz: tuple
    f_std: tuple
    zeta: tuple
    zeta_std: tuple
    trend: str
    damping_trend: str

    @property
    def f_ci95(self) -> list:
        """95 % interval of the frequency per fit."""
        return [[f - Z95 * s, f + Z95 * s] for f, s in zip(self.f_hz, self.f_std)]

    @property
    def zeta_ci95(self) -> list:
        """95 % interval of the damping ratio per fit."""
        return [[z - Z95 * s, z + Z95 * s] for z, s in zip(self.zeta, self.zeta_std)]

    @property
    def moves(self) -> bool:
        """Whether its frequency or damping changes beyond its uncertainty."""
        return self.trend != "none" or self.damping_trend != "none"

    def to_dict(self) -> dict:
        """The SPEC §9 ``modes`` entry."""
        return {"f_hz": list(self.f_hz), "f_ci95": self.f_ci95, "zeta": list(self.zeta), "zeta_ci95": self.zeta_ci95,
                "trend": self.trend, "damping_trend": self.damping_trend}


def track_modes(fits, levels=None, alpha: float = 0.05) -> list:
    """Follow each mode over fits at several levels and say whether it moves.

    Parameters
    ----------
    fits : list of `ModalFit`, one per level
    levels : one level figure per fit (default: the order given is increasing)
    alpha : family-wise level of the trend tests (Bonferroni over modes and both quantities)

    Returns
    -------
    list of TrackedMode
        The modes found (with a finite uncertainty) at every level, by frequency at the lowest
        level. A mode is matched to the nearest one at the next level up, when they lie within the
        larger half-power width plus the 95 % uncertainty of their difference.
    """
    order = list(np.argsort(levels, kind="stable")) if levels is not None else list(range(len(fits)))
    # a mode whose uncertainty the fit cannot give is not followed: nothing could be said of its change
    known = [[m for m in fit.modes if np.isfinite(m.f_std) and np.isfinite(m.zeta_std)] for fit in fits]
    tracks = [[m] for m in known[order[0]]]
    for i in order[1:]:
        last = [t[-1] for t in tracks]
        pairs = sorted((abs(m.f_hz - t[-1].f_hz), a, b) for a, t in enumerate(tracks)
                       for b, m in enumerate(known[i])
                       if abs(m.f_hz - t[-1].f_hz) <= _match_tol(t[-1], m, last, known[i]))
        taken_t, taken_m = set(), set()
        for _, a, b in pairs:
            if a not in taken_t and b not in taken_m:
                tracks[a].append(known[i][b])
                taken_t.add(a)
                taken_m.add(b)
        tracks = [tracks[a] for a in sorted(taken_t)]
    return read_trends([[t[order.index(j)] for j in range(len(fits))] for t in tracks], levels, alpha)


def read_trends(tracks, levels=None, alpha: float = 0.05, dof=None) -> list:
    """TrackedMode of each mode followed over the levels: its trends, lowest to highest level.

    Parameters
    ----------
    tracks : list (per mode) of lists (per level, in the order of ``levels``) of `Mode`
    levels : one level figure per fit (default: the order given is increasing)
    alpha : family-wise level of the trend tests (Bonferroni over modes and both quantities)
    dof : degrees of freedom of the std that weighted the fits: the tests read Student's t there (None: normal)

    Returns
    -------
    list of TrackedMode, by frequency at the lowest level
    """
    from scipy.stats import norm, t as student

    n = len(tracks[0]) if tracks else 0
    order = list(np.argsort(levels, kind="stable")) if levels is not None else list(range(n))
    tail = alpha / (4 * max(len(tracks), 1))  # two-sided, 2 quantities per mode
    threshold = norm.isf(tail) if dof is None or not np.isfinite(dof) else student.isf(tail, dof)
    out = []
    for given in sorted(tracks, key=lambda t: t[order[0]].f_hz):
        lo, hi = given[order[0]], given[order[-1]]
        out.append(TrackedMode(tuple(m.f_hz for m in given), tuple(m.f_std for m in given),
                               tuple(m.zeta for m in given), tuple(m.zeta_std for m in given),
                               _direction(hi.f_hz - lo.f_hz, lo.f_std, hi.f_std, threshold, "hardening", "softening"),
                               _direction(hi.zeta - lo.zeta, lo.zeta_std, hi.zeta_std, threshold, "rising",
                                          "falling")))
    return out


def _match_tol(a: Mode, b: Mode, before=(), after=()) -> float:
    """How far apart a mode ``a`` of one fit (modes ``before``) and ``b`` of the next (``after``) may be."""
    spread = np.hypot(a.f_std, b.f_std)
    width = max(a.half_power_hz, b.half_power_hz) + (Z95 * spread if np.isfinite(spread) else 0.0)
    gaps = [abs(m.f_hz - a.f_hz) for m in before if m is not a] + [abs(m.f_hz - b.f_hz) for m in after if m is not b]
    room = min([MOVE_SHARE * g for g in gaps] + [MAX_MOVE * a.f_hz])
    return max(width, room)


def _direction(change, sd_a, sd_b, threshold, up: str, down: str) -> str:
    sd = float(np.hypot(sd_a, sd_b))
    if not np.isfinite(sd) or abs(change) <= threshold * sd:
        return "none"
    return up if change > 0 else down

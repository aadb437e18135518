"""Impact records: pulses found, grouped into hits, and bad hits set aside with their reason (see `satmd.signal.excitation`)."""
from __future__ import annotations

import numpy as np

from ..conventions import TINY
from ..errors import DataError

IMPACT_DUTY = 0.05  # pulses (above a tenth of the peak) cover less than this share of an impact record
IMPACT_ENERGY = 0.8  # ... and hold at least this share of the force's energy
HIT_THRESHOLD = 0.1  # a pulse: the force above this share of its hit's peak


def _runs(mask):
    """(start, stop) of each run of True."""
    d = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def find_hits(x, fs, detected: bool):
    """Hits of an impact record (the fields of an impact `satmd.signal.excitation.Excitation`); None when not pulses.

    Parameters
    ----------
    x : the force
    fs : sample rate in Hz
    detected : True when probing (strict: the force must look like hits), False when the user said so

    Returns
    -------
    dict or None
        ``hits`` ((start, peak) samples), ``segment_samples``, ``dropped``
        ((which, why) pairs) and ``evidence``.
    """
    base = np.median(x)
    a = np.abs(x - base)
    peak = float(a.max()) if a.size else 0.0
    if peak <= 0:
        return None
    on = a > HIT_THRESHOLD * peak
    runs = _runs(on)
    duty = on.mean()
    # a pulse with its immediate surroundings (its skirt below the threshold) holds the energy
    margin = max(2, int(0.002 * fs))
    near = np.zeros(x.size, bool)
    for s, e in runs:
        near[max(0, s - margin): e + margin] = True
    energy = float(np.sum(a[near] ** 2) / max(np.sum(a ** 2), TINY))
    if detected and (duty >= IMPACT_DUTY or energy < IMPACT_ENERGY or not runs):
        return None
    if duty >= IMPACT_DUTY:
        raise DataError(f"the force is above a tenth of its peak {100 * duty:.0f} % of the time: not separate hits")
    if not runs:
        return None
    # group pulses: within one ring-down gap they are one hit (several pulses: a double hit)
    width = max(e - s for s, e in runs)
    gap = max(10 * width, int(0.05 * fs))
    groups = [[runs[0]]]
    for s, e in runs[1:]:
        if s - groups[-1][-1][1] < gap:
            groups[-1].append((s, e))
        else:
            groups.append([(s, e)])
    # small pulses far below the strongest hits are noise spikes, not hits
    heights = [max(a[s:e].max() for s, e in g) for g in groups]
    big = max(heights)
    groups = [g for g, h in zip(groups, heights) if h >= 0.2 * big] if detected else groups
    # a pre-trigger: anti-aliasing filters ring before a sharp pulse (linear phase), and that is part of the hit
    firsts = [g[0][0] for g in groups]
    spacing = int(np.min(np.diff(firsts))) if len(firsts) > 1 else x.size
    pre = min(max(margin, 64, spacing // 50), firsts[0] if firsts[0] >= margin else margin)
    starts = [max(0, f - pre) for f in firsts]
    seg = int(np.min(np.diff(starts))) if len(starts) > 1 else x.size - starts[0]
    if x.size - starts[-1] >= seg // 2:  # the last hit keeps its hit: all segments end as early as it must
        seg = min(seg, x.size - starts[-1])
    seg = max(seg, 8)
    kept, dropped = [], []
    for i, (g, s) in enumerate(zip(groups, starts)):
        where = f"hit {i + 1} at {s / fs:.3f} s"
        lo, hi = g[0]
        top = a[lo:hi]
        flat = np.sum(top >= top.max() * (1 - 1e-6))
        if len(g) > 1:
            dropped.append((where, f"a double hit ({len(g)} pulses within {gap / fs * 1e3:.0f} ms)"))
        elif flat >= 3:
            dropped.append((where, f"clipped (the force stays at its peak for {flat} samples)"))
        elif s + seg > x.size:
            dropped.append((where, f"too close to the record's end ({(x.size - s) / fs:.3f} s of "
                                   f"{seg / fs:.3f} s left for the response)"))
        else:
            kept.append((int(s), int(lo + np.argmax(top))))
    if not kept:
        if detected:
            return None
        raise DataError("no usable hit: " + "; ".join(f"{w}: {r}" for w, r in dropped))
    ev = (f"{len(groups)} pulse(s) above {HIT_THRESHOLD:.0%} of the peak cover {100 * duty:.2f} % of the record "
          f"and hold {100 * energy:.0f} % of the force's energy")
    return {"hits": tuple(kept), "segment_samples": int(seg), "dropped": tuple(dropped), "evidence": ev}


__all__ = ["HIT_THRESHOLD", "IMPACT_DUTY", "IMPACT_ENERGY", "find_hits"]

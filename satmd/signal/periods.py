"""A periodic force: its period (autocorrelation), the periods to average and the lines it excites.

`find_period` finds the shortest lag where the normalised autocorrelation peaks (within 5 % of the
highest peak); `periodic_layout` checks that the periods agree within their noise, drops a glitch and
the start-up transient of the responses, and lists the excited lines. `satmd.signal.excitation`
turns the layout into an `Excitation` (as `hits` does for impacts and `sweep` for sweeps).
"""
from __future__ import annotations

import numpy as np

from ..conventions import TINY
from ..errors import DataError

PERIODIC_SPREAD = 0.10  # period-to-period spread of the force, as a share of its power, still called periodic

MIN_AUTOCORRELATION = 0.5  # normalised autocorrelation at the period: below it the force does not repeat


# --- periodic -------------------------------------------------------------------------------------------
def _autocorrelation(x):
    """Normalised autocorrelation r(L) for lags 0..n//2 (each lag by the energy of its own overlap)."""
    n = x.size
    nfft = 1 << int(np.ceil(np.log2(2 * n)))
    X = np.fft.rfft(x, nfft)
    r = np.fft.irfft(np.abs(X) ** 2, nfft)[: n // 2 + 1]
    e = np.concatenate(([0.0], np.cumsum(x * x)))
    lags = np.arange(n // 2 + 1)
    head = e[n - lags]  # energy of x[0:n-L]
    tail = e[n] - e[lags]  # energy of x[L:n]
    return r / np.sqrt(np.maximum(head * tail, TINY))


def find_period(x, min_lag: int = 16) -> tuple[int, float]:
    """(period in samples, autocorrelation there) of a record that repeats at least twice; (0, r) if none.

    The shortest lag whose normalised autocorrelation is within 5 % of the
    highest one beyond ``min_lag`` (a multiple of the period is as high).
    """
    x = np.asarray(x, float) - np.mean(x)
    if x.size < 4 * min_lag or not np.any(x):
        return 0, 0.0
    r = _autocorrelation(x)
    lags = np.arange(r.size)
    search = r.copy()
    # start after the first zero crossing: the band-limited force is correlated with itself at short lags
    first_neg = int(np.argmax(r[1:] <= 0)) + 1 if np.any(r[1:] <= 0) else r.size
    search[: max(min_lag, first_neg)] = -np.inf
    best = float(np.max(search))
    if not np.isfinite(best) or best < MIN_AUTOCORRELATION:
        return 0, max(best, 0.0) if np.isfinite(best) else 0.0
    peaks = (search[1:-1] >= search[:-2]) & (search[1:-1] >= search[2:]) & (search[1:-1] >= 0.95 * best)
    candidates = lags[1:-1][peaks]
    period = int(candidates[0]) if candidates.size else int(np.argmax(search))
    return period, float(r[period])


def _blocks(x, period, count):
    return np.asarray(x, float)[: count * period].reshape(count, period)


def periodic_layout(x, fs, outs, period, evidence):
    """The fields of a periodic `Excitation` (periods, the ones to average, the excited lines, what was
    dropped and why); None when the periods do not agree."""
    count = x.size // period
    U = _blocks(x, period, count)
    dropped = []
    # a glitch: a period far from the median period (robust to the glitch itself)
    med = np.median(U, axis=0)
    dist = np.mean((U - med) ** 2, axis=1)
    typical = np.median(dist)
    bad = dist > 25.0 * max(typical, 1e-30 * np.mean(med ** 2))
    if 0 < bad.sum() <= count // 4:
        dropped += [(f"period {i + 1}", "the force differs from the other periods there (a glitch)")
                    for i in np.flatnonzero(bad)]
    keep = np.flatnonzero(~bad) if bad.sum() <= count // 4 else np.arange(count)
    late = keep[len(keep) // 2:] if len(keep) >= 4 else keep
    mean = U[late].mean(axis=0)
    spread = float(np.mean((U[late] - mean) ** 2) / max(np.mean(mean ** 2), TINY))
    if spread > PERIODIC_SPREAD:
        return None
    lines = excited_lines(U[late])
    if lines.size < 1:
        return None
    # the start-up transient: leading periods whose responses are still far from the steady state
    transient = _transient_periods([_blocks(y, period, count) for y in outs], keep, lines)
    if count >= 3:  # the first period always goes (Pintelon & Schoukens): a transient below the test still leaks
        transient = max(transient, 1)
    if transient:
        dropped.append((f"period{'s' if transient > 1 else ''} 1{f'–{transient}' if transient > 1 else ''}",
                        "start-up transient in the responses"))
    steady = np.array([i for i in keep if i >= transient], int)
    if steady.size < 2:
        raise DataError(f"the force is periodic ({period / fs:.6g} s) but leaves {steady.size} steady period(s) "
                        f"of {count} after the start-up transient: at least 2 are needed to estimate the "
                        f"noise; record more periods")
    tail = x.size - count * period
    ev = evidence + (f"; {tail} samples after the last whole period left out" if tail else "")
    return dict(period_samples=int(period), periods=int(count), steady=tuple(int(i) for i in steady),
                transient_periods=int(transient), lines=tuple(int(k) for k in lines), dropped=tuple(dropped),
                evidence=ev)


def _transient_periods(outputs, keep, lines) -> int:
    """Leading periods where a response differs from its steady state beyond the noise, at the excited lines.

    The steady state and the noise per line come from the later half of the
    periods; a period is transient while its mean squared distance from the
    steady state is more than 3x what the noise gives (median over the lines) (at most all but 2 periods).
    """
    count = len(keep)
    if count < 3:
        return 0
    worst = 0
    for B in outputs:
        Y = np.fft.rfft(B, axis=1)[:, lines]
        late = Y[keep[count // 2:]]
        ref = late.mean(axis=0)
        h = late.shape[0]
        noise = np.sum(np.abs(late - ref) ** 2, axis=0) / max(h - 1, 1) * (1 + 1 / h)
        noise = np.maximum(noise, 1e-12 * np.mean(np.abs(ref) ** 2) + TINY)
        drop = 0
        for i in keep[: count - 2]:
            if np.median(np.abs(Y[i] - ref) ** 2 / noise) > 3.0:
                drop = int(i) + 1
            else:
                break
        worst = max(worst, drop)
    return min(worst, int(keep[count - 2]))


def excited_lines(periods) -> np.ndarray:
    """DFT lines of one period that the force excites: within 40 dB of the strongest and 15 dB above the noise.

    Parameters
    ----------
    periods : (P, N) steady periods of the force (P ≥ 2)

    Returns
    -------
    ndarray of int
        Lines 1 ≤ k < N/2.
    """
    U = np.fft.rfft(periods, axis=1)
    P, N = periods.shape
    mean = U.mean(axis=0)
    power = np.abs(mean) ** 2
    noise = np.sum(np.abs(U - mean) ** 2, axis=0) / max(P - 1, 1) / P  # variance of the mean, per line
    k = np.arange(power.size)
    ok = (k >= 1) & (k < (N + 1) // 2)
    floor = np.median(noise[ok]) if np.any(ok) else 0.0
    strong = power > 1e-4 * np.max(power[ok]) if np.any(ok) else np.zeros(power.size, bool)
    above = power > 10 ** 1.5 * max(floor, TINY)
    lines = np.flatnonzero(ok & strong & above)
    if lines.size < 5:
        return lines
    # a lone line far from the rest (mains pick-up in the force channel) is not part of the design
    # (far in both senses: a linear grid's low lines are far in relative terms, a log grid's high lines in absolute)
    steps = np.diff(lines).astype(float)
    nearest = np.minimum(np.append(steps, np.inf), np.insert(steps, 0, np.inf))
    relative = nearest / lines
    lone = (nearest > 10.0 * np.median(steps)) & (relative > 10.0 * np.median(steps / lines[1:]))
    return lines[~lone]

"""A single-degree-of-freedom oscillator with polynomial stiffness, driven by a sampled input.

    m ÿ + c ẏ + k y + k2 z² + k3 z³ = g·u(t − τ) + f0,      output  y + y0 + d·u

with z = y − λẏ (λ = 0, the default, makes z = y; a small λ > 0 is a lag in the nonlinear element).

The sampled input is taken between samples as band-limited (FFT interpolation, the default), held
(zero-order hold) or linear (first-order hold); a delay τ (any fraction of a sample) shifts it. The
equation is integrated by classical RK4 at ``substeps`` steps per sample, vectorised over many
trajectories at once (parameter sets × record segments), so a Jacobian by finite differences costs
one pass. A long record is cut into segments simulated side by side, each started from rest
``warmup`` samples early: for a damped system the start is forgotten (fading memory), so this is
the serial simulation to within about exp(−ζω·warmup/fs) of the state. A strongly driven hardening
oscillator may have coexisting responses (the jump of the Duffing curve) and settle on another one
from rest: there, simulate serially (``warmup=None``).

>>> import numpy as np
>>> osc = PolynomialOscillator(k=(2 * np.pi * 10) ** 2, c=2 * 0.05 * 2 * np.pi * 10, k3=0.0)
>>> y = osc.simulate(np.ones(2000), fs=200.0)       # unit step: static gain 1/k
>>> round(float(y[-1] * osc.k), 6)
1.0
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import DataError

INTERSAMPLE = ("bandlimited", "zoh", "foh")


def fine_input(u, factor, delay=0.0, intersample="bandlimited"):
    """The input on a grid ``factor`` times finer than its samples, optionally delayed.

    Parameters
    ----------
    u : array_like, shape (n,)
        The sampled input.
    factor : int
        Points per sample period on the fine grid (≥ 1).
    delay : float
        Delay in samples (any real number ≥ 0); the value at fine time t is u(t − delay).
    intersample : {"bandlimited", "zoh", "foh"}
        Band-limited (FFT) interpolation, zero-order hold or linear interpolation.

    Returns
    -------
    numpy.ndarray, shape (n·factor + 1,)
        The input at times 0, 1/factor, …, n sample periods (the last point repeats the end).
    """
    u = np.asarray(u, dtype=float)
    n = u.size
    t = np.arange(n * factor + 1) / factor - float(delay)
    if intersample == "bandlimited":
        m = n * factor
        spec = np.fft.rfft(u)
        if delay:
            spec = spec * np.exp(-2j * np.pi * np.fft.rfftfreq(n) * float(delay))
        if n % 2 == 0:
            spec[-1] *= 0.5
        out = np.fft.irfft(spec, m) * factor
        return np.append(out, out[-1])
    if intersample == "zoh":
        idx = np.clip(np.floor(t + 1e-9).astype(int), 0, n - 1)
        return np.where(t < 0, 0.0, u[idx])
    if intersample == "foh":
        return np.interp(t, np.arange(n), u, left=0.0, right=u[-1])
    raise DataError(f"intersample must be one of {INTERSAMPLE}, not {intersample!r}")


def rk4_batch(coef, ufine, substeps, fs):
    """Integrate many oscillators at once from rest; the displacement at every sample.

    Parameters
    ----------
    coef : dict of numpy.ndarray
        Per-mass coefficients ``k, c, k2, k3, g, f0`` and optionally ``lag`` (each broadcastable to
        the batch shape B).
    ufine : numpy.ndarray, shape (2·substeps·n + 1, *B)
        The input at half sub-steps (time-major), as from `fine_input` with factor 2·substeps.
    substeps : int
        RK4 steps per sample period.
    fs : float
        Sampling frequency [Hz].

    Returns
    -------
    numpy.ndarray, shape (n, *B)
        y at the sample instants 0 … n−1 (y[0] = 0, the rest state).
    """
    k, c, k2, k3, g, f0 = (np.asarray(coef[name], dtype=float) for name in ("k", "c", "k2", "k3", "g", "f0"))
    lag = np.asarray(coef.get("lag", 0.0), dtype=float)
    gu = g * ufine + f0
    n = (ufine.shape[0] - 1) // (2 * substeps)
    h = 1.0 / (fs * substeps)
    h2 = 0.5 * h
    x = np.zeros(ufine.shape[1:])
    v = np.zeros_like(x)
    x, v = np.broadcast_arrays(x + 0 * k, v + 0 * k)
    x, v = x.copy(), v.copy()
    out = np.empty((n,) + x.shape)

    if np.any(lag != 0.0):
        def acc(xx, vv, f):
            z = xx - lag * vv
            return f - c * vv - k * xx - z * z * (k2 + k3 * z)
    else:
        def acc(xx, vv, f):
            return f - c * vv - xx * (k + xx * (k2 + k3 * xx))

    j = 0
    for i in range(n):
        out[i] = x
        for _ in range(substeps):
            a1 = acc(x, v, gu[j])
            xb, vb = x + h2 * v, v + h2 * a1
            a2 = acc(xb, vb, gu[j + 1])
            xc, vc = x + h2 * vb, v + h2 * a2
            a3 = acc(xc, vc, gu[j + 1])
            xd, vd = x + h * vc, v + h * a3
            a4 = acc(xd, vd, gu[j + 2])
            x = x + (h / 6.0) * (v + 2.0 * (vb + vc) + vd)
            v = v + (h / 6.0) * (a1 + 2.0 * (a2 + a3) + a4)
            j += 2
    return out


def segment_windows(n, length, warmup, lo=0, hi=None):
    """Start indices of side-by-side segments covering samples [lo + warmup, hi).

    Parameters
    ----------
    n : int
        Record length.
    length, warmup : int
        Samples scored per segment and samples simulated before them (from rest).
    lo, hi : int
        The part of the record to cover (``hi`` defaults to n); warm-up stays inside it.

    Returns
    -------
    tuple of (numpy.ndarray, int)
        First simulated sample of every segment, and the number of samples each one simulates
        (warmup + length; the last segment is moved back so that all have the same length).
    """
    hi = n if hi is None else hi
    span = hi - lo - warmup
    if span <= 0:
        raise DataError(f"samples [{lo}, {hi}) are fewer than the warm-up ({warmup})")
    length = min(length, span)
    starts = lo + np.arange(0, span, length)
    starts = np.minimum(starts, hi - warmup - length)
    return starts.astype(int), warmup + length


@dataclass(frozen=True)
class PolynomialOscillator:
    """m ÿ + c ẏ + k y + k2 y² + k3 y³ = g·u(t − τ) + f0, observed as y + y0 + d·u.

    Parameters
    ----------
    k, c : float
        Linear stiffness and viscous damping.
    k2, k3 : float
        Quadratic and cubic stiffness.
    m, gain, force_offset : float
        Mass, input gain g and constant force f0.
    delay : float
        Input delay τ [s].
    output_offset, feedthrough : float
        y0 and d in the observation.
    lag : float
        Lag λ [s] of the nonlinear force: k2 z² + k3 z³ with z = y − λẏ ≈ y(t − λ) (0: none).
    """

    k: float
    c: float
    k2: float = 0.0
    k3: float = 0.0
    m: float = 1.0
    gain: float = 1.0
    force_offset: float = 0.0
    delay: float = 0.0
    output_offset: float = 0.0
    feedthrough: float = 0.0
    lag: float = 0.0

    @property
    def natural_frequency_hz(self) -> float:
        """Undamped linear natural frequency √(k/m)/2π [Hz]."""
        return float(np.sqrt(self.k / self.m) / (2 * np.pi))

    @property
    def damping_ratio(self) -> float:
        """Linear damping ratio c / (2√(km))."""
        return float(self.c / (2 * np.sqrt(self.k * self.m)))

    def coefficients(self) -> dict:
        """Per-mass coefficients for `rk4_batch` (k, c, k2, k3, g, f0 divided by m)."""
        return {"k": self.k / self.m, "c": self.c / self.m, "k2": self.k2 / self.m, "k3": self.k3 / self.m,
                "g": self.gain / self.m, "f0": self.force_offset / self.m, "lag": self.lag}

    def simulate(self, u, fs, substeps=4, intersample="bandlimited", warmup=None, length=2000):
        """The output for a sampled input, from rest at the first sample.

        Parameters
        ----------
        u : array_like, shape (n,)
            Input samples.
        fs : float
            Sampling frequency [Hz].
        substeps : int
            RK4 steps per sample.
        intersample : {"bandlimited", "zoh", "foh"}
            How the input is taken between samples.
        warmup : int or None
            None: one serial simulation. An integer: segments of ``length`` samples simulated side
            by side, each from rest ``warmup`` samples early (see the module note).
        length : int
            Segment length when ``warmup`` is given.

        Returns
        -------
        numpy.ndarray, shape (n,)
            The observed output y + y0 + d·u.
        """
        u = np.asarray(u, dtype=float)
        if u.ndim != 1 or u.size < 2 or not np.all(np.isfinite(u)):
            raise DataError("the oscillator input must be a finite 1-D record of at least 2 samples")
        f = 2 * substeps
        uf = fine_input(u, f, self.delay * fs, intersample)
        coef = self.coefficients()
        if warmup is None:
            x = rk4_batch(coef, uf, substeps, fs)
        else:
            pad = int(warmup)
            up = np.concatenate([np.zeros(pad * f), uf])
            starts, span = segment_windows(u.size + pad, int(length), pad, lo=0)
            idx = (starts[None, :] * f + np.arange(span * f + 1)[:, None])
            seg = rk4_batch(coef, up[idx], substeps, fs)[pad:]
            x = np.empty(u.size)
            for j, s in enumerate(starts):
                x[s:s + span - pad] = seg[:, j]
        return x + self.output_offset + self.feedthrough * u

    def respond(self, force, fs_hz: float) -> dict:
        """The time-model protocol (`satmd.physics.timemodel`): {"force", "y"} from rest, serially.

        Parameters
        ----------
        force : (n,) input samples.
        fs_hz : sample rate [Hz].

        Returns
        -------
        dict
        """
        return {"force": np.asarray(force, float), "y": self.simulate(force, fs_hz)}

    def to_dict(self) -> dict:
        """JSON-ready parameters with the derived natural frequency and damping ratio."""
        return {**asdict(self), "natural_frequency_hz": self.natural_frequency_hz,
                "damping_ratio": self.damping_ratio}

    def report(self) -> str:
        """One line per parameter."""
        return "\n".join(f"{name:>22s} = {value:.6g}" for name, value in self.to_dict().items())

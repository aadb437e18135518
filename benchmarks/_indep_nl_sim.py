"""An independent nonlinear SATMD simulator for the nonlinear benchmark (shares no code with satmd).

Equations written here from SPEC §2 and §8b, integrated by a fixed-step RK4
vectorised over runs (one row per run), one step per sample; the force between
samples is its band-limited (polyphase) interpolation, as for a real force that
the sampler saw through its anti-aliasing filter (a linear interpolation would
be a first-order hold, a 0.8 % gain error at 100 Hz and 2 kHz). State per run: [u1, v1, u2, v2, q, lam] with lam the shunt flux
linkage (i = lam / L0 for a linear inductor). Nonlinear elements:

- ``cubic_absorber_spring``  k3 d³ on the absorber (d = u2 - u1)
- ``cubic_host_spring``      k3 u1³ on the primary mass
- ``absorber_friction``      Fc tanh(v / v0), v = d'
- ``quadratic_damping``      c2 |v| v
- ``inductor_saturation``    dλ/di = L0 / (1 + (i/isat)²), so i = isat tan(λ / (L0 isat))

Forces: band-limited Gaussian with a random spectral shape (flat, sloped, or
with a notch), starting at rest (the transient is in the record). Noise: white,
pink or brown, independently on every channel, relative to its RMS.
"""
from __future__ import annotations

import numpy as np

RIG = dict(m1=0.85, k1=194e3, c1=10.0, cp=4.0, e=0.65, Cp=27e-6, m2=0.518, kp=111e3, R=22.0, L=0.064)
ELEMENTS = ("cubic_absorber_spring", "cubic_host_spring", "absorber_friction", "quadratic_damping",
            "inductor_saturation")


def _matrices(p):
    m1, k1, c1, cp, e, Cp, m2, kp, R, L = (p[k] for k in ("m1", "k1", "c1", "cp", "e", "Cp", "m2", "kp", "R", "L"))
    a = np.zeros((6, 6))
    a[0, 1] = a[2, 3] = 1.0
    a[1] = [-(k1 + kp) / m1, -(c1 + cp) / m1, kp / m1, cp / m1, -e / Cp / m1, 0.0]
    a[3] = [kp / m2, cp / m2, -kp / m2, -cp / m2, e / Cp / m2, 0.0]
    a[4, 5] = 1.0 / L  # q' = i = lam / L
    a[5] = [-e / Cp, 0.0, e / Cp, 0.0, -1.0 / Cp, -R / L]  # lam' = -R i - q/Cp - (e/Cp)(u1 - u2)
    b = np.zeros(6)
    b[1] = 1.0 / m1
    return a, b


def _nonlinear(x, kind, par, p):
    """The extra state derivative of each run's element (rows = runs)."""
    out = np.zeros_like(x)
    if kind is None:
        return out
    d, v = x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]
    if kind == "cubic_absorber_spring":
        g = par * d ** 3
    elif kind == "absorber_friction":
        g = par[0] * np.tanh(v / par[1])
    elif kind == "quadratic_damping":
        g = par * np.abs(v) * v
    elif kind == "cubic_host_spring":
        out[:, 1] = -par * x[:, 0] ** 3 / p["m1"]
        return out
    elif kind == "inductor_saturation":
        L0, isat = p["L"], par
        arg = np.clip(x[:, 5] / (L0 * isat), -1.55, 1.55)
        di = isat * np.tan(arg) - x[:, 5] / L0
        out[:, 4] = di
        out[:, 5] = -p["R"] * di
        return out
    else:
        raise ValueError(kind)
    out[:, 1] = g / p["m1"]
    out[:, 3] = -g / p["m2"]
    return out


def simulate(forces, fs, kind=None, par=None, rig=None):
    """Integrate runs (rows of ``forces`` [N]) from rest; returns acc1, acc2, states (d, u1, v, i) per sample."""
    p = dict(RIG, **(rig or {}))
    a, b = _matrices(p)
    forces = np.atleast_2d(np.asarray(forces, float))
    runs, n = forces.shape
    mid = _midpoints(forces)
    h = 1.0 / fs
    x = np.zeros((runs, 6))
    acc1, acc2 = np.empty((runs, n)), np.empty((runs, n))
    states = np.empty((runs, n, 4))
    at = a.T

    def rhs(x, f):
        return x @ at + np.outer(f, b) + _nonlinear(x, kind, par, p)

    for k in range(n):
        f0 = forces[:, k]
        f1 = forces[:, k + 1] if k + 1 < n else f0
        fm = mid[:, k]
        k1_ = rhs(x, f0)
        acc1[:, k], acc2[:, k] = k1_[:, 1], k1_[:, 3]
        states[:, k, 0], states[:, k, 1] = x[:, 2] - x[:, 0], x[:, 0]
        states[:, k, 2], states[:, k, 3] = x[:, 3] - x[:, 1], x[:, 5] / p["L"]
        k2_ = rhs(x + 0.5 * h * k1_, fm)
        k3_ = rhs(x + 0.5 * h * k2_, fm)
        k4_ = rhs(x + h * k3_, f1)
        x = x + h / 6.0 * (k1_ + 2 * k2_ + 2 * k3_ + k4_)
    return acc1, acc2, states


def _midpoints(x):
    """Band-limited values halfway between samples (FFT interpolation on a zero-padded record)."""
    runs, n = x.shape
    m = 2 * n
    X = np.fft.rfft(np.concatenate([x, x[:, ::-1]], axis=1), axis=1)  # even extension: no jump at the wrap
    shift = np.exp(1j * np.pi * np.arange(X.shape[1]) / m)
    return np.fft.irfft(X * shift, m, axis=1)[:, :n]


def random_force(n, fs, rng, band=(20.0, 200.0), shape=None):
    """Band-limited Gaussian force of unit RMS with a random spectral shape; not periodic in n."""
    m = 2 * n
    spec = np.fft.rfft(rng.standard_normal(m))
    f = np.fft.rfftfreq(m, 1.0 / fs)
    shape = shape or rng.choice(["flat", "up", "down", "notch"])
    gain = np.where((f >= band[0]) & (f <= band[1]), 1.0, 0.0)
    if shape == "up":
        gain = gain * (f / band[0]) ** 0.5
    elif shape == "down":
        gain = gain * (band[0] / np.maximum(f, band[0])) ** 0.5
    elif shape == "notch":
        gain = gain * (1 - 0.8 * np.exp(-0.5 * ((f - rng.uniform(60, 160)) / 10.0) ** 2))
    x = np.fft.irfft(spec * gain, m)[:n]
    return x / np.sqrt(np.mean(x * x))


def coloured_noise(n, rng, colour="white"):
    """Unit-RMS Gaussian noise, white / pink (1/f) / brown-ish (1/f² above a corner)."""
    w = np.fft.rfft(rng.standard_normal(n))
    f = np.arange(w.size) / n
    f[0] = f[1]
    if colour == "pink":
        w = w / np.sqrt(f / f[1])
    elif colour == "brown":
        w = w / (f / f[1] + 20.0)
    x = np.fft.irfft(w, n)
    return x / np.sqrt(np.mean(x * x))


def strength_for(kind, target, states, rig=None):
    """Element parameter giving an equivalent-linear change ``target`` (e.g. 0.1) at the level of ``states``.

    ``states`` are (n, 4) samples [d, u1, v, i] of a linear run at that level
    (statistical linearisation with Gaussian responses).
    """
    p = dict(RIG, **(rig or {}))
    sd, su, sv, si = np.std(states, axis=0)
    if kind == "cubic_absorber_spring":
        return target * p["kp"] / (3 * sd ** 2)
    if kind == "cubic_host_spring":
        return target * p["k1"] / (3 * su ** 2)
    if kind == "quadratic_damping":  # c_eq = 2 sqrt(2/pi) c2 sv: a change of target * cp
        return target * p["cp"] / (2 * np.sqrt(2 / np.pi) * sv)
    if kind == "absorber_friction":  # v0 << sv: c_eq ~ sqrt(2/pi) Fc / sv
        v0 = 0.05 * sv
        return (target * p["cp"] * sv / np.sqrt(2 / np.pi), v0)
    if kind == "inductor_saturation":  # L_eq ~ L0 (1 - si² / isat²)
        return si / np.sqrt(target)
    raise ValueError(kind)


def recording(force, fs, kind=None, par=None, noise=0.02, colour="white", rng=None, rig=None):
    """(force_measured, acc1, acc2) for one force record with noise of the given colour on every channel."""
    rng = rng or np.random.default_rng(0)
    a1, a2, _ = simulate(force[None], fs, kind, par, rig)
    out = []
    for x, rel in ((force, noise / 2), (a1[0], noise), (a2[0], noise)):
        out.append(x + rel * np.sqrt(np.mean(x * x)) * coloured_noise(x.size, rng, colour))
    return tuple(out)

"""A small independent test bed: a chain of masses on springs with one nonlinear joint, tested as a GVT is.

Written here from Newton's law (no satmd code): masses m_i in a line, the first held to the ground by a
spring, springs and dampers between neighbours, one joint (an extra force law) between two masses or
one mass and the ground, a multisine force on the first mass, every mass's acceleration recorded with
noise. Integrated by classical Runge-Kutta at 8 steps a sample.
"""
from __future__ import annotations

import functools

import numpy as np

from satmd.io import Recording


def chain_matrices(n, m=1.0, k=4e4, zeta=0.01):
    """Mass vector, stiffness and damping matrices; ``m`` and ``k`` a value or one per mass (k[0]: to the ground)."""
    M = np.broadcast_to(np.asarray(m, float), (n,)).copy()
    ks = np.broadcast_to(np.asarray(k, float), (n,))
    K = np.zeros((n, n))
    K[0, 0] += ks[0]
    for i in range(n - 1):
        K[i, i] += ks[i + 1]
        K[i + 1, i + 1] += ks[i + 1]
        K[i, i + 1] -= ks[i + 1]
        K[i + 1, i] -= ks[i + 1]
    w1 = np.sqrt(np.min(np.linalg.eigvals(np.linalg.solve(np.diag(M), K)).real))
    C = 2 * zeta / w1 * K  # stiffness-proportional damping
    return M, K, C


def chain_modes(n, m=1.0, k=4e4, zeta=0.01):
    """(poles, accelerance residues (n masses, modes) and feed-through of a force on the first mass): the chain's
    own linear part, exact (its damping is proportional to its stiffness, so its modes are real)."""
    from scipy import linalg

    M, K, C = chain_matrices(n, m, k, zeta)
    w2, phi = linalg.eigh(K, np.diag(M))
    om = np.sqrt(w2)
    z = np.diag(phi.T @ C @ phi) / (2 * om)
    damped = om * np.sqrt(1 - z ** 2)
    poles = -z * om + 1j * damped
    residues = phi * phi[0][None, :] * poles[None, :] ** 2 / (2j * damped)[None, :]
    return poles, residues, (phi * phi[0][None, :]).sum(axis=1)


def multisine(period, fs, lo, hi, seed):
    rng = np.random.default_rng(seed)
    k = np.arange(period // 2 + 1)
    f = k * fs / period
    one = np.fft.irfft(np.where((f >= lo) & (f <= hi), np.exp(2j * np.pi * rng.random(k.size)), 0), period)
    return one / np.std(one)


def log_sweep(fs, duration_s, f_start, f_end, taper_s=0.5):
    """One logarithmic sine sweep from f_start to f_end Hz, unit amplitude, tapered in and out."""
    t = np.arange(int(round(duration_s * fs))) / fs
    rate = np.log(f_end / f_start) / duration_s
    x = np.sin(2 * np.pi * f_start * (np.exp(rate * t) - 1) / rate)
    return x * np.clip(np.minimum(t, duration_s - t) / taper_s, 0.0, 1.0)


def simulate_chain(n=5, joint=(2, 3), law=lambda d, v: 3e9 * d ** 3, levels=(1.0, 3.0, 8.0), fs=256.0,
                   period=1024, periods=5, band=(3.0, 60.0), noise=0.01, seed=0, m=1.0, k=4e4, force=None,
                   anti_alias=False):
    """Recordings (force, acc1..accN) of the chain at each level; ``joint`` = (i, j) masses (0-based), j None: ground.
    ``force``: one record of the force shape (a sweep, ...) instead of ``periods`` of a multisine. ``anti_alias``:
    the accelerations low-passed below the Nyquist frequency before they are sampled, as an acquisition's
    anti-alias filter does (an ideal one, on the record mirrored at its end), the force band-limited between its
    samples (a periodic force's: exact); else sampled as they are, the force straight between its samples."""
    M, K, C = chain_matrices(n, m, k)
    i, j = joint
    rng = np.random.default_rng(seed)
    u = multisine(period, fs, *band, seed=seed) if force is None else np.asarray(force, float)
    periods = periods if force is None else 1
    # every level at once (rows): the levels are independent, and a step costs Python the same for one or many;
    # the state y = (x, v), its linear part one product with [[0, I], [-K/M, -C/M]]
    f = np.array([np.tile(level * u, periods) for level in levels])
    sub = 8
    h = 1.0 / (fs * sub)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-K / M[:, None], -C / M[:, None]]]).T
    y = np.zeros((len(levels), 2 * n))
    acc = np.zeros((f.shape[1], len(levels), n))
    fine = np.zeros((f.shape[1] * sub, len(levels), n))

    def rhs(y, fk):
        d = y[:, i] - (y[:, j] if j is not None else 0.0)
        dv = y[:, n + i] - (y[:, n + j] if j is not None else 0.0)
        g = law(d, dv)
        dy = y @ A
        dy[:, n] += fk / M[0]
        dy[:, n + i] -= g / M[i]
        if j is not None:
            dy[:, n + j] += g / M[j]
        return dy

    if anti_alias:  # the force band-limited between its samples too (the record's periods: exact)
        smooth = np.fft.irfft(np.fft.rfft(f, axis=1), f.shape[1] * 2 * sub, axis=1) * 2 * sub
        smooth = np.concatenate([smooth, smooth[:, :1]], axis=1)
    for s in range(f.shape[1]):
        f0, f1 = f[:, s], f[:, s + 1] if s + 1 < f.shape[1] else f[:, s]
        acc[s] = rhs(y, f0)[:, n:]
        for q in range(sub):
            fa = f0 + (f1 - f0) * q / sub
            fm = f0 + (f1 - f0) * (q + 0.5) / sub
            fb = f0 + (f1 - f0) * (q + 1) / sub
            if anti_alias:
                fa, fm, fb = smooth[:, 2 * (s * sub + q):2 * (s * sub + q) + 3].T
            k1 = rhs(y, fa)
            fine[s * sub + q] = k1[:, n:]
            k2 = rhs(y + 0.5 * h * k1, fm)
            k3 = rhs(y + 0.5 * h * k2, fm)
            k4 = rhs(y + h * k3, fb)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    if anti_alias:
        mirrored = np.concatenate([fine, fine[::-1]])
        spectrum = np.fft.rfft(mirrored, axis=0)
        spectrum[np.fft.rfftfreq(mirrored.shape[0], 1.0 / (fs * sub)) >= fs / 2] = 0.0
        acc = np.fft.irfft(spectrum, mirrored.shape[0], axis=0)[:fine.shape[0]:sub]
    out = []
    for r, level in enumerate(levels):
        chans = {"force": f[r] + noise * 0.5 * np.std(f[r]) * rng.standard_normal(f.shape[1])}
        for q in range(n):
            a = acc[:, r, q]
            chans[f"acc{q + 1}"] = a + noise * np.std(a) * rng.standard_normal(a.size)
        out.append(Recording(fs, chans, meta={"source": f"level {level:g}"}))
    return out


@functools.lru_cache(maxsize=1)
def linear_chain_test() -> Recording:
    """The five-mass chain without a joint, tested once per process (a multisine 3-90 Hz over all five modes, six
    periods, 1 % noise on every channel, the acquisition's anti-alias filter on): a structure's linear test that
    several test files read (simulated in about 6 s). With four periods (a std from 4 degrees of freedom) the
    modal fit kept a spurious mode at 68 Hz."""
    return simulate_chain(n=5, law=lambda d, v: 0.0 * d, levels=(1.0,), periods=6, seed=4, anti_alias=True,
                          band=(3.0, 90.0))[0]

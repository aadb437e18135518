"""An independent recording simulator: shares no code (and no assumptions) with satmd.

satmd's own simulator convolves a force with satmd's FRF, so a recording made
by it and analysed by satmd tests satmd against itself. This one starts from
SPEC §2 written as second-order ODEs in time,

    M x'' + C x' + K x = [F(t), 0, 0],   x = [u1, u2, q]
    M = diag(m1, m2, L),  C = [[c1+cp, -cp, 0], [-cp, cp, 0], [0, 0, R]],
    K = [[k1+kp, -kp, e/Cp], [-kp, kp, -e/Cp], [e/Cp, -e/Cp, 1/Cp]],

(optionally a host mode u3 on the primary mass, a stray capacitance across the
shunt as a fourth electrical state), and integrates it with scipy.signal: the
force lives on a grid `oversample` times finer than the recording, is taken
piecewise linear there, and each mode of the state-space model is integrated
exactly for that force (first-order hold, one complex recursion per mode with
scipy.signal.lfilter). The data
acquisition then low-passes every channel with the same anti-aliasing filter
and keeps every `oversample`-th sample. Forces are shaped with Butterworth
filters (scipy.signal.butter) and a peaking filter for a shaker resonance;
noise is white, pink, drift and mains hum. Only numpy and scipy are imported.

`true_frf(freq, rig)` gives the model's accelerances from the same matrices
(C (iωI − A)⁻¹ B + D), for scoring estimates.
"""
from __future__ import annotations

import numpy as np
import scipy.signal as sg

NOMINAL = dict(m1=0.85, k1=194e3, c1=10.0, cp=4.0, e=0.65, Cp=27e-6, m2=0.518, kp=111e3, R=22.0, L=0.064)


def matrices(p, mode=None, Cs=0.0):
    """(M, C, K) of the rig ``p`` (dict of SPEC §3 symbols) with an optional host mode (f3, zeta, mu)
    and stray shunt capacitance Cs (adds the state q_s, the charge through the inductor branch)."""
    n = 3 + (mode is not None) + (Cs > 0)
    M, C, K = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n))
    b = p["e"] / p["Cp"]
    M[0, 0], M[1, 1] = p["m1"], p["m2"]
    C[:2, :2] = [[p["c1"] + p["cp"], -p["cp"]], [-p["cp"], p["cp"]]]
    K[:3, :3] = [[p["k1"] + p["kp"], -p["kp"], b], [-p["kp"], p["kp"], -b], [b, -b, 1.0 / p["Cp"]]]
    if Cs > 0:
        # charge q through the piezo splits into the inductor branch s and the stray capacitor q - s:
        # piezo voltage = (q - s)/Cs = L s'' + R s'
        i = n - 1
        K[2, 2] += 1.0 / Cs
        K[2, i] = K[i, 2] = -1.0 / Cs
        K[i, i] = 1.0 / Cs
        M[i, i], C[i, i] = p["L"], p["R"]
    else:
        M[2, 2], C[2, 2] = p["L"], p["R"]
    if mode is not None:
        f3, zeta, mu = mode
        j = 3
        m3 = mu * p["m1"]
        k3 = m3 * (2 * np.pi * f3) ** 2
        c3 = 2 * zeta * np.sqrt(k3 * m3)
        M[j, j] = m3
        K[0, 0] += k3
        K[0, j] = K[j, 0] = -k3
        K[j, j] = k3
        C[0, 0] += c3
        C[0, j] = C[j, 0] = -c3
        C[j, j] = c3
    return M, C, K


def state_space(p, mode=None, Cs=0.0):
    """Continuous (A, B, Cy, D) with outputs the accelerations of u1 and u2 for a force on u1."""
    M, C, K = matrices(p, mode, Cs)
    alg = np.flatnonzero(np.diag(M) == 0)  # massless, undamped states (the piezo charge with Cs): condense
    if alg.size:
        keep = np.setdiff1d(np.arange(M.shape[0]), alg)
        K = K[np.ix_(keep, keep)] - K[np.ix_(keep, alg)] @ np.linalg.solve(K[np.ix_(alg, alg)], K[np.ix_(alg, keep)])
        M, C = M[np.ix_(keep, keep)], C[np.ix_(keep, keep)]
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    f = np.zeros(n)
    f[0] = 1.0
    B = np.concatenate([np.zeros(n), Minv @ f])[:, None]
    Cy = A[n:n + 2]  # accelerations are the lower rows of x' = A x + B F
    D = B[n:n + 2]
    return A, B, Cy, D


def true_frf(freq_hz, p, mode=None, Cs=0.0, gains=(1.0, 1.0), tau=0.0):
    """a1, a2 [m/s²/N] of the model at ``freq_hz`` (e^{+iωt}), sensor gains and delay applied."""
    A, B, Cy, D = state_space(p, mode, Cs)
    out = np.empty((2, len(freq_hz)), dtype=complex)
    eye = np.eye(A.shape[0])
    for k, f in enumerate(freq_hz):
        w = 2 * np.pi * f
        out[:, k] = (Cy @ np.linalg.solve(1j * w * eye - A, B) + D)[:, 0]
    delay = np.exp(-2j * np.pi * np.asarray(freq_hz) * tau)
    return {"a1": gains[0] * out[0] * delay, "a2": gains[1] * out[1] * delay}


def shaker_force(n, fs, rng, lo=10.0, hi=300.0, rolloff=8, highpass=2, pink=False, resonance=None):
    """A shaker's force: white or pink Gaussian noise, Butterworth roll-off at hi, high-pass at lo,
    optional armature resonance (f, Q, gain); n samples at fs (with a lead-in so filters have settled)."""
    lead = int(2 * fs)
    w = rng.standard_normal(n + lead)
    if pink:  # 1/f power: the Voss-like shaping by FFT of the white sequence
        W = np.fft.rfft(w)
        f = np.fft.rfftfreq(w.size, 1 / fs)
        W[1:] /= np.sqrt(f[1:] / f[1])
        w = np.fft.irfft(W, w.size)
    x = sg.sosfilt(sg.butter(rolloff, hi, fs=fs, output="sos"), w) if rolloff else w
    if highpass:
        x = sg.sosfilt(sg.butter(highpass, lo, "highpass", fs=fs, output="sos"), x)
    if resonance is not None:
        f0, q, gain = resonance
        b, a = sg.iirpeak(f0, q, fs=fs)
        x = x + gain * sg.lfilter(b, a, x)
    return x[lead:] / np.std(x[lead:])


def respond(force_fine, fs_fine, A, B, Cy, D):
    """Accelerations for a piecewise-linear force on the fine grid, system at rest at t = 0.

    Exact first-order hold, mode by mode: A = V Λ V⁻¹, and each modal state obeys
    x' = λ x + b u, so over one step h with u linear,
    x[k] = e^{λh} x[k-1] + b (I1 u[k] + (I0 - I1) u[k-1]), I0 = (e^{λh} - 1)/λ,
    I1 = (e^{λh} - 1 - λh)/(λ² h): a first-order complex recursion (scipy.signal.lfilter).
    """
    lam, V = np.linalg.eig(A)
    b = np.linalg.solve(V, B[:, 0])
    c = Cy @ V
    h = 1.0 / fs_fine
    z = lam * h
    phi = np.exp(z)
    small = np.abs(z) < 1e-4
    em1 = np.where(small, z + z * z / 2 + z ** 3 / 6, phi - 1.0)
    i0 = em1 / lam
    i1 = np.where(small, h * (0.5 + z / 6 + z * z / 24), (em1 - z) / (lam * z))
    out = [D[row, 0] * force_fine for row in range(Cy.shape[0])]
    for m in range(lam.size):
        xm = sg.lfilter([b[m] * i1[m], b[m] * (i0[m] - i1[m])], [1.0, -phi[m]], force_fine.astype(complex))
        for row in range(Cy.shape[0]):
            out[row] = out[row] + c[row, m] * xm
    return [np.real(o) for o in out]


def sensor_noise(n, fs, rms, rng, white, pink=0.0, drift=0.0, hum=0.0, mains=50.0):
    """White + pink (1/f) + drift (< 0.5 Hz) + mains hum with harmonics, each relative to ``rms``."""
    x = white * rms * rng.standard_normal(n)
    f = np.fft.rfftfreq(n, 1 / fs)
    if pink:
        W = np.fft.rfft(rng.standard_normal(n)) / np.sqrt(np.maximum(f, 0.5))
        y = np.fft.irfft(W, n)
        x += pink * rms * y / np.std(y)
    if drift:
        y = np.cumsum(rng.standard_normal(n))  # a random walk, then kept below 0.5 Hz
        y = sg.sosfiltfilt(sg.butter(2, 0.5, fs=fs, output="sos"), y - y.mean())
        x += drift * rms * y / np.std(y)
    if hum:
        t = np.arange(n) / fs
        for h, a in ((1, 1.0), (2, 0.3), (3, 0.6), (5, 0.2)):
            if h * mains < fs / 2:
                x += hum * a * rms * np.sqrt(2) * np.sin(2 * np.pi * h * mains * t + rng.uniform(0, 2 * np.pi))
    return x


def record(p, seconds, fs, rng, effect=None, force=None, noise=None, oversample=8):
    """One recording (dict force, acc1, acc2 at fs) of rig ``p`` with an optional effect.

    effect: None or (name, params) for extra_mode (f_hz, zeta, mass_ratio), shunt_capacitance (Cs),
    sensor_gain (gain_a1, gain_a2), time_delay (tau_s), parameter_offset:k1 / :c1 (value).
    force: keywords of `shaker_force`. noise: dict white_acc, white_force, pink, drift, hum, mains.
    """
    p = dict(p)
    mode, Cs, gains, tau = None, 0.0, (1.0, 1.0), 0.0
    if effect is not None:
        name, ep = effect
        if name == "extra_mode":
            mode = (ep["f_hz"], ep["zeta"], ep["mass_ratio"])
        elif name == "shunt_capacitance":
            Cs = ep["Cs"]
        elif name == "sensor_gain":
            gains = (ep["gain_a1"], ep["gain_a2"])
        elif name == "time_delay":
            tau = ep["tau_s"]
        elif name.startswith("parameter_offset:"):
            p[name.split(":")[1]] = ep["value"]
        else:
            raise ValueError(f"the independent simulator has no {name}")
    force, noise = dict(force or {}), dict(noise or {})
    n = int(round(seconds * fs))
    fine = fs * oversample
    tail = int(0.2 * fs)  # the acquisition filter looks ahead: simulate a little past the record
    x = shaker_force((n + tail) * oversample, fine, rng, **force)
    A, B, Cy, D = state_space(p, mode, Cs)
    a1, a2 = respond(x, fine, A, B, Cy, D)
    if tau:  # acquisition latency on both accelerometers: an exact band-limited delay on the fine grid
        # (linear interpolation, used before, low-passes by a(1-a)(ωh)²/2: 5e-4 at 400 Hz with fs 5 kHz, a gain
        # error ∝ f² that the stated truth e^{-iωτ} does not have). Zero-padded so nothing wraps into the start.
        m = x.size + 2 * int(np.ceil(tau * fine)) + 1024
        w = 2 * np.pi * np.fft.rfftfreq(m, 1.0 / fine)
        a1, a2 = (np.fft.irfft(np.fft.rfft(a, m) * np.exp(-1j * w * tau), m)[:x.size] for a in (a1, a2))
    a1, a2 = gains[0] * a1, gains[1] * a2
    # the DAQ: the same zero-phase anti-aliasing low-pass (0.45 fs) on every channel, then decimation
    aa = sg.butter(10, 0.45 * fs, fs=fine, output="sos")
    chans = {k: sg.sosfiltfilt(aa, v)[::oversample][:n] for k, v in (("force", x), ("acc1", a1), ("acc2", a2))}
    out = {}
    for k, v in chans.items():
        rms = np.std(v)
        if k == "force":
            out[k] = v + noise.get("white_force", 0.01) * rms * rng.standard_normal(n)
        else:
            out[k] = v + sensor_noise(n, fs, rms, rng, noise.get("white_acc", 0.02), noise.get("pink", 0.0),
                                      noise.get("drift", 0.0), noise.get("hum", 0.0), noise.get("mains", 50.0))
    truth = {"mode": mode, "Cs": Cs, "gains": gains, "tau": tau, "p": p}
    return out, truth

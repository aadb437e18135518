"""Independent simulator of structures the SATMD model cannot describe, with one nonlinear joint (issue 35).

numpy and scipy only; nothing from satmd. Used by `benchmarks/structures_levels.py`.

Structures (linear part)
------------------------
- ``chainN`` (N = 2…6): N masses in a line (0.5–3 kg), springs between neighbours, a spring to ground at
  the first mass and, half the time, at the last; the joint sits on one of these springs (δ = the
  spring's stretch). Force on one mass; a1 at that mass, a2 on another.
- ``beam-ss`` / ``beam-cant``: a simply supported or a cantilever Euler–Bernoulli beam by modal
  superposition of its first 4 modes (unit-length shapes, mass-normalised with the beam's mass), with a
  support spring to ground at a point where the joint sits (δ = the beam's deflection there); force at
  one point, a1 there, a2 at another point.
- ``plate``: a simply supported rectangular Kirchhoff plate (sides 1 and 0.55–0.85) by modal superposition
  of its first 4 modes, with a point spring to ground where the joint sits; force at one point, a1 there,
  a2 at another point.

The linear spring at the joint stays in every structure (k_s); the joint acts in parallel with it.
Damping is modal (0.5–2 % per mode of the small-amplitude structure: C = M Φ diag(2ζω) Φᵀ M). Every
structure is scaled so that its first mode lies in 10–20 Hz; modes above the band are kept (they are the
residual of the modes in it).

Joints (force g on δ, acting through w)
---------------------------------------
- ``hardening``: g = k3 δ³, k3 > 0.
- ``softening``: g = k3 δ³, k3 < 0, within stability: the joint's tangent stiffness k_s + 3 k3 δ² stays
  positive over the whole record (checked on the simulated δ; a rig where it does not is simulated again
  with k3 halved).
- ``friction``: a Jenkins element (joint stiffness k_j in series with a Coulomb slider, slip force F_s =
  k_j x_s) in parallel with k_s; the stick–slip switch regularised Bouc–Wen style (exponent 2):
  ṙ = (k_j / F_s) (δ̇ − ½ |δ̇| |r| r − ½ δ̇ r²), g = F_s r. Rate-independent, as dry friction is.
- ``gap``: a contact spring k_c that engages when |δ| exceeds a clearance g0: g = k_c sign(δ) (|δ| − g0)⁺.

Simulation
----------
Fixed-step RK4 at 8× the sample rate (2048 Hz for 256 Hz records), vectorised over runs (one row per
structure and level), from rest; the force is given at twice the step rate (band-limited, so its
mid-step values are exact). Force and accelerations (computed from the equations of motion at every
step) go through one 8th-order elliptic anti-alias filter (streamed, the same on every channel) and are
decimated to the sample rate; noise is then added to every channel (white, relative to its RMS).

Forces (8–64 Hz): ``random`` — band-limited Gaussian noise, not periodic; ``periodic`` — a random-phase
multisine (every line or odd lines only) of 16 s periods, four periods (the first one has the transient).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import linalg, signal
from scipy.special import erfc

FS = 256.0                 # Hz, the recording's sample rate
OVER = 8                   # RK4 steps per sample
BAND = (8.0, 64.0)         # Hz, the force's band (a ratio of 8: see structures_levels.py on why not wider)
PERIOD = 4096              # samples of one multisine period (16 s at 256 Hz)
SWEEP_MIN_S = 128.0        # a sweep's record: 96 s of sweep (~0.6 Hz/s over the band), 32 s of ring-down
NMAX = 6                   # the largest number of coordinates
JOINTS = ("hardening", "softening", "friction", "gap")
BW_EXP = 2                 # Bouc–Wen exponent of the friction joint
SPAN = 10.0                # highest / lowest force level (20 dB)


@dataclass
class Rig:
    """One structure with (or without: ``joint`` None) its joint, its excitation and its levels."""

    name: str
    M: np.ndarray
    K: np.ndarray            # includes the linear spring k_s at the joint
    C: np.ndarray
    w: np.ndarray            # δ = w·q
    b: np.ndarray            # generalised force of a unit force
    o1: np.ndarray           # a1 = o1·q̈
    o2: np.ndarray
    k_s: float
    joint: str | None
    par: dict = field(default_factory=dict)
    f_modes: np.ndarray = field(default_factory=lambda: np.zeros(0))   # small-amplitude modes [Hz]
    zeta: np.ndarray = field(default_factory=lambda: np.zeros(0))
    target: int = -1         # index of the mode the joint moves most
    excitation: str = "random"
    odd: bool = False
    levels: np.ndarray = field(default_factory=lambda: np.zeros(0))   # force RMS per level [N]
    duration_s: float = 64.0
    noise: dict = field(default_factory=dict)
    seed: int = 0
    sigma_top: float = float("nan")   # RMS of δ at the top level, small-amplitude linear prediction
    expected: dict = field(default_factory=dict)

    @property
    def f_target(self) -> float:
        return float(self.f_modes[self.target])

    def k_small(self) -> np.ndarray:
        """Stiffness at small amplitude: the friction joint stuck adds k_j on δ."""
        if self.joint == "friction":
            return self.K + self.par["kj"] * np.outer(self.w, self.w)
        return self.K

    def describe(self) -> dict:
        """JSON-ready summary."""
        return {"name": self.name, "joint": self.joint, "seed": self.seed, "excitation": self.excitation,
                "odd": self.odd, "levels_n_rms": [float(x) for x in self.levels],
                "f_modes_hz": [round(float(f), 4) for f in self.f_modes], "zeta": [round(float(z), 5) for z in self.zeta],
                "target_hz": self.f_target, "par": {k: float(v) for k, v in self.par.items()},
                "sigma_top": self.sigma_top, "noise": self.noise, "expected": self.expected}


# ------------------------------------------------------------------------------------------------ structures
def _modes(K, M):
    lam, phi = linalg.eigh(K, M)
    return np.sqrt(np.maximum(lam, 0.0)), phi   # phi mass-normalised: phiᵀ M phi = I


def _chain(rng, n):
    m = rng.uniform(0.5, 3.0, n)
    k0 = 1.0
    springs = [(-1, 0, k0)] + [(i, i + 1, k0 * rng.uniform(0.5, 2.0)) for i in range(n - 1)]
    if rng.random() < 0.5 or n == 1:
        springs.append((n - 1, -1, k0 * rng.uniform(0.5, 2.0)))
    K = np.zeros((n, n))
    for a, c, k in springs:
        v = np.zeros(n)
        if a >= 0:
            v[a] += 1.0
        if c >= 0:
            v[c] -= 1.0
        K += k * np.outer(v, v)
    j = int(rng.integers(len(springs)))
    a, c, k_s = springs[j]
    w = np.zeros(n)
    if a >= 0:
        w[a] += 1.0
    if c >= 0:
        w[c] -= 1.0
    d = int(rng.integers(n))
    s = int(rng.choice([i for i in range(n) if i != d]))
    e = np.eye(n)
    return f"chain{n}", np.diag(m), K, w, k_s, e[d], e[d], e[s]


_BETA_CANT = np.array([1.875104069, 4.694091133, 7.854757438, 10.99554073])


def _shape(kind, r, x):
    """Mode shape r (0-based) at x ∈ [0, 1], normalised to ∫ φ² dx = 1."""
    x = np.asarray(x, float)
    if kind == "ss":
        return np.sqrt(2.0) * np.sin((r + 1) * np.pi * x)
    b = _BETA_CANT[r]
    sig = (np.cosh(b) + np.cos(b)) / (np.sinh(b) + np.sin(b))
    raw = lambda t: np.cosh(b * t) - np.cos(b * t) - sig * (np.sinh(b * t) - np.sin(b * t))  # noqa: E731
    xs = np.linspace(0.0, 1.0, 4001)
    norm = np.sqrt(np.trapezoid(raw(xs) ** 2, xs))
    return raw(x) / norm


def _plate(rng):
    """A simply supported rectangular plate (sides 1 and β), its first 4 modes; the joint a point spring to ground.

    Kirchhoff plate: ω_mn ∝ m² + (n/β)², shapes 2 sin(mπx) sin(nπy/β) (unit mean square over the plate),
    mass-normalised. β in 0.55–0.85 keeps the first modes apart (a square plate has double modes).
    """
    beta = rng.uniform(0.55, 0.85)
    mass = rng.uniform(2.0, 10.0)
    pairs = sorted(((m, n) for m in range(1, 5) for n in range(1, 5)), key=lambda mn: mn[0] ** 2 + (mn[1] / beta) ** 2)
    pairs = pairs[:4]
    omega = np.array([m ** 2 + (n / beta) ** 2 for m, n in pairs])
    omega = omega / omega[0]

    def phi(x, y):
        return np.array([2.0 * np.sin(m * np.pi * x) * np.sin(n * np.pi * y) for m, n in pairs]) / np.sqrt(mass)

    pts = rng.uniform(0.1, 0.9, (3, 2))
    while np.hypot(*(pts[1] - pts[2])) < 0.15:
        pts[2] = rng.uniform(0.1, 0.9, 2)
    w = phi(*pts[0])
    K = np.diag(omega ** 2)
    k_s = rng.uniform(0.1, 0.6) * omega[0] ** 2 / max(w[0] ** 2, 1e-12) if abs(w[0]) > 1e-6 else 1.0
    K = K + k_s * np.outer(w, w)
    return "plate", np.eye(4), K, w, k_s, phi(*pts[1]), phi(*pts[1]), phi(*pts[2])


def _beam(rng):
    kind = "ss" if rng.random() < 0.5 else "cant"
    nm = 4
    mass = rng.uniform(2.0, 10.0)
    ratios = (np.arange(1, nm + 1) ** 2.0) if kind == "ss" else (_BETA_CANT / _BETA_CANT[0]) ** 2
    omega = ratios  # scaled later
    phi = lambda x: np.array([_shape(kind, r, x) for r in range(nm)]) / np.sqrt(mass)  # noqa: E731
    lo = 0.1 if kind == "ss" else 0.3
    xj, xf, xs = rng.uniform(lo, 0.95, 3)
    while abs(xs - xf) < 0.15:
        xs = rng.uniform(lo, 0.95)
    w = phi(xj)
    K = np.diag(omega ** 2)
    # the support spring: a share of the first mode's stiffness
    k_s = rng.uniform(0.1, 0.6) * omega[0] ** 2 / max(w[0] ** 2, 1e-12) if abs(w[0]) > 1e-6 else 1.0
    K = K + k_s * np.outer(w, w)
    return f"beam-{kind}", np.eye(nm), K, w, k_s, phi(xf), phi(xf), phi(xs)


def make_rig(seed: int, joint: str | None, excitation: str, n_levels: int, duration_s: float = 64.0,
             structure: str | None = None, like: str | None = None) -> Rig:
    """A random structure with its joint (redrawn until the joint's mode is in band, separate and seen).

    Parameters
    ----------
    seed : the rig's random stream
    joint : one of `JOINTS`, or None (the same structure without the joint: a null)
    excitation : ``random``, ``periodic`` or ``sweep`` (linear, up or down, then at rest)
    n_levels : how many force levels (geometric, the highest `SPAN` × the lowest)
    duration_s : record length (periodic: rounded to whole 16 s periods)
    structure : ``chain``, ``beam`` or ``plate`` (default: drawn)
    like : for a null (``joint`` None), the joint whose structure it copies (same seed: the same structure)

    Returns
    -------
    Rig
    """
    rng = np.random.default_rng(seed)
    design = joint or like or JOINTS[seed % 4]
    for _ in range(200):
        draw = rng.random()
        kind = structure or ("beam" if draw < 0.25 else "plate" if draw < 0.45 else "chain")
        name, M, K, w, k_s, b, o1, o2 = (_beam(rng) if kind == "beam" else _plate(rng) if kind == "plate"
                                         else _chain(rng, int(rng.integers(2, 7))))
        par = {}
        if design == "friction":
            par["kj"] = k_s * rng.uniform(0.3, 1.5)
        om, phi = _modes(K + (par["kj"] * np.outer(w, w) if design == "friction" else 0.0), M)
        scale = (2 * np.pi * rng.uniform(10.0, 20.0) / om[0]) ** 2
        K, k_s, om = K * scale, k_s * scale, om * np.sqrt(scale)
        if "kj" in par:
            par["kj"] *= scale
        f = om / (2 * np.pi)
        if f[-1] > 350.0:
            continue
        psi = w @ phi
        sens = psi ** 2 / om ** 2                     # d(ω²)/ω² per unit joint stiffness
        inband = np.flatnonzero((f >= 10.0) & (f <= 58.0))
        if inband.size == 0:
            continue
        t = int(inband[np.argmax(sens[inband])])
        others = np.delete(f, t)
        if others.size and np.min(np.abs(others / f[t] - 1)) < 0.08:
            continue
        peaks = np.abs(phi.T @ b) * np.maximum(np.abs(phi.T @ o1), np.abs(phi.T @ o2))  # modal peaks, alike ζ
        inb = (f >= BAND[0]) & (f <= BAND[1])
        if peaks[t] < 0.05 * peaks[inb].max():
            continue
        zeta = rng.uniform(0.005, 0.02, f.size)
        C = M @ phi @ np.diag(2 * zeta * om) @ phi.T @ M
        rig = Rig(name, M, K, C, w, b, o1, o2, float(k_s), joint, par, f, zeta, t, excitation,
                  bool(excitation == "periodic" and rng.random() < 0.5), np.zeros(0), duration_s,
                  {"acc": float(rng.uniform(0.005, 0.02)), "force": float(rng.uniform(0.003, 0.01))}, seed)
        top = float(rng.uniform(5.0, 50.0))
        rig.levels = top * SPAN ** (np.linspace(0.0, 1.0, n_levels) - 1.0)
        if excitation == "periodic":
            rig.duration_s = PERIOD / FS * max(3, round(duration_s * FS / PERIOD))
        elif excitation == "sweep":  # time for the sweep to pass each resonance slowly, and to ring down after
            rig.duration_s = max(duration_s, SWEEP_MIN_S)
        force = forces(rig, rng_force(rig))[-1][::2 * OVER]        # the top level at the sample rate
        rig.sigma_top = float(np.std(_linear_delta(rig, force)))
        ok = _joint_strength(rig, rng, design, om[t], psi[t])
        if not ok:
            continue
        if joint is None:   # the null: the same structure, its joint replaced by its small-amplitude stiffness
            rig.joint = design
            rig.K, rig.par, rig.joint = rig.k_small(), {}, None
            rig.expected = {"trend": "none", "damping_trend": "none", "like": design}
        return rig
    raise RuntimeError(f"no rig found for seed {seed}")


def _joint_strength(rig, rng, joint, om_t, psi_t) -> bool:
    """Set the joint's parameters from the top level's δ RMS; the expected trends. False: redraw."""
    s = rig.sigma_top
    per_k = 2 * om_t ** 2 / psi_t ** 2            # joint stiffness that moves the target's f by +100 % (first order)
    if joint == "hardening":
        p = rng.uniform(0.03, 0.08)
        rig.par = {"k3": p * per_k / (3 * s ** 2)}
        rig.expected = {"trend": "hardening", "damping_trend": None, "f_change_pred": p}
    elif joint == "softening":
        p = rng.uniform(0.015, 0.04)
        dk = min(p * per_k, rig.k_s / 30.0)        # tangent stiffness positive out to ~5.5 σ
        p = dk / per_k
        if p < 0.008:
            return False
        rig.par = {"k3": -dk / (3 * s ** 2)}
        rig.expected = {"trend": "softening", "damping_trend": None, "f_change_pred": -p}
    elif joint == "friction":
        rho = rng.uniform(0.5, 1.2)                # σ_top / slip displacement
        share = rig.par["kj"] / per_k * 2           # share of the target's stiffness in the stuck joint
        if not 0.05 <= share <= 0.5:
            return False
        rig.par["Fs"] = rig.par["kj"] * s / rho
        rig.expected = {"trend": "softening", "damping_trend": "rising", "sigma_over_slip_top": rho,
                        "stuck_share": share}
    elif joint == "gap":
        rho = rng.uniform(0.8, 1.3)                # clearance / σ_top
        p = rng.uniform(0.03, 0.08)
        kc = p * per_k / erfc(rho / np.sqrt(2))
        local = kc * rig.w @ np.linalg.solve(rig.M, rig.w)
        if np.sqrt(local) / (2 * np.pi) > 250.0:   # the contact's own frequency stays well within RK4's step
            return False
        rig.par = {"kc": kc, "g0": rho * s}
        rig.expected = {"trend": "hardening", "damping_trend": None, "f_change_pred": p, "gap_over_sigma": rho}
    return True


def _linear_delta(rig, force):
    """δ(t) of the small-amplitude linear structure (periodic steady state) for a force at the sample rate."""
    F = np.fft.rfft(force)
    om = 2 * np.pi * np.fft.rfftfreq(force.size, 1 / FS)
    Ks = rig.k_small()
    keep = (om >= 2 * np.pi * BAND[0] * 0.9) & (om <= 2 * np.pi * BAND[1] * 1.1)
    H = np.zeros(om.size, complex)
    for i in np.flatnonzero(keep):
        H[i] = rig.w @ np.linalg.solve(Ks - om[i] ** 2 * rig.M + 1j * om[i] * rig.C, rig.b)
    return np.fft.irfft(H * F, force.size)


# ------------------------------------------------------------------------------------------------ forces
def rng_force(rig):
    return np.random.default_rng([rig.seed, 7])


def forces(rig, rng):
    """(levels, 2·N·OVER + 1) force at twice the step rate, every level scaled from one realisation."""
    n = int(round(rig.duration_s * FS))
    fine = 2 * OVER
    nf = n * fine + fine  # one sample beyond the last step
    if rig.excitation == "periodic":
        p = PERIOD * fine
        freq = np.fft.rfftfreq(p, 1 / (FS * fine))
        k = np.arange(freq.size)
        lines = (freq >= BAND[0]) & (freq <= BAND[1])
        if rig.odd:
            lines &= (k % 2 == 1)
        X = np.zeros(freq.size, complex)
        X[lines] = np.exp(2j * np.pi * rng.random(lines.sum()))
        one = np.fft.irfft(X, p)
        x = np.tile(one, nf // p + 1)[:nf]
    elif rig.excitation == "sweep":
        # a linear sine sweep over the first 3/4 of the record, up or down, tapered; then at rest (rings down)
        t = np.arange(nf) / (FS * fine)
        T = 0.75 * rig.duration_s
        f0, f1 = (BAND[1], BAND[0]) if rng.random() < 0.5 else BAND
        x = np.sin(2 * np.pi * (f0 * t + (f1 - f0) * t ** 2 / (2 * T))) * (t < T)
        ramp = np.clip(np.minimum(t, T - t) / 0.5, 0.0, 1.0)
        x *= 0.5 - 0.5 * np.cos(np.pi * ramp)
    else:
        freq = np.fft.rfftfreq(nf, 1 / (FS * fine))
        X = rng.standard_normal(freq.size) + 1j * rng.standard_normal(freq.size)
        X[(freq < BAND[0]) | (freq > BAND[1])] = 0.0
        x = np.fft.irfft(X, nf)
    x /= np.std(x)
    return rig.levels[:, None] * x[None, :]


# ------------------------------------------------------------------------------------------------ simulation
def _pad(v, n=NMAX):
    out = np.zeros(n)
    out[:v.size] = v
    return out


def _padm(A, n=NMAX):
    out = np.zeros((n, n))
    out[:A.shape[0], :A.shape[1]] = A
    return out


def simulate(rigs, seed_noise: int = 0, k3_scale=None):
    """Every level of every rig, from rest: list (per rig) of list (per level) of (force, a1, a2) at FS.

    Parameters
    ----------
    rigs : list of Rig (all of one duration)
    seed_noise : seed of the measurement noise
    k3_scale : optional per-rig factor on k3 (softening rigs simulated again)

    Returns
    -------
    (records, info)
        records[i][l] = dict(force=, acc1=, acc2=) numpy arrays; info[i] = {"max_abs_delta": per level,
        "stable": bool, "finite": bool}
    """
    dur = {r.duration_s for r in rigs}
    assert len(dur) == 1, "one duration per batch"
    rows = [(i, lv) for i, r in enumerate(rigs) for lv in range(len(r.levels))]
    R = len(rows)
    Ka, Ca, ba, ua, wv, o1, o2 = (np.zeros((R, NMAX, NMAX)), np.zeros((R, NMAX, NMAX)), np.zeros((R, NMAX)),
                                  np.zeros((R, NMAX)), np.zeros((R, NMAX)), np.zeros((R, NMAX)), np.zeros((R, NMAX)))
    k3, kc, g0, kj, Fs = (np.zeros(R) for _ in range(5))
    fr = np.zeros(R, bool)
    F = []
    for ri, (i, lv) in enumerate(rows):
        r = rigs[i]
        Minv = np.linalg.inv(r.M)
        Ka[ri], Ca[ri] = _padm(Minv @ r.K), _padm(Minv @ r.C)
        ba[ri], ua[ri], wv[ri] = _pad(Minv @ r.b), _pad(Minv @ r.w), _pad(r.w)
        o1[ri], o2[ri] = _pad(r.o1), _pad(r.o2)
        p = r.par
        k3[ri] = p.get("k3", 0.0) * (k3_scale[i] if k3_scale is not None else 1.0)
        kc[ri], g0[ri] = p.get("kc", 0.0), p.get("g0", 0.0)
        if r.joint == "friction" and p:
            kj[ri], Fs[ri], fr[ri] = p["kj"], p["Fs"], True
    for i, r in enumerate(rigs):
        F.append(forces(r, rng_force(r)))
    Fall = np.concatenate(F, axis=0)  # (R, nf), rows in the order of `rows`
    gain = np.where(fr, kj / np.where(Fs > 0, Fs, 1.0), 0.0)
    Fs_eff = np.where(fr, Fs, 0.0)
    has_gap = kc > 0

    def rhs(q, v, z, f):
        d = np.einsum("ri,ri->r", wv, q)
        dv = np.einsum("ri,ri->r", wv, v)
        g = k3 * d ** 3 + Fs_eff * z
        if has_gap.any():
            g = g + kc * np.sign(d) * np.maximum(np.abs(d) - g0, 0.0)
        acc = (-np.einsum("rij,rj->ri", Ka, q) - np.einsum("rij,rj->ri", Ca, v) + ba * f[:, None]
               - ua * g[:, None])
        az = np.abs(z)
        dz = gain * (dv - 0.5 * np.abs(dv) * az ** (BW_EXP - 1) * z - 0.5 * dv * az ** BW_EXP)
        return acc, dz, d

    n = int(round(rigs[0].duration_s * FS))
    steps = n * OVER
    dt = 1.0 / (FS * OVER)
    sos = signal.ellip(8, 0.05, 90.0, 0.8 * FS / 2, fs=FS * OVER, output="sos")
    zi = np.zeros((sos.shape[0], 3, R, 2))   # (sections, channel, rows, 2)
    out = np.zeros((3, R, n))
    q, v, z = np.zeros((R, NMAX)), np.zeros((R, NMAX)), np.zeros(R)
    maxd = np.zeros(R)
    chunk = 4096
    buf = np.zeros((3, R, chunk))
    k = 0
    for s0 in range(0, steps, chunk):
        m = min(chunk, steps - s0)
        for j in range(m):
            st = s0 + j
            f0, fh, f1 = Fall[:, 2 * st], Fall[:, 2 * st + 1], Fall[:, 2 * st + 2]
            a1, z1, d = rhs(q, v, z, f0)
            buf[0, :, j], buf[1, :, j], buf[2, :, j] = f0, np.einsum("ri,ri->r", o1, a1), np.einsum("ri,ri->r", o2, a1)
            np.maximum(maxd, np.abs(d), out=maxd)
            q2, v2, zz2 = q + 0.5 * dt * v, v + 0.5 * dt * a1, z + 0.5 * dt * z1
            a2, z2, _ = rhs(q2, v2, zz2, fh)
            q3, v3, zz3 = q + 0.5 * dt * v2, v + 0.5 * dt * a2, z + 0.5 * dt * z2
            a3, z3, _ = rhs(q3, v3, zz3, fh)
            q4, v4, zz4 = q + dt * v3, v + dt * a3, z + dt * z3
            a4, z4, _ = rhs(q4, v4, zz4, f1)
            q = q + dt / 6 * (v + 2 * v2 + 2 * v3 + v4)
            v = v + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
            z = z + dt / 6 * (z1 + 2 * z2 + 2 * z3 + z4)
        for c in range(3):
            y, zi[:, c] = signal.sosfilt(sos, buf[c, :, :m], axis=1, zi=zi[:, c])
            take = y[:, (-s0) % OVER::OVER]
            out[c, :, k:k + take.shape[1]] = take
        k += len(range((-s0) % OVER, m, OVER))
    rng = np.random.default_rng([seed_noise, 11])
    records = [[None] * len(r.levels) for r in rigs]
    info = [{"max_abs_delta": [0.0] * len(r.levels), "finite": True, "stable": True} for r in rigs]
    for ri, (i, lv) in enumerate(rows):
        r = rigs[i]
        rec = {}
        for c, name in enumerate(("force", "acc1", "acc2")):
            x = out[c, ri].copy()
            rel = r.noise["force" if name == "force" else "acc"]
            x += rel * np.sqrt(np.mean(x ** 2)) * rng.standard_normal(x.size)
            rec[name] = x
        records[i][lv] = rec
        info[i]["max_abs_delta"][lv] = float(maxd[ri])
        info[i]["finite"] &= bool(np.all(np.isfinite(out[:, ri])))
        if r.joint == "softening" and r.par:
            kk = k3[ri]
            info[i]["stable"] &= bool(r.k_s + 3 * kk * maxd[ri] ** 2 > 0)
    return records, info

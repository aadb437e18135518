"""Independent simulator of ground vibration tests: one shaker, 4–8 accelerometers, one nonlinear joint (issue 47).

numpy and scipy only; nothing from satmd. Used by `benchmarks/structures_gvt.py`.

Structures (physical degrees of freedom, then modal reduction)
-------------------------------------------------------------
- ``chain``: 4–7 masses in a line, springs between neighbours, a spring to the ground at the first and,
  half the time, at the last mass; an accelerometer on every mass. The joint sits on one of the springs.
- ``frame``: a lumped two-column frame of 2–4 storeys (a node per column and storey, one horizontal
  coordinate each): columns between storeys, the first storey's to the ground, a floor spring between the
  two nodes of each storey; an accelerometer on every node. The joint sits on a column, a floor or a base.
- ``beam``: a free–free Euler–Bernoulli beam (6 Hermite elements, deflection and slope at 7 nodes) on two
  or three support springs; accelerometers on 5–7 nodes, always on the supports. The joint is one support
  (between its node and the ground).
- ``wing``: a cantilever beam (5 elements) on an elastic root (a translational spring to the ground, the
  slope held), a payload on a pylon spring under node 2–5; accelerometers on the root, the pylon's node,
  the payload and 1–3 other nodes. The joint is the pylon (wing ↔ payload) or, one time in four, the root.

Each structure's modes above 300 Hz are dropped (the rest keep their mass-normalised shapes); damping is
modal (0.5–2 %). The structure is scaled so that its first mode lies in 5–10 Hz; the joint's mode (the
in-band mode it moves most) must lie in the band, apart from its neighbours and be seen at the sensors.

Joints (force g on the stretch δ = q_a − q_b, or q_a to the ground)
-------------------------------------------------------------------
The joint's spring at small amplitude (k_j) stays in the linear structure; g is what it adds.

- ``cubic``: g = k3 δ³ (k3 > 0, a stiffening joint).
- ``softening``: a spring that saturates: the joint's force k_j δ becomes k_j δ / √(1 + (δ/δ_s)²), so
  g = k_j δ (1/√(1 + (δ/δ_s)²) − 1).
- ``clearance``: a contact spring k_c beyond a gap: g = k_c sign(δ) (|δ| − gap)⁺.
- ``friction``: a Jenkins element (k_j in series with a Coulomb slider, F_s = k_j x_s) in place of k_j,
  regularised Bouc–Wen (exponent 2): ṙ = (k_j/F_s)(δ̇ − ½|δ̇||r|r − ½δ̇r²), force F_s r, so g = F_s r − k_j δ.
- ``quadratic_damping``: g = c δ̇|δ̇|.

Strengths are set from the linear response at the highest level (σ = RMS of δ): the top level changes the
joint's mode by a few per cent; the lowest level (8× lower) is close to linear.

Test
----
A random-phase multisine (5–40 Hz, a ratio of 8, 8 s periods at 256 Hz), a new phase draw per level, five
periods from rest (the first carries the transient); seven levels √2 apart. Fixed-step RK4 at 8× the
sample rate, the force known at half steps (band-limited: exact); every channel through one causal
8th-order elliptic anti-alias filter and decimated; noise on every channel (accelerometers 0.5–2 % of
their RMS, white or pink; force 0.3–1 %).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import linalg, signal
from scipy.special import erfc

FS = 256.0
OVER = 8
BAND = (5.0, 40.0)
PERIOD = 2048
PERIODS = 5
SWEEP_S, QUIET_S = 40.0, 40.0   # a sweep's duration and the quiet recorded after it (`simulate(excitation="sweep")`)
F_KEEP = 300.0
LAWS = ("cubic", "softening", "clearance", "friction", "quadratic_damping")
STRUCTURES = ("chain", "frame", "beam", "wing")
LEVELS = np.sqrt(2.0) ** np.arange(7)          # relative to level 1


@dataclass
class Test:
    """One structure with (``law`` None: without) its joint, as tested at seven levels."""

    structure: str
    seed: int
    law: str | None
    sensors: list                  # names acc1..accN
    between: tuple                 # the joint's two sensors (or one and "ground")
    drive: str                     # the shaker's sensor
    freq_hz: np.ndarray            # kept modes (small amplitude)
    zeta: np.ndarray
    phi_s: np.ndarray              # (sensors, modes) mass-normalised shapes at the sensors
    psi: np.ndarray                # (modes,) the joint's stretch per modal coordinate
    b: np.ndarray                  # (modes,) the shaker's modal force
    k_j: float                     # the joint's small-amplitude stiffness
    par: dict = field(default_factory=dict)
    level1_n: float = 1.0          # force RMS at level 1 [N]
    noise: dict = field(default_factory=dict)
    target_hz: float = float("nan")

    def describe(self) -> dict:
        return {"structure": self.structure, "seed": self.seed, "law": self.law, "sensors": self.sensors,
                "between": list(self.between), "drive": self.drive,
                "f_modes_hz": [round(float(f), 3) for f in self.freq_hz if f <= BAND[1] * 1.5],
                "target_hz": round(float(self.target_hz), 3), "par": {k: float(v) for k, v in self.par.items()},
                "level1_n_rms": self.level1_n, "noise": self.noise}


# --------------------------------------------------------------------------------------------- structures
def _stretch(n, a, b):
    v = np.zeros(n)
    v[a] += 1.0
    if b is not None:
        v[b] -= 1.0
    return v


def _springs_to_k(n, springs):
    K = np.zeros((n, n))
    for a, b, k in springs:
        v = _stretch(n, a, b)
        K += k * np.outer(v, v)
    return K


def _chain(rng):
    n = int(rng.integers(4, 8))
    springs = [(0, None, 1.0)] + [(i, i + 1, rng.uniform(0.5, 2.0)) for i in range(n - 1)]
    if rng.random() < 0.5:
        springs.append((n - 1, None, rng.uniform(0.5, 2.0)))
    return np.diag(rng.uniform(0.5, 3.0, n)), springs, list(range(n)), springs


def _frame(rng):
    s = int(rng.integers(2, 5))
    n = 2 * s                                  # node 2i: left column, 2i+1: right, storey i
    springs = []
    for i in range(s):
        for side in (0, 1):
            below = None if i == 0 else 2 * (i - 1) + side
            springs.append((2 * i + side, below, rng.uniform(0.7, 1.4)))
        springs.append((2 * i, 2 * i + 1, rng.uniform(0.3, 1.5)))
    return np.diag(rng.uniform(0.5, 2.0, n)), springs, list(range(n)), springs


def _beam_elements(n_el, length, EI, rhoA):
    """Hermite beam: K, M over (w0, θ0, w1, θ1, ...)."""
    ell = length / n_el
    ke = EI / ell ** 3 * np.array([[12, 6 * ell, -12, 6 * ell], [6 * ell, 4 * ell ** 2, -6 * ell, 2 * ell ** 2],
                                   [-12, -6 * ell, 12, -6 * ell], [6 * ell, 2 * ell ** 2, -6 * ell, 4 * ell ** 2]])
    me = rhoA * ell / 420 * np.array([[156, 22 * ell, 54, -13 * ell], [22 * ell, 4 * ell ** 2, 13 * ell, -3 * ell ** 2],
                                      [54, 13 * ell, 156, -22 * ell], [-13 * ell, -3 * ell ** 2, -22 * ell, 4 * ell ** 2]])
    n = 2 * (n_el + 1)
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for e in range(n_el):
        sl = slice(2 * e, 2 * e + 4)
        K[sl, sl] += ke
        M[sl, sl] += me
    return K, M


def _beam(rng):
    M = _beam_elements(6, 1.0, 1.0, rng.uniform(0.7, 1.5))[1]   # its bending stiffness: `_assemble`
    supports = [0, 6] if rng.random() < 0.5 else [0, int(rng.integers(2, 5)), 6]
    springs = [(2 * node, None, rng.uniform(20.0, 200.0)) for node in supports]
    others = [i for i in range(7) if i not in supports]
    picked = sorted(supports + list(rng.choice(others, int(rng.integers(5, 8)) - len(supports), replace=False)))
    return M, springs, [2 * i for i in picked], springs   # joint candidates: the supports


def _wing(rng):
    Kb, Mb = _beam_elements(5, 1.0, 1.0, 1.0)
    nb = Kb.shape[0]
    n = nb + 1                                 # + the payload
    K, M = np.zeros((n, n)), np.zeros((n, n))
    K[:nb, :nb], M[:nb, :nb] = Kb, Mb
    K[1, 1] += 1e4                             # the root's slope held (a stiff rotational spring)
    M[nb, nb] = rng.uniform(0.15, 0.5)         # payload: a share of the wing's unit mass
    node = int(rng.integers(2, 6))
    root = (0, None, rng.uniform(50.0, 300.0))
    pylon = (2 * node, nb, rng.uniform(0.5, 3.0) * 3.0)
    springs = [root, pylon]
    others = [i for i in range(1, 6) if i != node]
    picked = sorted({0, node} | set(int(x) for x in rng.choice(others, int(rng.integers(1, 4)), replace=False)))
    sensors = [2 * i for i in picked] + [nb]
    K0 = K + _springs_to_k(n, springs)
    joint = [pylon] * 3 + [root]
    return M, K0, sensors, joint


def _assemble(kind, rng):
    """(M, K with every spring, sensor dofs, joint candidates (a, b, k))."""
    if kind == "wing":
        return _wing(rng)
    M, springs, sensors, cands = {"chain": _chain, "frame": _frame, "beam": _beam}[kind](rng)
    bending = _beam_elements(6, 1.0, 1.0, 1.0)[0] if kind == "beam" else 0.0
    return M, bending + _springs_to_k(M.shape[0], springs), sensors, cands


# --------------------------------------------------------------------------------------------- the test
def make_test(seed: int, structure: str, law: str | None) -> Test:
    """A structure of kind ``structure`` with a joint of ``law`` (None: the same structure, no joint)."""
    rng = np.random.default_rng([seed, STRUCTURES.index(structure)])
    for _ in range(300):
        M, K, sensors, cands = _assemble(structure, rng)
        a, b, k_j = cands[int(rng.integers(len(cands)))]
        n = M.shape[0]
        lam, phi = linalg.eigh(K, M)
        om = np.sqrt(np.maximum(lam, 1e-12))
        scale = (2 * np.pi * rng.uniform(5.0, 10.0) / om[0]) ** 2
        K, k_j, om = K * scale, k_j * scale, om * np.sqrt(scale)
        f = om / (2 * np.pi)
        keep = f <= F_KEEP
        f, om, phi = f[keep], om[keep], phi[:, keep]
        w = _stretch(n, a, b)
        psi = w @ phi
        inband = np.flatnonzero((f >= BAND[0] * 1.1) & (f <= BAND[1] * 0.85))
        if inband.size == 0:
            continue
        sens = psi ** 2 / om ** 2
        t = int(inband[np.argmax(sens[inband])])
        if sens[t] * k_j < 0.02:               # the joint hardly touches its mode
            continue
        near = np.delete(f, t)
        if near.size and np.min(np.abs(near / f[t] - 1)) < 0.08:
            continue
        drive = int(rng.choice(sensors))
        phi_s = phi[sensors]
        peaks = np.abs(phi[drive]) * np.max(np.abs(phi_s), axis=0)
        inb = (f >= BAND[0]) & (f <= BAND[1])
        if peaks[t] < 0.1 * peaks[inb].max():
            continue
        names = [f"acc{i + 1}" for i in range(len(sensors))]
        between = (names[sensors.index(a)], names[sensors.index(b)] if b is not None else "ground")
        zeta = rng.uniform(0.005, 0.02, f.size)
        test = Test(structure, seed, law, names, between, names[sensors.index(drive)], f, zeta, phi_s, psi,
                    phi[drive], float(k_j), level1_n=float(rng.uniform(0.5, 5.0)),
                    noise={"acc": float(rng.uniform(0.005, 0.02)), "force": float(rng.uniform(0.003, 0.01)),
                           "colour": str(rng.choice(["white", "pink"]))}, target_hz=float(f[t]))
        if law is None or _strength(test, rng, t):
            return test
    raise RuntimeError(f"no {structure} found for seed {seed}")


def _strength(test, rng, t) -> bool:
    """The joint's parameters from the linear δ at the top level; False: redraw the structure."""
    force = multisine(np.random.default_rng([test.seed, 99]))[::2 * OVER][:PERIOD] * test.level1_n * LEVELS[-1]
    d, v = _linear_stretch(test, force)
    s, sv = float(np.std(d)), float(np.std(v))
    om, psi = 2 * np.pi * test.freq_hz[t], test.psi[t]
    per_k = 2 * om ** 2 / psi ** 2             # joint stiffness that doubles the mode's frequency (first order)
    share = test.k_j / per_k * 2               # the joint's share of the mode's stiffness
    p = rng.uniform(0.02, 0.06)                # the mode's frequency change at the top level
    if test.law == "cubic":
        test.par = {"k3": p * per_k / (3 * s ** 2)}
    elif test.law == "softening":
        # lost stiffness at RMS stroke ≈ k_j (1 − (1 + 1/u²)^(-3/2)), u = δ_s/σ; find u for p
        if share < 2 * p:
            return False
        loss = p * per_k / test.k_j
        u = 1.0 / np.sqrt(max((1 - loss) ** (-2.0 / 3.0) - 1, 1e-9))
        test.par = {"d_s": u * s}
    elif test.law == "clearance":
        rho = rng.uniform(0.8, 1.3)
        kc = p * per_k / erfc(rho / np.sqrt(2))
        closed = np.linalg.eigvalsh(np.diag((2 * np.pi * test.freq_hz) ** 2) + kc * np.outer(test.psi, test.psi))
        if np.sqrt(closed[-1]) / (2 * np.pi) > 400.0:   # the contact's own mode stays well inside RK4's step
            return False
        test.par = {"k_c": kc, "gap": rho * s}
    elif test.law == "friction":
        if not 0.05 <= share <= 0.6:
            return False
        test.par = {"F_s": test.k_j * s / rng.uniform(0.5, 1.2)}
    elif test.law == "quadratic_damping":
        dz = test.zeta[t] * rng.uniform(0.5, 1.5)
        test.par = {"c": dz * 2 * om / (psi ** 2 * sv * np.sqrt(8 / np.pi))}
    return True


def _linear_stretch(test, force):
    """δ and δ̇ of the linear structure in periodic steady state (one period of force at FS)."""
    F = np.fft.rfft(force)
    om = 2 * np.pi * np.fft.rfftfreq(force.size, 1 / FS)
    w0 = 2 * np.pi * test.freq_hz
    H = ((test.psi * test.b)[None, :] / (w0 ** 2 - om[:, None] ** 2 + 2j * test.zeta * w0 * om[:, None])).sum(1)
    return np.fft.irfft(H * F, force.size), np.fft.irfft(1j * om * H * F, force.size)


def multisine(rng) -> np.ndarray:
    """One period of a unit-RMS random-phase multisine at 2·OVER × FS (exact between samples)."""
    p = PERIOD * 2 * OVER
    freq = np.fft.rfftfreq(p, 1 / (FS * 2 * OVER))
    X = np.zeros(freq.size, complex)
    lines = (freq >= BAND[0]) & (freq <= BAND[1])
    X[lines] = np.exp(2j * np.pi * rng.random(lines.sum()))
    x = np.fft.irfft(X, p)
    return x / np.std(x)


# --------------------------------------------------------------------------------------------- simulation
def sweep(seconds: float, quiet_s: float) -> np.ndarray:
    """A linear sine sweep down the band (BAND[1] → BAND[0]) over ``seconds``, ends tapered over 0.5 s, unit RMS
    over the sweep, then ``quiet_s`` of nothing, at 2·OVER × FS (exact between samples)."""
    fine = FS * 2 * OVER
    t = np.arange(int(round(seconds * fine))) / fine
    f0, f1 = BAND[1], BAND[0]
    x = np.sin(2 * np.pi * (f0 * t + (f1 - f0) / (2 * seconds) * t ** 2))
    x *= np.clip(np.minimum(t, seconds - t) / 0.5, 0.0, 1.0)
    x /= np.sqrt(np.mean(x ** 2))
    return np.concatenate([x, np.zeros(int(round(quiet_s * fine)))])


def simulate(test: Test, excitation: str = "multisine") -> list:
    """Seven levels: a list of dicts (``time_s``, ``force``, ``acc1`` …) at FS, from rest. ``excitation``
    ``"sweep"``: one sweep down the band in SWEEP_S seconds and QUIET_S of quiet after it, each level's RMS over the
    sweep the multisine's."""
    L = LEVELS.size
    nm = test.freq_hz.size
    om = 2 * np.pi * test.freq_hz
    om2, dmp = np.tile(om ** 2, (L, 1)), np.tile(2 * test.zeta * om, (L, 1))
    psi, bm = test.psi, test.b
    law, par, kj = test.law, test.par, test.k_j
    if excitation == "sweep":
        one = sweep(SWEEP_S, QUIET_S)
        force_fine = np.stack([one * test.level1_n * LEVELS[lv] for lv in range(L)])
        n = one.size // (2 * OVER)
        force_fine = np.concatenate([force_fine, np.zeros((L, 2))], axis=1)  # the last step's end
    else:
        force_fine = np.stack([multisine(np.random.default_rng([test.seed, 99, lv])) * test.level1_n * LEVELS[lv]
                               for lv in range(L)])
        n = PERIOD * PERIODS
    steps = n * OVER

    def joint(d, dv, r):
        if law == "cubic":
            return par["k3"] * d ** 3, 0.0
        if law == "softening":
            return kj * d * (1.0 / np.sqrt(1.0 + (d / par["d_s"]) ** 2) - 1.0), 0.0
        if law == "clearance":
            return par["k_c"] * np.sign(d) * np.maximum(np.abs(d) - par["gap"], 0.0), 0.0
        if law == "friction":
            g = kj / par["F_s"]
            dr = g * (dv - 0.5 * np.abs(dv) * np.abs(r) * r - 0.5 * dv * r ** 2)
            return par["F_s"] * r - kj * d, dr
        if law == "quadratic_damping":
            return par["c"] * dv * np.abs(dv), 0.0
        return 0.0, 0.0

    def rhs(q, v, r, f):
        d, dv = q @ psi, v @ psi
        g, dr = joint(d, dv, r)
        acc = -om2 * q - dmp * v + np.outer(f, bm) - np.outer(np.broadcast_to(g, (L,)), psi)
        return acc, np.broadcast_to(dr, (L,))

    dt = 1.0 / (FS * OVER)
    sos = signal.ellip(8, 0.05, 90.0, 0.8 * FS / 2, fs=FS * OVER, output="sos")
    nch = 1 + len(test.sensors)
    zi = np.zeros((sos.shape[0], L * nch, 2))
    out = np.zeros((L * nch, n))
    q, v, r = np.zeros((L, nm)), np.zeros((L, nm)), np.zeros(L)
    chunk = OVER * 512
    buf = np.zeros((L * nch, chunk))
    period_fine = PERIOD * 2 * OVER if excitation != "sweep" else force_fine.shape[1]
    for s0 in range(0, steps, chunk):
        for j in range(chunk):
            st = s0 + j
            i0 = (2 * st) % period_fine
            f0, fh, f1 = force_fine[:, i0], force_fine[:, (i0 + 1) % period_fine], force_fine[:, (i0 + 2) % period_fine]
            a1, r1 = rhs(q, v, r, f0)
            buf[:L, j] = f0
            buf[L:, j] = (a1 @ test.phi_s.T).T.reshape(-1)
            a2, r2 = rhs(q + 0.5 * dt * v, v + 0.5 * dt * a1, r + 0.5 * dt * r1, fh)
            v2 = v + 0.5 * dt * a1
            a3, r3 = rhs(q + 0.5 * dt * v2, v + 0.5 * dt * a2, r + 0.5 * dt * r2, fh)
            v3 = v + 0.5 * dt * a2
            a4, r4 = rhs(q + dt * v3, v + dt * a3, r + dt * r3, f1)
            v4 = v + dt * a3
            q = q + dt / 6 * (v + 2 * v2 + 2 * v3 + v4)
            v = v + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
            r = r + dt / 6 * (r1 + 2 * r2 + 2 * r3 + r4)
        y, zi = signal.sosfilt(sos, buf, axis=1, zi=zi)
        out[:, s0 // OVER:(s0 + chunk) // OVER] = y[:, ::OVER]
    if not np.all(np.isfinite(out)):
        raise FloatingPointError(f"{test.structure} seed {test.seed}: the simulation ran away")
    rng = np.random.default_rng([test.seed, 5])
    recs = []
    for lv in range(L):
        rec = {"time_s": np.arange(n) / FS}
        for c, name in enumerate(["force", *test.sensors]):
            x = out[lv if c == 0 else L + (c - 1) * L + lv].copy()
            rel = test.noise["force" if c == 0 else "acc"]
            e = rng.standard_normal(n)
            if test.noise["colour"] == "pink" and c > 0:
                E = np.fft.rfft(e)
                E[1:] /= np.sqrt(np.arange(1, E.size))
                e = np.fft.irfft(E, n)
                e /= np.std(e)
            rec[name] = x + rel * np.sqrt(np.mean(x ** 2)) * e
        recs.append(rec)
    return recs


def write_csv(rec: dict, path) -> None:
    """A plain ``time_s,force,acc1,...`` CSV (what a data logger exports)."""
    names = list(rec)
    np.savetxt(path, np.column_stack([rec[k] for k in names]), delimiter=",", header=",".join(names), comments="",
               fmt="%.9g")

"""Out-of-model data families for the discovery benchmark (issue 24): files the SATMD model cannot describe.

Every family is made here with numpy alone, without satmd's forward model: the
SATMD rig itself (for the wrong-unit and wrong-convention families) is solved
from SPEC §2 by a plain 3×3 linear solve written below, so a bug in
`satmd.physics` cannot hide here. Families:

- ``one_dof``: a 1-DOF oscillator (f0 150–600 Hz) measured as accelerance;
- ``beam``: a multi-mode beam (3–6 modes, 20–1000 Hz), one or two response points;
- ``two_dof``: a mechanical 2-DOF host + absorber with values far from the rig's;
- ``white_noise`` (std given) and ``white_noise_nostd``;
- ``units_g``, ``units_mm``, ``displacement``, ``velocity``: the SATMD rig in wrong units;
- ``conjugate``: the SATMD rig written with the e^{-iωt} convention;
- ``db_phase``: magnitude in dB and phase in degrees in the _re/_im columns;
- ``dead_channel``: a2 column present but the sensor gave nothing (noise only) or a copy of a1;
- ``real_beam``: the 3 third-party beam accelerances ../shared/data/real/meas_point_{1,2,3}.txt.

`families(seed)` yields (family, name, FRFData-kwargs) for `satmd.io.FRFData`.
"""
from __future__ import annotations

import numpy as np

RIG = dict(m1=0.85, k1=194e3, c1=10.0, cp=4.0, e=0.65, Cp=27e-6)
RANGES = {"m2": (0.3, 0.8), "kp": (5e4, 2e5), "R": (5.0, 100.0), "L": (0.02, 0.5)}
GRIDS = ((40.0, 130.0, 60), (30.0, 160.0, 200))


def satmd_rig_a(f, m2, kp, R, L):
    """A1, A2 of SPEC §2 by a direct 3×3 solve per frequency (independent of satmd.physics)."""
    r = RIG
    w = 2 * np.pi * f
    a1, a2 = np.empty(f.size, complex), np.empty(f.size, complex)
    for i, om in enumerate(w):
        Z = np.array([[r["k1"] + kp - r["m1"] * om**2 + 1j * om * (r["c1"] + r["cp"]), -kp - 1j * om * r["cp"],
                       r["e"] / r["Cp"]],
                      [-kp - 1j * om * r["cp"], kp - m2 * om**2 + 1j * om * r["cp"], -r["e"] / r["Cp"]],
                      [r["e"] / r["Cp"], -r["e"] / r["Cp"], 1 / r["Cp"] - L * om**2 + 1j * om * R]])
        u = np.linalg.solve(Z, np.array([1.0, 0.0, 0.0]))
        a1[i], a2[i] = -om**2 * u[0], -om**2 * u[1]
    return a1, a2


def _noisy(rng, x, rel=0.01, floor_frac=0.002):
    std = rel * np.abs(x) + floor_frac * np.abs(x).max()
    return x + std * (rng.standard_normal(x.size) + 1j * rng.standard_normal(x.size)), std


def _grid(rng):
    lo, hi, n = GRIDS[rng.integers(len(GRIDS))]
    return np.linspace(lo, hi, n)


def _pack(f, chans, std_given, rng, rel=0.01):
    out, stds = {}, {}
    for c, x in chans.items():
        out[c], s = _noisy(rng, x, rel)
        stds[c] = s
    return {"freq_hz": f, "channels": out, "std": stds if std_given else {}}


def one_dof(rng):
    f0, zeta, m = rng.uniform(150, 600), rng.uniform(0.005, 0.05), rng.uniform(0.2, 5.0)
    f = np.linspace(rng.uniform(0.3, 0.6) * f0, rng.uniform(1.5, 2.5) * f0, int(rng.choice([100, 200, 400])))
    w, w0 = 2 * np.pi * f, 2 * np.pi * f0
    a = -w**2 / (m * (w0**2 - w**2 + 2j * zeta * w0 * w))
    return _pack(f, {"a1": a}, rng.random() < 0.5, rng)


def beam(rng):
    n = int(rng.integers(3, 7))
    fr = np.sort(rng.uniform(30, 900, n))
    zeta = rng.uniform(0.002, 0.03, n)
    phi1, phi2 = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    mass = rng.uniform(0.5, 5.0)
    f = np.linspace(rng.uniform(5, 20), 1000.0, int(rng.choice([500, 1000])))
    w = 2 * np.pi * f

    def acc(pa, pb):
        return sum(-w**2 * pa[r] * pb[r] / (mass * ((2 * np.pi * fr[r])**2 - w**2 + 2j * zeta[r] * 2 * np.pi * fr[r] * w))
                   for r in range(n))
    chans = {"a1": acc(phi1, phi1)}
    if rng.random() < 0.5:
        chans["a2"] = acc(phi1, phi2)
    return _pack(f, chans, rng.random() < 0.5, rng)


def two_dof(rng):
    """Host + absorber, no piezo, values far from the rig's (heavier, stiffer, other frequencies)."""
    m1, m2 = rng.uniform(5, 50), 0
    f1 = rng.uniform(150, 400)
    k1 = m1 * (2 * np.pi * f1) ** 2
    m2 = m1 * rng.uniform(0.02, 0.1)
    k2 = m2 * (2 * np.pi * f1 * rng.uniform(0.85, 1.0)) ** 2
    c1, c2 = 2 * 0.01 * np.sqrt(k1 * m1), 2 * rng.uniform(0.02, 0.1) * np.sqrt(k2 * m2)
    f = np.linspace(0.5 * f1, 1.6 * f1, 200)
    w = 2 * np.pi * f
    Z11 = k1 + k2 - m1 * w**2 + 1j * w * (c1 + c2)
    Z12 = -k2 - 1j * w * c2
    Z22 = k2 - m2 * w**2 + 1j * w * c2
    det = Z11 * Z22 - Z12**2
    u1, u2 = Z22 / det, -Z12 / det
    return _pack(f, {"a1": -w**2 * u1, "a2": -w**2 * u2}, rng.random() < 0.5, rng)


def _rig_case(rng):
    f = _grid(rng)
    p = {k: rng.uniform(*v) for k, v in RANGES.items()}
    return f, satmd_rig_a(f, **p)


def white_noise(rng, std_given=True):
    f = _grid(rng)
    scale = 10 ** rng.uniform(-2, 1)
    chans = {c: scale * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) for c in ("a1", "a2")}
    std = {c: np.full(f.size, scale) for c in chans} if std_given else {}
    return {"freq_hz": f, "channels": chans, "std": std}


def units(rng, kind):
    f, (a1, a2) = _rig_case(rng)
    w = 2 * np.pi * f
    conv = {"g": lambda a: a / 9.80665, "mm": lambda a: a * 1e3, "displacement": lambda a: a / -(w**2),
            "velocity": lambda a: a / (1j * w), "conjugate": np.conj}[kind]
    return _pack(f, {"a1": conv(a1), "a2": conv(a2)}, rng.random() < 0.5, rng)


def db_phase(rng):
    f, (a1, a2) = _rig_case(rng)
    d = _pack(f, {"a1": a1, "a2": a2}, False, rng)
    d["channels"] = {c: 20 * np.log10(np.abs(x)) + 1j * np.degrees(np.angle(x)) for c, x in d["channels"].items()}
    return d


def dead_channel(rng):
    f, (a1, a2) = _rig_case(rng)
    d = _pack(f, {"a1": a1, "a2": a2}, rng.random() < 0.5, rng)
    if rng.random() < 0.5:
        s = 0.002 * np.abs(a1).max()
        d["channels"]["a2"] = s * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size))
        if d["std"]:
            d["std"]["a2"] = np.full(f.size, s)
    else:
        d["channels"]["a2"] = d["channels"]["a1"].copy()
        if d["std"]:
            d["std"]["a2"] = d["std"]["a1"].copy()
    return d


FAMILIES = {
    "one_dof": (one_dof, 6), "beam": (beam, 6), "two_dof": (two_dof, 5),
    "white_noise": (lambda r: white_noise(r, True), 4), "white_noise_nostd": (lambda r: white_noise(r, False), 4),
    "units_g": (lambda r: units(r, "g"), 4), "units_mm": (lambda r: units(r, "mm"), 4),
    "displacement": (lambda r: units(r, "displacement"), 4), "velocity": (lambda r: units(r, "velocity"), 4),
    "conjugate": (lambda r: units(r, "conjugate"), 4), "db_phase": (db_phase, 4), "dead_channel": (dead_channel, 4),
}


def families(seed: int = 0, scale: int = 1):
    """(family, case name, FRFData keyword arguments) for every generated case; ``scale`` multiplies counts."""
    for k, (name, (make, n)) in enumerate(FAMILIES.items()):
        for i in range(n * scale):
            rng = np.random.default_rng([seed, k, i])
            yield name, f"{name}_{i:02d}", make(rng)

"""An independent re-derivation of the SATMD model for the physics tests.

The solver in ``satmd.physics.model`` eliminates Q in closed form; here the
full symmetric dynamic stiffness of SPEC §2 (plus the SPEC §8 effects, the
extra mode as an explicit fourth DOF) is assembled entry by entry and solved
with ``numpy.linalg.solve``. Nothing from ``satmd.physics.model`` is used.
"""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

NOMINAL = dict(m1=0.85, k1=194e3, c1=10.0, cp=4.0, e=0.65, Cp=27e-6,
               m2=0.518, kp=111e3, R=22.0, L=0.064, F0=1.0)


def explicit_Z(f_hz, p, eta=0.0, tan_delta=0.0, Cs=0.0, mode=None):
    """Full dynamic stiffness at one frequency: 3x3, or 4x4 with ``mode=(f3, zeta, mu)``.

    DOF order: U1, U2, Q (, U3).
    """
    w = 2.0 * math.pi * f_hz
    Cp = p["Cp"] * (1.0 - 1j * tan_delta)
    kp = p["kp"] + p["e"] ** 2 * (1.0 / Cp - 1.0 / p["Cp"])  # SPEC §8: kp - e²/Cp stays real
    Zs = p["R"] + 1j * w * p["L"]
    Zs = Zs / (1.0 + 1j * w * Cs * Zs)
    n = 3 if mode is None else 4
    Z = np.zeros((n, n), dtype=complex)
    Z[0, 0] = p["k1"] * (1.0 + 1j * eta) + kp - p["m1"] * w**2 + 1j * w * (p["c1"] + p["cp"])
    Z[0, 1] = Z[1, 0] = -kp - 1j * w * p["cp"]
    Z[1, 1] = kp - p["m2"] * w**2 + 1j * w * p["cp"]
    Z[0, 2] = Z[2, 0] = p["e"] / Cp
    Z[1, 2] = Z[2, 1] = -p["e"] / Cp
    Z[2, 2] = 1.0 / Cp + 1j * w * Zs
    if mode is not None:
        f3, zeta, mu = mode
        m3 = mu * p["m1"]
        k3 = m3 * (2.0 * math.pi * f3) ** 2
        c3 = 2.0 * zeta * math.sqrt(k3 * m3)
        z3 = k3 + 1j * w * c3
        Z[0, 0] += z3
        Z[0, 3] = Z[3, 0] = -z3
        Z[3, 3] = z3 - m3 * w**2
    return Z


def explicit_response(freq, p=None, eta=0.0, tan_delta=0.0, Cs=0.0, mode=None,
                      gains=(1.0, 1.0), tau=0.0):
    """States and measured accelerations on a grid, by a dense solve per frequency."""
    p = dict(NOMINAL, **(p or {}))
    freq = np.atleast_1d(np.asarray(freq, dtype=float))
    n = 3 if mode is None else 4
    X = np.empty((freq.size, n), dtype=complex)
    for k, f in enumerate(freq):
        rhs = np.zeros(n, dtype=complex)
        rhs[0] = p["F0"]
        X[k] = np.linalg.solve(explicit_Z(f, p, eta, tan_delta, Cs, mode), rhs)
    w = 2.0 * np.pi * freq
    delay = np.exp(-1j * w * tau)
    out = {"u1": X[:, 0], "u2": X[:, 1], "q": X[:, 2],
           "a1": -(w**2) * gains[0] * delay * X[:, 0],
           "a2": -(w**2) * gains[1] * delay * X[:, 1]}
    if mode is not None:
        out["u3"] = X[:, 3]
    return out


def rel_err(a, b):
    """max |a - b| / max |b| (b the reference)."""
    a, b = np.asarray(a), np.asarray(b)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.fixture(scope="session")
def ref():
    return SimpleNamespace(NOMINAL=NOMINAL, Z=explicit_Z, response=explicit_response, rel_err=rel_err)

"""Compiled path of the integrator (optional: numba). Same discretisation, one sequential pass.

``x_k = Φ x_{k-1} + G0 u_{k-1} + G1 u_k`` with ``u = [F, g_1 .. g_m]``; the element
forces ``g_k`` are solved at every sample by Newton steps from a linear extrapolation,
exactly as the NumPy path does, but over the whole record (no segments, no warm-up):
a 90 s record at 2048 Hz takes a few milliseconds per parameter set.

Each element's law is its class's ``force``/``slope`` written for the compiler: the
class declares ``kernel_law`` (0 cubic in its reading, 1 regularised Coulomb, 2
velocity-squared, 3 saturating inductor) and ``kernel_parameters()``; a test holds the
two forms equal. Without numba, `available` is False and `integrate` uses NumPy (numba is
imported when `available` is first asked).
"""
from __future__ import annotations

import math

import numpy as np


def _load() -> bool:
    """Import numba (optional: `pip install numba` makes the integrator ~100x faster) and compile the pass,
    on first use: numba's import alone costs a CLI start-up a third of a second. False: the NumPy path runs."""
    global _law, _run
    if "available" not in globals():
        try:
            import numba
        except ImportError:  # pragma: no cover - exercised where numba is absent
            globals()["available"] = False
        else:
            _law = numba.njit(cache=True, fastmath=False)(_law)  # _run calls it by this name
            _run = numba.njit(cache=True, fastmath=False)(_run)
            globals()["available"] = True
    return globals()["available"]


def __getattr__(name):
    """``available``: whether the compiled pass runs (numba imported on this first question)."""
    if name == "available":
        return _load()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

HALF_PI = 0.999 * math.pi / 2


def _law(code, p0, p1, y):
    """(force, slope) of law ``code`` with parameters p0, p1 at reading y (scalar)."""
    if code == 0:
        return p0 * y * y * y, 3.0 * p0 * y * y
    if code == 1:
        t = math.tanh(y / p1)
        return p0 * t, p0 / p1 * (1.0 - t * t)
    if code == 2:
        return p0 * abs(y) * y, 2.0 * p0 * abs(y)
    x = min(max(y / p0, -HALF_PI), HALF_PI)
    t = math.tan(x)
    return p0 * t - y, t * t


def _run(phi, g0, g1, C, D, out_rows, out_direct, drive, force, codes, prm, rd, corrections, out, gout):
    """The sequential pass for every parameter set b (see the module docstring)."""
    P, n = phi.shape[0], phi.shape[1]
    m = codes.shape[0]
    N = drive.shape[1]
    r = C.shape[0]
    n_out = out_rows.shape[1]
    for b in range(P):
        x = np.zeros(n)
        w = np.zeros(n)
        g = np.zeros(m)
        gp = np.zeros(m)
        gpp = np.zeros(m)
        step = np.zeros(m)
        yw = np.zeros(r)
        f_prev = 0.0
        for k in range(N):
            fk = drive[b, k]
            for i in range(n):
                s = g0[b, i, 0] * f_prev + g1[b, i, 0] * fk
                for j in range(n):
                    s += phi[b, i, j] * x[j]
                for j in range(m):
                    s += g0[b, i, 1 + j] * gp[j]
                w[i] = s
            for q in range(r):
                s = 0.0
                for i in range(n):
                    s += C[q, i] * w[i]
                yw[q] = s
            for j in range(m):
                g[j] = 2.0 * gp[j] - gpp[j]
            for _ in range(corrections):  # Newton, diagonal in the elements (Jacobi, as the NumPy path)
                for j in range(m):
                    y = yw[rd[j]]
                    for i in range(m):
                        y += D[b, rd[j], i] * g[i]
                    f, sl = _law(codes[j], prm[b, j, 0], prm[b, j, 1], y)
                    step[j] = (g[j] - f) / (1.0 - sl * D[b, rd[j], j])
                for j in range(m):
                    g[j] -= step[j]
            for i in range(n):
                s = w[i]
                for j in range(m):
                    s += g1[b, i, 1 + j] * g[j]
                x[i] = s
            for o in range(n_out):
                s = out_direct[b, o, 0] * force[b, k]
                for i in range(n):
                    s += out_rows[b, o, i] * x[i]
                for j in range(m):
                    s += out_direct[b, o, 1 + j] * g[j]
                out[b, o, k] = s
            for j in range(m):
                gout[b, j, k] = g[j]
                gpp[j] = gp[j]
                gp[j] = g[j]
            f_prev = fk



def run(phi, g0, g1, C, D, out_rows, out_direct, drive, force, codes, prm, rd, corrections):
    """Outputs (P, o, N) and element forces (P, m, N) by the compiled sequential pass.

    Parameters
    ----------
    phi, g0, g1 : (P, n, n), (P, n, 1 + m), (P, n, 1 + m) from `statespace.discretise`.
    C : (r, n) rows of the read signals; D : (P, r, m) = C @ G1 (element columns).
    out_rows, out_direct : (P, o, n), (P, o, 1 + m) output rows and feed-through.
    drive : (P, N) force fed to the state (band-limited correction applied); force : (P, N) raw samples.
    codes : (m,) element laws; prm : (P, m, 2) their parameters; rd : (m,) the signal each reads.
    corrections : Newton steps per sample.

    Returns
    -------
    (ndarray, ndarray)
    """
    _load()
    P, N = drive.shape
    out = np.empty((P, out_rows.shape[1], N))
    gout = np.empty((P, len(codes), N))
    f = np.ascontiguousarray
    _run(f(phi), f(g0), f(g1), f(C), f(D), f(out_rows), f(out_direct), f(drive), f(force),
         f(np.asarray(codes, np.int64)), f(prm), f(np.asarray(rd, np.int64)), int(corrections), out, gout)
    return out, gout

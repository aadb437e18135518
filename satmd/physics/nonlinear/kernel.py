"""Compiled path of the integrator (optional: numba). Same discretisation, one sequential pass.

``x_k = Φ x_{k-1} + G0 u_{k-1} + G1 u_k`` with ``u = [F, g_1 .. g_m]``; the element
forces ``g_k`` are solved at every sample by Newton steps from a linear extrapolation,
exactly as the NumPy path does, but over the whole record (no segments, no warm-up):
a 90 s record at 2048 Hz takes a few milliseconds per parameter set.

Each element's law is its class's one ``law(p0, p1, y) -> (force, slope)`` (NumPy
functions, which numba compiles), with ``kernel_parameters()``. The built-in laws are
compiled into one cached pass; an element defined elsewhere gets a pass of its own,
compiled once per process for each set of laws (`laws_pass`). Without numba, `available`
is False and `integrate` uses NumPy (numba is imported when `available` is first asked).
"""
from __future__ import annotations

import types

import numpy as np

from .elements import coulomb_law, cubic_law, saturation_law, velocity_squared_law

BUILTIN_LAWS = (cubic_law, coulomb_law, velocity_squared_law, saturation_law)  # codes 0..3 of `_law`
_PASSES: dict = {}  # laws -> (compiled pass, codes) for elements defined outside the package


def _load() -> bool:
    """Import numba (optional: `pip install numba` makes the integrator ~100x faster) and compile the pass,
    on first use: numba's import alone costs a CLI start-up a third of a second. False: the NumPy path runs."""
    global _law, _run, cubic_law, coulomb_law, velocity_squared_law, saturation_law
    if "available" not in globals():
        try:
            import numba
        except ImportError:  # pragma: no cover - exercised where numba is absent
            globals()["available"] = False
        else:
            jit = numba.njit(cache=True, fastmath=False)
            cubic_law, coulomb_law = jit(cubic_law), jit(coulomb_law)  # _law calls them by these names
            velocity_squared_law, saturation_law = jit(velocity_squared_law), jit(saturation_law)
            _law = jit(_law)  # _run calls it by this name
            _run = jit(_run)
            globals()["available"] = True
    return globals()["available"]


def __getattr__(name):
    """``available``: whether the compiled pass runs (numba imported on this first question)."""
    if name == "available":
        return _load()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _law(code, p0, p1, y):
    """(force, slope) of built-in law ``code`` (its index in `BUILTIN_LAWS`) at reading y (scalar)."""
    if code == 0:
        return cubic_law(p0, p1, y)
    if code == 1:
        return coulomb_law(p0, p1, y)
    if code == 2:
        return velocity_squared_law(p0, p1, y)
    return saturation_law(p0, p1, y)


def laws_pass(laws: tuple):
    """(compiled pass, codes): the cached pass for built-in laws, else one compiled for these laws.

    Parameters
    ----------
    laws : each element's ``law`` (Python functions).

    Returns
    -------
    (callable, list of int)
    """
    _load()
    if all(f in BUILTIN_LAWS for f in laws):  # the Python functions: `_load` rebinds only the module's names
        return _run, [BUILTIN_LAWS.index(f) for f in laws]
    distinct = tuple(dict.fromkeys(laws))
    if distinct not in _PASSES:
        import numba

        jit = numba.njit(fastmath=False)
        names = {f"law{i}": jit(f) for i, f in enumerate(distinct)}
        src = "def dispatch(code, p0, p1, y):\n" + "".join(
            f"    if code == {i}:\n        return law{i}(p0, p1, y)\n" for i in range(len(distinct) - 1))
        src += f"    return law{len(distinct) - 1}(p0, p1, y)\n"
        exec(src, names)  # a dispatcher over exactly these laws (numba cannot index a tuple of functions)
        py_run = getattr(_run, "py_func", _run)
        run_ = types.FunctionType(py_run.__code__, dict(py_run.__globals__, _law=jit(names["dispatch"])))
        _PASSES[distinct] = jit(run_)
    return _PASSES[distinct], [distinct.index(f) for f in laws]


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



def run(phi, g0, g1, C, D, out_rows, out_direct, drive, force, laws, prm, rd, corrections):
    """Outputs (P, o, N) and element forces (P, m, N) by the compiled sequential pass.

    Parameters
    ----------
    phi, g0, g1 : (P, n, n), (P, n, 1 + m), (P, n, 1 + m) from `statespace.discretise`.
    C : (r, n) rows of the read signals; D : (P, r, m) = C @ G1 (element columns).
    out_rows, out_direct : (P, o, n), (P, o, 1 + m) output rows and feed-through.
    drive : (P, N) force fed to the state (band-limited correction applied); force : (P, N) raw samples.
    laws : (m,) each element's ``law``; prm : (P, m, 2) their parameters; rd : (m,) the signal each reads.
    corrections : Newton steps per sample.

    Returns
    -------
    (ndarray, ndarray)
    """
    pass_, codes = laws_pass(tuple(laws))
    P, N = drive.shape
    out = np.empty((P, out_rows.shape[1], N))
    gout = np.empty((P, len(codes), N))
    f = np.ascontiguousarray
    pass_(f(phi), f(g0), f(g1), f(C), f(D), f(out_rows), f(out_direct), f(drive), f(force),
         f(np.asarray(codes, np.int64)), f(prm), f(np.asarray(rd, np.int64)), int(corrections), out, gout)
    return out, gout

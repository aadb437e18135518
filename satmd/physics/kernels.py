"""NumPy kernels of the closed-form solve of `model.py`, for the batched driver `model.frf`.

`model.terms` writes Z's entries and `model.solve` the closed form, once, for
every backend. The two kernels here evaluate that closed form on NumPy chunks:

* `solve_into`: the values, the same operations in the same order as
  `model.solve` (so the same bits), with every (batch, frequency) temporary in
  a scratch buffer reused from chunk to chunk and each channel written straight
  into the caller's output. Fewer allocations and passes over memory is what
  makes the NumPy path fast: most of its time is spent moving complex arrays.
* `solve_with_tangents`: the values and the Jacobian, tangents pushed through
  the closed form, dx/dθ = -Z⁻¹ (dZ/dθ) x, written out for the eliminated system.
"""
from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from ..conventions import ACCEL_CHANNELS
from . import dual


def solve_into(t, out: dict, work: "Workspace") -> None:
    """`model.solve` for NumPy, operation for operation (so bit for bit), written in place.

    Every (batch, frequency) intermediate lands in a scratch buffer of ``work``
    that is reused from chunk to chunk, and each channel in ``out`` (arrays of
    the chunk's shape) is written directly: no allocation per chunk, no copy.
    Channels not in ``out`` are computed only when another channel needs them.
    """
    shape = next(iter(out.values())).shape

    def dest(name):
        return out[name] if name in out else work.get(name, shape)

    bz = np.divide(t.b, t.Z33, out=work.get("bz", shape))
    K = np.multiply(t.b, bz, out=work.get("K", shape))
    np.subtract(t.Kp, K, out=K)  # K = Kp - b bz
    M2 = work.get("M2", shape)  # cast once (exact), not in each of the three products below
    M2[...] = t.M2
    KmM = np.subtract(K, M2, out=work.get("KmM", shape))
    inv = np.multiply(work.full("K1", t.K1, shape), KmM, out=work.get("inv", shape))
    np.subtract(inv, np.multiply(K, M2, out=work.get("tmp", shape)), out=inv)
    np.divide(t.F0, inv, out=inv)  # inv = F0 / (K1 KmM - K M2)
    need_u1 = "u1" in out or "a1" in out
    need_u2 = "u2" in out or "a2" in out
    u1: Any = np.multiply(KmM, inv, out=dest("u1")) if need_u1 else None  # computed where a channel needs it
    u2: Any = np.multiply(K, inv, out=dest("u2")) if need_u2 else None
    if "q" in out:
        np.multiply(np.multiply(bz, M2, out=work.get("tmp", shape)), inv, out=out["q"])
    mw2 = -(t.omega * t.omega)
    if "a1" in out:
        np.multiply(work.full("g1", mw2 if t.s1 is None else mw2 * t.s1, shape), u1, out=out["a1"])
    if "a2" in out:
        np.multiply(work.full("g2", mw2 if t.s2 is None else mw2 * t.s2, shape), u2, out=out["a2"])


class Workspace:
    """Scratch buffers of one worker thread, kept across chunks."""

    def __init__(self):
        self._buffers = {}
        self._views = {}
        self._tiles = {}

    def get(self, name, shape):
        """The complex scratch array ``name`` of ``shape`` (its contents are whatever was left there)."""
        view = self._views.get((name, shape))
        if view is None:
            size = math.prod(shape)
            buf = self._buffers.get(name)
            if buf is None or buf.size < size:
                buf = self._buffers[name] = np.empty(size, dtype=complex)
            view = self._views[name, shape] = buf[:size].reshape(shape)
        return view

    def full(self, name, x, shape):
        """``x`` as a complex array of the chunk's ``shape``. A quantity that
        varies along frequency only (the same in every chunk) is broadcast once
        and kept while it does not change: operations on whole contiguous
        arrays run several times faster than on broadcast ones. Exact."""
        if not isinstance(x, np.ndarray) or x.ndim != 1:
            return x
        key = x.tobytes()  # ~1 KB: cheaper to compare than anything else
        cached = self._tiles.get((name, shape))
        if cached is None or cached[0] != key:
            cached = self._tiles[name, shape] = (key, self.get(name, shape))
            cached[1][...] = x
        return cached[1]


def solve_with_tangents(t, wrt: Sequence[str], outputs: Sequence[str], out_values: dict, out_jac: dict,
                        work: "Workspace | None" = None):
    """Values and d(output)/d(parameter) for each name in ``wrt``, written into
    ``out_values[ch]`` (rows, F) and ``out_jac[ch]`` (rows, F, P).

    ``t`` holds duals; the solve is done on their values and tangents are
    pushed through the closed form. Every parameter acts through a handful of
    intermediates (K, m2 ω², K1, F0, b, Z33, sensor factors), so the
    coefficient d(output)/d(intermediate) is computed once and shared by all
    parameters: a 4-parameter Jacobian costs a few FRFs, not four. ``work``
    keeps frequency-only tangents (d(m2 ω²)/dm2 = ω², ...) broadcast across chunks.
    """
    shape = next(iter(out_values.values())).shape

    def full(key, x):
        return x if work is None else work.full(key, x, shape)

    v = {k: dual.value(getattr(t, k)) for k in ("omega", "K1", "Kp", "b", "Z33", "M2", "F0", "s1", "s2")}
    K1, b, Z33, M2, F0 = full("K1", v["K1"]), v["b"], v["Z33"], v["M2"], v["F0"]
    if isinstance(M2, np.ndarray) and M2.dtype.kind == "f":  # cast once (exact), not in each product
        M2 = M2.astype(complex)
    bz = b / Z33
    K = v["Kp"] - b * bz
    KmM = K - M2
    rdet = 1.0 / (K1 * KmM - K * M2)
    inv = F0 * rdet
    u = {"u1": np.multiply(KmM, inv, **_into(out_values, "u1")), "u2": np.multiply(K, inv, **_into(out_values, "u2"))}
    q: Any = np.multiply(bz * M2, inv, **_into(out_values, "q")) if "q" in outputs else None
    mw2 = -(v["omega"] * v["omega"])
    gain = {"a1": full("g1", mw2 if v["s1"] is None else mw2 * v["s1"]),
            "a2": full("g2", mw2 if v["s2"] is None else mw2 * v["s2"])}
    for ch in ACCEL_CHANNELS:
        if ch in outputs:
            np.multiply(gain[ch], u["u" + ch[1]], out=out_values[ch])
    shared = {}  # products every parameter acting through b or Z33 uses

    def bz_times(k):
        if k not in shared:
            shared[k] = (-2.0 * bz) if k == -2.0 else (bz * bz)
        return shared[k]

    base = {}  # d(u1, u2)/d(intermediate)

    def du(key):
        if key not in base:
            if key == "K":
                T = (K1 - M2) * rdet
                base[key] = (inv - u["u1"] * T, inv - u["u2"] * T)
            elif key == "M2":
                S = (K1 + K) * rdet
                base[key] = (u["u1"] * S - inv, u["u2"] * S)
            elif key == "K1":
                base[key] = (-u["u1"] * KmM * rdet, -u["u2"] * KmM * rdet)
            else:  # F0
                base[key] = (KmM * rdet, K * rdet)
        return base[key]

    coefs = {}  # d(channel)/d(intermediate)

    def coef(key, ch):
        if (key, ch) not in coefs:
            d1, d2 = du(key)
            if ch == "q":
                coefs[key, ch] = -bz * (d1 - d2)
            elif ch in ACCEL_CHANNELS:
                coefs[key, ch] = gain[ch] * (d1 if ch == "a1" else d2)
            else:
                coefs[key, ch] = d1 if ch == "u1" else d2
        return coefs[key, ch]

    params = []  # per parameter: its tangents and how it moves the intermediates
    for name in wrt:
        d = {k: dual.tangent(getattr(t, k), name) for k in ("K1", "Kp", "b", "Z33", "M2", "F0", "s1", "s2")}
        d = {k: x if x is None or _is_one(x) else full(f"d{k}/d{name}", x) for k, x in d.items()}
        dK = d["Kp"]
        if d["b"] is not None:
            dK = _acc(dK, bz_times(-2.0) * d["b"])
        if d["Z33"] is not None:
            dK = _acc(dK, bz_times("bz") * d["Z33"])
        moves = [(key, dx) for key, dx in (("K", dK), ("M2", d["M2"]), ("K1", d["K1"]), ("F0", d["F0"])) if dx is not None]
        params.append((d, moves))
    for ch in outputs:
        cols = []
        for d, moves in params:
            col = None
            for key, dx in moves:
                c = coef(key, ch)
                col = _acc(col, c if _is_one(dx) else c * dx)
            if ch == "q":  # q = b M2 F0 / (det Z33) depends on b and Z33 directly too
                if d["b"] is not None:
                    col = _acc(col, (q / b) * d["b"])
                if d["Z33"] is not None:
                    col = _acc(col, (-q / Z33) * d["Z33"])
            elif ch in ACCEL_CHANNELS and d["s" + ch[1]] is not None:
                col = _acc(col, (mw2 * d["s" + ch[1]]) * u["u" + ch[1]])
            cols.append(col)
        for j, col in enumerate(cols):  # the columns back to back: the chunk's (rows, F, P) block stays in cache
            out_jac[ch][..., j] = 0.0 if col is None else col


def _into(out: dict, ch: str) -> dict:
    """``out=`` keyword for a ufunc when ``ch`` is an output, else nothing (a new array)."""
    return {"out": out[ch]} if ch in out else {}


def _is_one(x):
    return isinstance(x, (int, float)) and x == 1.0


def _acc(total, x):
    return x if total is None else total + x

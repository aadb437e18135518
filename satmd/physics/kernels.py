"""NumPy kernels of the closed-form solve of `model.py`, for the batched driver `model.frf`.

`model.terms` writes Z's entries and `model.solve` the closed form, once, for
every backend. The kernels here evaluate that closed form on NumPy chunks:

* `solve_into`: the values, the same operations in the same order as
  `model.solve` (so the same bits), with every (batch, frequency) temporary in
  a scratch buffer reused from chunk to chunk and each channel written straight
  into the caller's output. Fewer allocations and passes over memory is what
  makes the NumPy path fast: most of its time is spent moving complex arrays.
* `solve_plain_into`: `model.terms` and `solve_into` fused for the model without
  effects (no hooks to call): Z's entries written from the real products `terms`
  multiplies out to, straight into the buffers the solve reads. The same bits.
* `solve_with_tangents`: the values and the Jacobian, tangents pushed through
  the closed form, dx/dθ = -Z⁻¹ (dZ/dθ) x, written out for the eliminated system;
  `plain_dual_terms` gives it the plain model's terms and their tangents in the
  usual free parameters without dual arithmetic on whole arrays.

Where the time goes (10⁴ rigs x 60 frequencies, issue 36): the two complex
divisions (numpy's Smith loop, a third of a chunk), the passes over complex
arrays, and the kernel's page faults on fresh output memory: the outputs are one
allocation (`model.frf`), mapped in huge pages, not one per channel, and reused
once the caller has let go of them (`buffers.OutputPool`). Scratch buffers live
in a `buffers.Workspace`.
"""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any, Sequence

import numpy as np

from ..conventions import ACCEL_CHANNELS, DEFAULT_FREE
from . import dual
from .buffers import Workspace


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


def solve_plain_into(omega, rig, out: dict, work: "Workspace") -> None:
    """`model.solve` of `model.terms` without effects, fused and in place; bit for bit the same.

    ``rig`` is a mapping of the rig's fields (scalars or arrays of shape (rows, 1)). Z's entries are not
    formed as complex arrays of their own: each is written from the real products `terms` multiplies
    out to (iω (R + iωL) = -ω(ωL) + iωR exactly, and so on), straight into the real or imaginary part
    of the buffer the solve reads, and frequency-only factors are kept broadcast across chunks.
    """
    shape = next(iter(out.values())).shape

    def dest(name):
        return out[name] if name in out else work.get(name, shape)

    w2 = omega * omega
    Cp = rig["Cp"]
    Z33 = work.get("Z33", shape)  # 1/Cp + iω (R + iωL) = (1/Cp - ω (ωL)) + i ωR
    wL = np.multiply(omega, rig["L"], out=work.get("wL", shape, float))
    np.subtract(1.0 / Cp, np.multiply(work.tile("w", shape, lambda: omega, omega, dtype=float), wL, out=wL),
                out=Z33.real)
    np.multiply(omega, rig["R"], out=Z33.imag)
    b = rig["e"] / Cp
    bz = np.divide(b, Z33, out=work.get("bz", shape))
    K = np.multiply(b, bz, out=work.get("K", shape))
    np.subtract(rig["kp"], K.real, out=K.real)  # K = (kp + iω cp) - b bz
    np.subtract(work.tile("wcp", shape, lambda: omega * rig["cp"], omega, rig["cp"], dtype=float), K.imag,
                out=K.imag)
    M2 = work.get("M2 (real)", shape)  # only its real part is ever written: a real m2 ω² the complex products take
    np.multiply(rig["m2"], w2, out=M2.real)
    KmM = np.subtract(K, M2, out=work.get("KmM", shape))
    K1 = work.tile("K1", shape, lambda: host_terms(omega, rig), omega, rig["k1"], rig["m1"], rig["c1"])
    inv = np.multiply(K1, KmM, out=work.get("inv", shape))
    np.subtract(inv, np.multiply(K, M2, out=work.get("tmp", shape)), out=inv)
    np.divide(rig["F0"], inv, out=inv)  # inv = F0 / (K1 KmM - K M2)
    u1: Any = np.multiply(KmM, inv, out=dest("u1")) if "u1" in out or "a1" in out else None
    u2: Any = np.multiply(K, inv, out=dest("u2")) if "u2" in out or "a2" in out else None
    if "q" in out:
        np.multiply(np.multiply(bz, M2, out=work.get("tmp", shape)), inv, out=out["q"])
    if "a1" in out or "a2" in out:
        mw2 = work.tile("g", shape, lambda: -w2, omega)
        for ch, u in (("a1", u1), ("a2", u2)):
            if ch in out:
                np.multiply(mw2, u, out=out[ch])


def host_terms(omega, rig):
    """K1 = k1 - m1 ω² + iω c1, the operations of `model.terms` (the same bits)."""
    return rig["k1"] - rig["m1"] * (omega * omega) + 1j * omega * rig["c1"]


#: rig fields whose tangents `plain_dual_terms` writes itself (the model's usual free parameters)
PLAIN_WRT = frozenset(DEFAULT_FREE)


def plain_dual_terms(omega, rig, wrt: Sequence[str], work: "Workspace") -> SimpleNamespace:
    """`model.terms` of the plain model (no effects) with duals seeded on ``wrt`` (names from `PLAIN_WRT`),
    bit for bit: the values written in place as `solve_plain_into` writes them, the tangents those the
    duals carry through `model.terms` (dKp/dkp = 1, dZ33/dR = iω, dZ33/dL = -ω², d(m2 ω²)/dm2 = ω²), with
    none of the dual arithmetic on (rows, frequency) arrays, and b / Z33 and K = Kp - b bz (``bz_K``) as
    `solve_plain_into` writes them. ``rig`` maps the rig's fields to scalars or arrays of shape (rows, 1).
    For `solve_with_tangents`."""
    shape = np.broadcast_shapes(omega.shape, *(np.shape(v) for v in rig.values()))
    w2 = omega * omega
    Cp = rig["Cp"]
    Z33 = work.get("Z33", shape)  # as in solve_plain_into
    wL = np.multiply(omega, rig["L"], out=work.get("wL", shape, float))
    np.subtract(1.0 / Cp, np.multiply(work.tile("w", shape, lambda: omega, omega, dtype=float), wL, out=wL),
                out=Z33.real)
    np.multiply(omega, rig["R"], out=Z33.imag)
    b = rig["e"] / Cp
    bz = np.divide(b, Z33, out=work.get("bz", shape))
    K = np.multiply(b, bz, out=work.get("K", shape))  # Kp - b bz with Kp = kp + iω cp = (kp, ω cp) exactly
    np.subtract(rig["kp"], K.real, out=K.real)
    np.subtract(work.tile("wcp", shape, lambda: omega * rig["cp"], omega, rig["cp"], dtype=float), K.imag,
                out=K.imag)
    M2 = work.get("M2 (real)", shape)  # complex with a zero imaginary part, as the solve casts it
    np.multiply(rig["m2"], w2, out=M2.real)
    iw = 1j * omega
    dZ33 = {"R": 1.0 * iw, "L": (1.0 * iw) * iw}  # what the duals of R and L come out of `terms` with
    return SimpleNamespace(
        omega=omega, K1=work.tile("K1", shape, lambda: host_terms(omega, rig), omega, rig["k1"], rig["m1"], rig["c1"]),
        b=b, F0=rig["F0"],
        Kp=dual.Dual(None, {"kp": 1.0} if "kp" in wrt else {}),  # its value is in bz_K: K = Kp - b bz
        Z33=dual.Dual(Z33, {n: dZ33[n] for n in ("R", "L") if n in wrt}), bz_K=(bz, K),
        M2=dual.Dual(M2, {"m2": 1.0 * w2}) if "m2" in wrt else M2, s1=None, s2=None)


def solve_with_tangents(t, wrt: Sequence[str], outputs: Sequence[str], out_values: dict, out_jac: dict,
                        work: "Workspace | None" = None):
    """Values and d(output)/d(parameter) for each name in ``wrt``, written into
    ``out_values[ch]`` (rows, F) and ``out_jac[ch]`` (rows, F, P).

    ``t`` holds duals; the solve is done on their values and tangents are
    pushed through the closed form. Every parameter acts through a handful of
    intermediates (K, m2 ω², K1, F0, b, Z33, sensor factors), so the
    coefficient d(output)/d(intermediate) is computed once and shared by all
    parameters: a 4-parameter Jacobian costs a few FRFs, not four. ``work``
    keeps frequency-only tangents (d(m2 ω²)/dm2 = ω², ...) broadcast across chunks,
    and every (rows, F) intermediate in a scratch buffer reused from chunk to chunk
    (the same operations in the same order as without it: the same bits).
    """
    shape = next(iter(out_values.values())).shape

    def full(key, x):
        return x if work is None else work.full(key, x, shape)

    def buf(name):  # a scratch array for ``out=`` (None: a new array)
        return None if work is None else work.get("tangents " + name, shape)

    v = {k: dual.value(getattr(t, k)) for k in ("omega", "K1", "Kp", "b", "Z33", "M2", "F0", "s1", "s2")}
    K1, b, Z33, M2, F0 = full("K1", v["K1"]), v["b"], v["Z33"], v["M2"], v["F0"]
    if isinstance(M2, np.ndarray) and M2.dtype.kind == "f":  # cast once (exact), not in each product
        M2c = M2.astype(complex) if work is None else buf("M2")
        M2c[...] = M2
        M2 = M2c
    if getattr(t, "bz_K", None) is not None:  # b / Z33 and Kp - b bz, written in place (`plain_dual_terms`)
        bz, K = t.bz_K
    else:
        bz = np.divide(b, Z33, out=buf("bz"))
        K = np.subtract(v["Kp"], np.multiply(b, bz, out=buf("K")), out=buf("K"))  # Kp - b bz
    KmM = np.subtract(K, M2, out=buf("KmM"))
    rdet = np.multiply(K1, KmM, out=buf("rdet"))
    rdet = np.divide(1.0, np.subtract(rdet, np.multiply(K, M2, out=buf("x")), out=rdet), out=rdet)
    inv = np.multiply(F0, rdet, out=buf("inv"))
    u = {ch: np.multiply(a, inv, out=out_values[ch] if ch in out_values else buf(ch))
         for ch, a in (("u1", KmM), ("u2", K))}
    q: Any = np.multiply(np.multiply(bz, M2, out=buf("x")), inv, **_into(out_values, "q")) if "q" in outputs else None
    mw2 = -(v["omega"] * v["omega"])
    gain = {"a1": full("g1", mw2 if v["s1"] is None else mw2 * v["s1"]),
            "a2": full("g2", mw2 if v["s2"] is None else mw2 * v["s2"])}
    for ch in ACCEL_CHANNELS:
        if ch in outputs:
            np.multiply(gain[ch], u["u" + ch[1]], out=out_values[ch])
    shared = {}  # products every parameter acting through b or Z33 uses

    def bz_times(k):
        if k not in shared:
            shared[k] = np.multiply(-2.0, bz, out=buf("-2 bz")) if k == -2.0 else np.multiply(bz, bz, out=buf("bz2"))
        return shared[k]

    base = {}  # d(u1, u2)/d(intermediate)

    def du(key):
        if key not in base:
            d1, d2 = buf(f"d{key}/1"), buf(f"d{key}/2")
            if key == "K":
                T = np.multiply(np.subtract(K1, M2, out=buf("T")), rdet, out=buf("T"))  # T, S: one buffer
                base[key] = (np.subtract(inv, np.multiply(u["u1"], T, out=d1), out=d1),
                             np.subtract(inv, np.multiply(u["u2"], T, out=d2), out=d2))
            elif key == "M2":
                S = np.multiply(np.add(K1, K, out=buf("T")), rdet, out=buf("T"))
                base[key] = (np.subtract(np.multiply(u["u1"], S, out=d1), inv, out=d1), np.multiply(u["u2"], S, out=d2))
            elif key == "K1":
                base[key] = tuple(np.multiply(np.multiply(np.negative(u[c], out=d), KmM, out=d), rdet, out=d)
                                  for c, d in (("u1", d1), ("u2", d2)))
            else:  # F0
                base[key] = (np.multiply(KmM, rdet, out=d1), np.multiply(K, rdet, out=d2))
        return base[key]

    coefs = {}  # d(channel)/d(intermediate)

    def coef(key, ch):
        if (key, ch) not in coefs:
            d1, d2 = du(key)
            if ch == "q":
                diff = np.subtract(d1, d2, out=buf(f"c{key}/q"))
                coefs[key, ch] = np.multiply(np.negative(bz, out=buf("x")), diff, out=diff)
            elif ch in ACCEL_CHANNELS:
                coefs[key, ch] = np.multiply(gain[ch], d1 if ch == "a1" else d2, out=buf(f"c{key}/{ch}"))
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
        for j, (d, moves) in enumerate(params):
            column = out_jac[ch][..., j]
            extra = (ch == "q" and (d["b"] is not None or d["Z33"] is not None)) or (
                ch in ACCEL_CHANNELS and d["s" + ch[1]] is not None)
            if len(moves) == 1 and not extra:  # one product, written straight into the Jacobian's column
                c, dx = coef(moves[0][0], ch), moves[0][1]
                if _is_one(dx):
                    column[...] = c
                else:
                    np.multiply(c, dx, out=column)
                continue
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
            column[...] = 0.0 if col is None else col


def _into(out: dict, ch: str) -> dict:
    """``out=`` keyword for a ufunc when ``ch`` is an output, else nothing (a new array)."""
    return {"out": out[ch]} if ch in out else {}


def _is_one(x):
    return isinstance(x, (int, float)) and x == 1.0


def _acc(total, x):
    return x if total is None else total + x

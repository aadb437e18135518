"""The coupled electromechanical FRF model (SPEC §2) and its analytic Jacobian.

This module is the only place that writes the dynamic stiffness Z. The shunt
charge Q is eliminated in closed form (Schur complement): the piezo branch
between the two masses becomes the complex stiffness

    K(ω) = kp + iω cp - b² / Z33,      b = e / Cp,  Z33 = 1/Cp + iω Zs(ω),

and the remaining 2x2 system is solved by Cramer's rule,

    det = K1 (K - m2 ω²) - K m2 ω²,    U1 = F0 (K - m2 ω²) / det,
    U2  = F0 K / det,                  Q  = -b (U1 - U2) / Z33,

with K1 = k1 + i ω c1 - m1 ω² (plus host effects). Everything is elementwise
over (batch, frequency) in float64/complex128.

Jacobians are forward-mode: the small intermediate quantities (K1, K's parts,
Z33, ...) carry exact tangents through `dual.Dual`; the solve propagates them
in closed form, dx/dθ = -Z⁻¹ (dZ/dθ) x, written out for the eliminated system.
`frf` runs both on NumPy chunks through the kernels of `kernels.py` (in place,
bit for bit the arithmetic of `solve`).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Iterable, Sequence

import numpy as np

from ..errors import DataError  # a ValueError: user-facing, one line
from ..validation import NAMES, Interval, Whole, validate_params

from . import dual
from .effects import Effect
from .buffers import OUTPUTS, Workspace, kept_workspace
from .kernels import PLAIN_WRT, plain_dual_terms, solve_into, solve_plain_into, solve_with_tangents
from .rig import Rig

STATES = ("u1", "u2", "q")
CHANNELS = ("u1", "u2", "q", "a1", "a2")
# complex elements per chunk: keeps the working set (about 16 arrays) within 2 MB of cache; a Jacobian's
# chunks are twice as long (its Python work per chunk is several times a plain solve's)
_CHUNK_ELEMENTS = 8192
# below this many (batch x frequency) points threads cost more than they give
_THREADED_POINTS = 100_000


@dataclass
class Terms:
    """The entries of the eliminated system at each (batch, frequency) point."""

    omega: Any  # arrays (NumPy or torch) broadcast over (batch, frequency)
    K1: Any  # host: k1 - m1 ω² + iω c1 (+ host effects)
    Kp: Any  # piezo mechanical branch: kp + iω cp
    b: Any  # e / Cp
    Z33: Any  # 1/Cp + iω Zs
    M2: Any  # m2 ω²
    F0: Any
    s1: Any = None  # sensor factor on a1 (None = 1)
    s2: Any = None


def terms(omega, rig: Rig, effects: Sequence[Effect] = ()) -> Terms:
    """Z's entries, written once. Works for NumPy, torch tensors and duals.

    Parameters
    ----------
    omega : angular frequencies [rad/s], broadcasting with the rig's fields.
    rig : Rig
        Parameter values (fields may be arrays, tensors or duals).
    effects : sequence of Effect
        Applied in order: rig changes first, then host, capacitance, piezo-branch, shunt and sensor hooks.

    Returns
    -------
    Terms
        K1, Kp, M2, b, Z33, F0 and the sensor factors the closed-form solve needs.
    """
    for eff in effects:
        rig = eff.rig(rig)
    w2 = omega * omega
    K1 = rig.k1 - rig.m1 * w2 + 1j * omega * rig.c1
    Cp = rig.Cp
    Zs = rig.R + 1j * omega * rig.L
    Kp = rig.kp + 1j * omega * rig.cp
    s1 = s2 = None
    for eff in effects:
        K1 = eff.host(omega, rig, K1)
        Cp = eff.capacitance(omega, rig, Cp)
        Kp = eff.branch(omega, rig, Kp)
        Zs = eff.shunt(omega, rig, Zs)
        s1 = eff.sensor(omega, "a1", s1)
        s2 = eff.sensor(omega, "a2", s2)
    return Terms(
        omega=omega,
        K1=K1,
        Kp=Kp,
        b=rig.e / Cp,
        Z33=1.0 / Cp + 1j * omega * Zs,
        M2=rig.m2 * w2,
        F0=rig.F0,
        s1=s1,
        s2=s2,
    )


def solve(t: Terms) -> dict:
    """Closed-form solution of Z x = [F0, 0, 0] (plus measured accelerations).

    Parameters
    ----------
    t : Terms
        The entries of Z from `terms`.

    Returns
    -------
    dict
        ``u1, u2, q`` (physical states) and ``a1, a2`` (measured accelerations, sensor effects applied).
    """
    bz = t.b / t.Z33
    K = t.Kp - t.b * bz
    KmM = K - t.M2
    inv = t.F0 / (t.K1 * KmM - K * t.M2)
    u1 = KmM * inv
    u2 = K * inv
    q = (bz * t.M2) * inv  # = -b (u1 - u2) / Z33 since u1 - u2 = -M2 inv
    mw2 = -(t.omega * t.omega)
    a1 = mw2 * u1 if t.s1 is None else (mw2 * t.s1) * u1
    a2 = mw2 * u2 if t.s2 is None else (mw2 * t.s2) * u2
    return {"u1": u1, "u2": u2, "q": q, "a1": a1, "a2": a2}


@dataclass
class Response:
    """FRFs of a rig (batch of rigs) on a frequency grid.

    Each of ``u1, u2, q, a1, a2`` is complex with shape ``(*batch, n_freq)``.
    ``a1, a2`` are what the sensors report (sensor effects applied);
    ``u1, u2, q`` are the physical states. When a Jacobian was asked for,
    ``jac[channel]`` has shape ``(*batch, n_freq, len(wrt))``. The channels' arrays
    (and the Jacobians') are slabs of one allocation each: a channel kept alone keeps
    the memory of the others.
    """

    freq_hz: np.ndarray
    u1: np.ndarray | None = None
    u2: np.ndarray | None = None
    q: np.ndarray | None = None
    a1: np.ndarray | None = None
    a2: np.ndarray | None = None
    wrt: tuple = ()
    jac: dict = field(default_factory=dict)

    def channel(self, name: str) -> np.ndarray:
        if name not in CHANNELS:
            raise DataError(f"unknown channel {name!r}; known: {', '.join(CHANNELS)}")
        value = getattr(self, name)
        if value is None:
            raise DataError(f"channel {name} was not computed")
        return value

    def stack(self, channels: Iterable[str]) -> np.ndarray:
        """Channels side by side: shape (*batch, n_channels, n_freq)."""
        return np.stack([self.channel(c) for c in channels], axis=-2)


def parameter_names(rig: Rig, effects: Sequence[Effect]) -> list[str]:
    """Every name a Jacobian can be taken with respect to.

    Parameters
    ----------
    rig : Rig
        The rig (all its fields are names).
    effects : sequence of Effect
        Their parameters are named ``effect.param``.

    Returns
    -------
    list of str
    """
    names = list(Rig.names())
    for eff in effects:
        names += [eff.qualified(p) for p in eff.parameter_names]
    return names


def resolve_parameter(name: str, effects: Sequence[Effect]) -> tuple[int, str]:
    """Map a Jacobian name to (-1, rig field) or (effect index, parameter).

    Effect parameters are named ``effect.param`` (``extra_mode.f_hz``); a bare
    parameter name is accepted when exactly one effect has it.
    """
    if name in Rig.names():
        return -1, name
    hits = []
    for i, eff in enumerate(effects):
        for p in eff.parameter_names:
            if name in (eff.qualified(p), p):
                hits.append((i, p))
    if len(hits) == 1:
        return hits[0]
    if not hits:
        raise DataError(f"no parameter {name!r}; known: {', '.join(parameter_names(Rig(), effects))}")
    raise DataError(f"parameter name {name!r} is ambiguous; use the qualified form effect.param")


@validate_params({"rig": [None, Rig], "outputs": [NAMES], "threads": [None, Interval(Whole, 1)],
                  "validate": [bool]})
def frf(
    freq_hz,
    rig: Rig | None = None,
    effects: Sequence[Effect] = (),
    wrt: Sequence[str] | None = None,
    outputs: Sequence[str] = CHANNELS,
    threads: int | None = None,
    validate: bool = True,
) -> Response:
    """FRFs of the SATMD for a unit force on the primary mass.

    Parameters
    ----------
    freq_hz : array_like, shape (n_freq,)
        Frequencies in Hz (> 0 not required; 0 gives the static solution). Complex values evaluate the
        model at ``s = 2πi f`` off the imaginary axis (``f − iσ/2π`` is ``H(iω + σ)``).
    rig : Rig
        Parameters; fields may be arrays that broadcast to a batch shape.
    effects : sequence of Effect
        Missing-physics effects (SPEC §8) applied in order. Their parameters
        may also be arrays that broadcast with the rig.
    wrt : sequence of str, optional
        Parameter names for the analytic Jacobian: rig fields
        (``"m2"``, ``"R"``, ...) or effect parameters (``"extra_mode.f_hz"``).
    outputs : sequence of str
        Channels to return (and differentiate).
    threads : int, optional
        Worker threads for large batches (default: `default_threads`: all
        cores up to 8 on more than two, else one).
    validate : bool
        Check the rig for impossible values (fitting loops that keep the
        parameters inside bounds switch this off).

    Returns
    -------
    Response

    Notes
    -----
    Results of 1 MB and more are written into memory of earlier results the caller has let go of (no
    page zeroed again: 10⁴ rigs x 60 frequencies run ~1.3x faster); a result still held, or any view
    of it, is never written. Up to four such blocks, 512 MB, are kept; ``satmd.physics.buffers.OUTPUTS.clear()``
    gives them back to the system.
    """
    rig = Rig() if rig is None else rig
    if validate:
        rig.validate()
    freq = np.asarray(freq_hz)  # complex: the model off the axis, at s = 2πi f (an exponential window's data)
    freq = freq.astype(complex if np.iscomplexobj(freq) else float)
    if freq.ndim != 1:
        raise DataError(f"freq_hz must be 1-D, got shape {freq.shape}")
    if not np.all(np.isfinite(freq)):
        raise DataError("freq_hz contains NaN or infinite values")
    unknown = [o for o in outputs if o not in CHANNELS]
    if unknown:
        raise DataError(f"unknown output channel(s) {unknown}; known: {', '.join(CHANNELS)}")
    for i, eff in enumerate(effects):  # a nonlinear element has no frequency-domain form: never ignored silently
        if not isinstance(eff, Effect) or eff.acts_on == "nonlinear":
            hint = (": a nonlinear element acts in the time domain (simulate(time=True, nonlinear=[...])); at one "
                    "level its equivalent linear rig is satmd.physics.nonlinear.equivalent_rig(rig, [element], ...)"
                    if isinstance(eff, Effect) else "")
            raise DataError(f"effects[{i}] is {type(eff).__name__}, not a missing-physics effect (SPEC §8){hint}")
    wrt = tuple(wrt or ())
    targets = [resolve_parameter(n, effects) for n in wrt]

    leaves = [getattr(rig, n) for n in Rig.names()]
    for eff in effects:
        leaves += [eff.params[p] for p in eff.parameter_names]
    batch = np.broadcast_shapes(*(np.shape(x) for x in leaves))
    n_rows = int(np.prod(batch, dtype=int))
    n_freq = freq.size
    omega = 2.0 * np.pi * freq

    # each channel's array is one slab of a single allocation: one large block is mapped in huge pages,
    # several blocks of a few MB each cost the kernel 4 kB page faults that took as long as a third of the solve;
    # the block of an earlier call the caller has let go of is reused (`buffers.OutputPool`: no page zeroed again)
    block = OUTPUTS.empty((len(outputs), n_rows, n_freq))
    out = dict(zip(outputs, block))
    jac_block = OUTPUTS.empty((len(outputs), n_rows, n_freq, len(wrt))) if wrt else None
    jac = {} if jac_block is None else dict(zip(outputs, jac_block))
    step = max(1, (_CHUNK_ELEMENTS * (2 if wrt else 1)) // max(n_freq, 1))  # a Jacobian's chunks: more work per call
    flat_rig = {n: _flatten(getattr(rig, n), batch) for n in Rig.names()}
    rig_arrays = [n for n, v in flat_rig.items() if isinstance(v, np.ndarray)]
    flat_eff = [{p: _flatten(eff.params[p], batch) for p in eff.parameter_names} for eff in effects]

    plain = not effects and np.isrealobj(omega)  # no hooks to call: Z's entries are written in place
    in_place = plain and set(wrt) <= PLAIN_WRT  # with a Jacobian in the usual parameters: its tangents too

    def run(sl, work):
        if in_place:
            rig_rows = {**flat_rig, **{n: flat_rig[n][sl, None] for n in rig_arrays}}
            if wrt:
                solve_with_tangents(plain_dual_terms(omega, rig_rows, wrt, work), wrt, outputs,
                                    {ch: out[ch][sl] for ch in outputs}, {ch: jac[ch][sl] for ch in outputs}, work)
            else:
                solve_plain_into(omega, rig_rows, {ch: out[ch][sl] for ch in outputs}, work)
            return
        rig_c = Rig(**{**flat_rig, **{n: flat_rig[n][sl, None] for n in rig_arrays}})
        effs_c = [eff.replace(**{p: _rows(v, sl) for p, v in fp.items()}) for eff, fp in zip(effects, flat_eff)]
        if wrt:
            rig_c, effs_c = _seed_duals(rig_c, effs_c, wrt, targets)
            solve_with_tangents(
                terms(omega, rig_c, effs_c), wrt, outputs,
                {ch: out[ch][sl] for ch in outputs}, {ch: jac[ch][sl] for ch in outputs}, work,
            )
        else:
            solve_into(terms(omega, rig_c, effs_c), {ch: out[ch][sl] for ch in outputs}, work)

    chunks = [slice(i, min(i + step, n_rows)) for i in range(0, n_rows, step)]
    n_threads = _threads(threads, n_rows * n_freq, len(chunks))
    if n_threads > 1:  # NumPy releases the GIL inside ufuncs
        import threading  # only big batches need threads
        from concurrent.futures import ThreadPoolExecutor

        lock, todo = threading.Lock(), iter(chunks)

        def worker():  # one workspace per thread; chunks handed out one at a time, so a busy core holds none back
            work = Workspace()
            while True:
                with lock:
                    sl = next(todo, None)
                if sl is None:
                    return
                run(sl, work)

        with ThreadPoolExecutor(n_threads) as pool:
            for f in [pool.submit(worker) for _ in range(n_threads)]:
                f.result()
    else:
        with kept_workspace() as work:
            for sl in chunks:
                run(sl, work)

    shape = batch + (n_freq,)
    res = Response(freq_hz=freq, wrt=wrt)
    for ch in outputs:
        setattr(res, ch, out[ch].reshape(shape))
    res.jac = {ch: a.reshape(shape + (len(wrt),)) for ch, a in jac.items()}
    for used in (block, jac_block):
        if used is not None:
            OUTPUTS.keep(used)
    return res


def default_threads(n_points: int) -> int:
    """Worker threads `frf` uses for ``n_points`` (batch x frequency) points when not told: one for small
    problems (below 100 000 points) and on two cores or fewer, else all cores up to 8. On two cores the
    workers contend for the cores with each other and with anything else running (10⁴ rigs x 60
    frequencies, issue 36: at best 10 % faster than one thread on a quiet machine, 1.4x slower on a busy one).
    """
    cores = os.cpu_count() or 1
    return 1 if n_points < _THREADED_POINTS or cores <= 2 else min(cores, 8)


def _threads(requested, n_points, n_chunks):
    wanted = default_threads(n_points) if requested is None else int(requested)
    return max(1, min(wanted, n_chunks))


def _seed_duals(rig, effects, wrt, targets):
    rig_changes = {}
    effects = list(effects)
    for name, (i, p) in zip(wrt, targets):
        if i < 0:
            rig_changes[p] = dual.Dual.variable(getattr(rig, p), name)
        else:
            effects[i] = effects[i].replace(**{p: dual.Dual.variable(effects[i].params[p], name)})
    return rig.replace(**rig_changes) if rig_changes else rig, effects


def _flatten(x, batch):
    if np.ndim(x) == 0:
        return x
    return np.broadcast_to(np.asarray(x, dtype=float), batch).reshape(-1)


def _rows(x, sl):
    return x[sl, None] if isinstance(x, np.ndarray) else x

"""The one time-domain integrator: the SATMD with nonlinear elements, driven by a sampled force.

Method (superposition on the linear part, exact discretisation, implicit element forces):

1. The linear system ``x' = A x + B [F, g]`` (`statespace`) is discretised exactly
   for inputs that are straight lines between samples (first-order hold).
2. The force's response ``x_F`` is computed over the whole record by modal
   recursions (`scipy.signal.lfilter`): no Python loop.
3. The element forces ``g`` need a loop over samples: ``z_{k+1} = Φ z_k + G0 g_k
   + G1 g_{k+1}`` with ``g_{k+1} = g(C (x_F + z)_{k+1})`` solved by fixed-point
   steps from a linear extrapolation (G1 is O(Δ²) on displacements, O(Δ) on
   rates, so the steps contract fast). To make the loop short it runs on many
   segments of the record at once as a NumPy batch: each segment starts from
   rest ``warmup`` before its part of the record, long enough for the slowest
   mode to forget the start (to ``memory_tol``); ``segments=1`` is exact.
4. The outputs are the linear responses to ``[F, g]`` over the whole record.

In the linear limit (no elements, or zero strength) the outputs are the
exact first-order-hold response of the SPEC §2 model, whose steady state is the
FRF of `satmd.physics.frf`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from numbers import Real

import numpy as np

from ...conventions import ACCEL_CHANNELS
from ...errors import DataError
from ...validation import NAMES, Interval, Options, validate_params
from ..rig import Rig
from . import kernel
from .statespace import Modal, discretise, read_rows, slowest_decay, system

OUTPUTS = ("a1", "a2", "u1", "u2", "q", "v1", "v2", "i")
_STATE_INDEX = {"u1": 0, "u2": 1, "q": 2, "v1": 3, "v2": 4}


@dataclass(frozen=True)
class NonlinearResponse:
    """Time histories from `integrate`.

    Parameters
    ----------
    fs_hz : sample rate [Hz].
    signals : {name: array (N,) or (batch, N)}: the requested outputs (a1, a2 [m/s²], u1, u2 [m],
        q [C], v1, v2 [m/s], i [A]) and each element's force ``g:<name>``.
    meta : how it was computed (segments, warm-up, fixed-point steps).
    """

    fs_hz: float
    signals: dict
    meta: dict = field(default_factory=dict)

    def __getattr__(self, key):
        sig = self.__dict__.get("signals", {})
        if key in sig:
            return sig[key]
        raise AttributeError(key)

    def to_dict(self) -> dict:
        """JSON-ready dict (signals as lists)."""
        return {"fs_hz": self.fs_hz, "signals": {k: np.asarray(v).tolist() for k, v in self.signals.items()},
                "meta": dict(self.meta)}

    def report(self) -> str:
        """One line per signal: its RMS."""
        lines = [f"time response at {self.fs_hz:g} Hz ({self.meta.get('segments', 1)} segments)"]
        for k, v in self.signals.items():
            lines.append(f"  {k:>24s}: RMS {float(np.sqrt(np.mean(np.square(v)))):.4g}")
        return "\n".join(lines)


def _batch_size(rig, elements, force) -> int:
    sizes = {int(np.size(v)) for v in rig.as_dict().values() if np.ndim(v)}
    for el in elements:
        sizes |= {int(np.size(v)) for v in el.params.values() if np.ndim(v)}
    if np.ndim(force) == 2:
        sizes.add(int(np.shape(force)[0]))
    sizes.discard(1)
    if len(sizes) > 1:
        raise DataError(f"integrate: batch sizes disagree ({sorted(sizes)})")
    return sizes.pop() if sizes else 1


def band_limited(force, fs_hz: float, pad: int = 2048) -> np.ndarray:
    """The samples whose straight-line interpolation drives the rig as the band-limited force would.

    Straight lines between samples pass a sinusoid at f with gain sinc²(f / fs) (-0.8 % at
    100 Hz and 2048 Hz); dividing the spectrum by it (padded: 0 before the record, its end mirrored
    after it, `_padded`) makes the first-order-hold response that of the Shannon-interpolated force.

    Parameters
    ----------
    force : (N,) or (batch, N) samples.
    fs_hz : sample rate [Hz].
    pad : samples added at each end before the FFT.

    Returns
    -------
    ndarray, the shape of ``force``.
    """
    from scipy.fft import irfft, rfft, rfftfreq

    x = np.asarray(force, float)
    n = x.shape[-1]
    padded, size = _padded(x, pad)
    gain = np.sinc(rfftfreq(size, 1.0)) ** 2  # f / fs on the rfft grid
    return irfft(rfft(padded) / gain, size)[..., pad:pad + n]


def _padded(x, pad: int):
    """(``x`` with ``pad`` zeros before it and its own end mirrored after it, tapered to zero; the FFT's size): a
    record starts from rest, and its force goes on after its last sample; cut to zero there, the step rang over
    the last samples through the modes near Nyquist (an independent wing's quiet channel missed its last sample
    by 2.5 times its RMS; with its place and law given, its held-out levels' worst NRMSE went 0.034 → 0.025,
    3x its noise 0.027)."""
    from scipy.fft import next_fast_len

    n = x.shape[-1]
    size = next_fast_len(n + 2 * pad, real=True)
    padded = np.zeros(x.shape[:-1] + (size,))
    padded[..., pad:pad + n] = x
    tail = min(pad, n)
    if tail:
        taper = np.cos(np.linspace(0.0, np.pi / 2, tail)) ** 2
        padded[..., pad + n:pad + n + tail] = x[..., ::-1][..., :tail] * taper
    return padded, size


def upsample(force, k: int, pad: int = 2048) -> np.ndarray:
    """Band-limited interpolation of samples to ``k`` times the rate (FFT; 0 before the record, its end mirrored
    after it: `_padded`).

    Parameters
    ----------
    force : (N,) or (batch, N) samples.
    k : factor.
    pad : samples added at each end before the FFT.

    Returns
    -------
    ndarray (..., k N); every k-th sample is the input.
    """
    from scipy.fft import irfft, rfft

    x = np.asarray(force, float)
    n = x.shape[-1]
    padded, size = _padded(x, pad)
    spec = rfft(padded)
    if size % 2 == 0:
        spec[..., -1] *= 0.5  # split the Nyquist line between its two images
    up = irfft(spec, size * k) * k
    return up[..., pad * k:(pad + n) * k]


@validate_params({"rig": [Rig], "fs_hz": [Interval(Real, 0, open="lo")], "outputs": [NAMES],
                  "hold": [Options(("bandlimited", "linear"))], "backend": [Options(("auto", "numba", "numpy"))],
                  "extrapolate": [bool]})
def integrate(rig, force, fs_hz: float, elements=(), outputs=ACCEL_CHANNELS, segments="auto",
              warmup_s="auto", memory_tol: float = 1e-7, corrections: int = 3,
              hold: str = "bandlimited", backend: str = "auto", oversample: int = 1,
              extrapolate: bool = False) -> NonlinearResponse:
    """Simulate the rig with nonlinear elements for a sampled force on the primary mass, from rest.

    Parameters
    ----------
    rig : Rig; fields scalars or 1-D arrays (a batch of parameter sets, simulated together).
    force : (N,) or (batch, N) force samples [N]; straight lines between samples.
    fs_hz : sample rate [Hz].
    elements : sequence of NonlinearElement (parameters scalars or length-batch arrays).
    outputs : names from a1 a2 u1 u2 q v1 v2 i.
    segments : "auto", or the number of segments the record is cut into for the loop (1: exact).
    warmup_s : "auto" (1.5 x the time the slowest linear mode takes to decay to ``memory_tol``), or seconds of warm-up per segment.
    memory_tol : what the warm-up leaves of a segment's wrong start (relative).
    corrections : fixed-point steps on the implicit element forces per sample.
    hold : ``"bandlimited"`` (default): the force is a band-limited signal sampled at fs (see
        `band_limited`); ``"linear"``: it is a straight line between samples.
    backend : ``"auto"`` (compiled when numba is installed, else NumPy), ``"numba"`` or ``"numpy"``.
        The compiled pass is sequential over the whole record (``segments``, ``warmup_s``
        and ``memory_tol`` then do not apply: it is exact).
    oversample : integrate at this multiple of fs (the force interpolated band-limited) and return
        every ``oversample``-th sample: the element forces' straight-line hold errs by ~(ωΔ)²/12
        (0.8 % at 100 Hz and 2048 Hz); 4 brings it to 0.05 %.
    extrapolate : also integrate at twice ``oversample`` and return ``(4 y(2k) - y(k)) / 3`` (Richardson):
        the hold's leading error, in Δ², cancels (what is left falls as Δ⁴); three times the work.

    Returns
    -------
    NonlinearResponse
        Arrays of shape (N,) for a single parameter set, (batch, N) for a batch.
    """
    if extrapolate and elements:  # without elements the response is exact: nothing to extrapolate
        k = max(1, int(oversample))
        fine, coarse = (integrate(rig, force, fs_hz, elements, outputs, segments, warmup_s, memory_tol, corrections,
                                  hold, backend, j) for j in (2 * k, k))
        return NonlinearResponse(fine.fs_hz, {n: (4.0 * v - coarse.signals[n]) / 3.0 for n, v in fine.signals.items()},
                                 {**fine.meta, "oversample": k, "extrapolated": True})
    if int(oversample) > 1:
        k = int(oversample)
        res = integrate(rig, upsample(force, k), fs_hz * k, elements, outputs, segments, warmup_s, memory_tol,
                        corrections, hold, backend)
        return NonlinearResponse(res.fs_hz / k, {n: v[..., ::k] for n, v in res.signals.items()},
                                 {**res.meta, "oversample": k})
    bad = [o for o in outputs if o not in OUTPUTS]
    if bad:
        raise DataError(f"integrate: unknown output(s) {bad}; known: {', '.join(OUTPUTS)}")
    force = np.asarray(force, float)
    if force.ndim not in (1, 2) or force.shape[-1] < 2 or not np.all(np.isfinite(force)):
        raise DataError("integrate: force must be finite samples, shape (N,) or (batch, N)")
    batched = force.ndim == 2 or any(np.ndim(v) for v in rig.as_dict().values()) or any(
        np.ndim(v) for el in elements for v in el.params.values())
    P = _batch_size(rig, elements, force)
    n_samples = force.shape[-1]
    drive = band_limited(force, fs_hz) if hold == "bandlimited" else force
    F = np.broadcast_to(drive, (P, n_samples))
    A, B = system(rig, elements, P)
    dt = 1.0 / fs_hz
    phi, g0, g1 = discretise(A, B, dt)
    m = len(elements)
    if backend == "numba" and not kernel.available:
        raise DataError("integrate: backend='numba' needs numba (pip install numba)")
    if backend != "numpy" and kernel.available:
        out = _compiled(elements, F, np.broadcast_to(force, (P, n_samples)), A, B, phi, g0, g1, outputs, corrections)
        if not batched:
            out = {k: v[0] for k, v in out.items()}
        return NonlinearResponse(float(fs_hz), out, {"segments": 1, "backend": "numba", "corrections": corrections})
    modal = [Modal(phi[b], g0[b], g1[b]) for b in range(P)]
    eta = [modal[b].states(F[b][None], [0]) for b in range(P)]  # the force's response, whole record
    if m:
        g, meta = _element_forces(rig, elements, modal, eta, A, phi, g0, g1, fs_hz, segments, warmup_s,
                                  memory_tol, corrections)
    else:
        g, meta = np.zeros((P, 0, n_samples)), {"segments": 0}
    rows, direct, names = _output_rows(A, B, elements, outputs)
    out = {name: np.empty((P, n_samples)) for name in names}
    for b in range(P):
        u = np.vstack([np.broadcast_to(force, (P, n_samples))[b][None], g[b]])
        states = eta[b] + modal[b].states(g[b], range(1, 1 + m)) if m else eta[b]
        y = modal[b].project(rows[b], states) + direct[b] @ u
        for r, name in enumerate(names):
            out[name][b] = y[r]
    for j, el in enumerate(elements):
        out[f"g:{el.name}"] = g[:, j]
    if not batched:
        out = {k: v[0] for k, v in out.items()}
    return NonlinearResponse(float(fs_hz), out, meta)


def _compiled(elements, drive, force, A, B, phi, g0, g1, outputs, corrections) -> dict:
    """Outputs and element forces by the compiled sequential pass (`kernel`)."""
    P = drive.shape[0]
    m = len(elements)
    signals = sorted({s for el in elements for s in el.reads}) or ["d"]
    C = read_rows(signals)
    rd = [signals.index(el.reads[0]) for el in elements]
    D = C[None] @ g1[:, :, 1:]
    prm = np.zeros((P, m, 2))
    for j, el in enumerate(elements):
        p0, p1 = el.kernel_parameters()
        prm[:, j, 0], prm[:, j, 1] = np.broadcast_to(np.ravel(p0), (P,)), np.broadcast_to(np.ravel(p1), (P,))
    rows, direct, names = _output_rows(A, B, elements, outputs)
    y, g = kernel.run(phi, g0, g1, C, D, rows, direct, np.ascontiguousarray(drive, float),
                      np.ascontiguousarray(force, float), [type(el).law for el in elements], prm, rd, corrections)
    out = {name: y[:, r] for r, name in enumerate(names)}
    for j, el in enumerate(elements):
        out[f"g:{el.name}"] = g[:, j]
    return out


def _output_rows(A, B, elements, outputs):
    """Rows and direct terms giving each output from (state, inputs)."""
    P, n, p = B.shape
    rows, direct = np.zeros((P, len(outputs), n)), np.zeros((P, len(outputs), p))
    for r, name in enumerate(outputs):
        if name in ACCEL_CHANNELS:
            k = 3 if name == "a1" else 4
            rows[:, r], direct[:, r] = A[:, k], B[:, k]
        elif name == "i":  # the true current: q' = ĩ + (shunt element inputs)
            rows[:, r], direct[:, r] = A[:, 2], B[:, 2]
        else:
            rows[:, r, _STATE_INDEX[name]] = 1.0
    return rows, direct, list(outputs)


def _element_forces(rig, elements, modal, eta, A, phi, g0, g1, fs_hz, segments, warmup_s, memory_tol,
                    corrections):
    """The element inputs g (batch, m, N), by the segmented implicit loop (see the module docstring)."""
    P, N = len(eta), eta[0].shape[1]
    m = len(elements)
    signals = sorted({s for el in elements for s in el.reads})
    C = read_rows(signals)
    index = {s: r for r, s in enumerate(signals)}
    yF = np.stack([modal[b].project(C, eta[b]) for b in range(P)])  # (P, r, N): the force's part of the readings
    if segments == 1:
        warm = 0
    elif warmup_s == "auto":
        # x1.5: amplitude-dependent stiffness and damping make the nonlinear memory longer than the linear one
        warm = int(np.ceil(1.5 * np.log(1.0 / memory_tol) / slowest_decay(A) * fs_hz))
    else:
        warm = int(round(float(warmup_s) * fs_hz))
    if segments == "auto":
        core = max(warm // 2, int(np.ceil(N / 64)), 256)
    else:
        core = int(np.ceil(N / max(int(segments), 1)))
    S = int(np.ceil(N / core))
    if S == 1:
        warm = 0
    steps = core + warm
    # padded read signals: warm zeros in front (the rig is at rest before the record), zeros after it
    padded = np.zeros((P, C.shape[0], warm + S * core))
    padded[:, :, warm:warm + N] = yF
    starts = np.arange(S) * core  # in padded samples; segment s runs padded[start : start + steps]
    win = np.stack([padded[:, :, s0:s0 + steps] if s0 + steps <= padded.shape[2] else
                    np.pad(padded[:, :, s0:], ((0, 0), (0, 0), (0, s0 + steps - padded.shape[2])))
                    for s0 in starts], axis=-1)  # (P, r, steps, S)
    # element copies whose parameters broadcast against (P, S) readings
    shaped = [el.replace(**{k: (np.asarray(v, float).reshape(-1, 1) if np.ndim(v) else v)
                            for k, v in el.params.items()}) for el in elements]
    Cb = np.broadcast_to(C, (P,) + C.shape)
    phi_b, G0, G1 = phi, g0[:, :, 1:], g1[:, :, 1:]  # element columns only
    D = Cb @ G1  # (P, r, m): how g_{k+1} feeds back into the readings at k+1 (small)
    z = np.zeros((P, phi.shape[1], S))
    g_now = np.zeros((P, m, S))
    g_prev = np.zeros((P, m, S))
    out = np.empty((P, m, steps, S))
    rd = [index[el.reads[0]] for el in shaped]  # the one signal each element reads
    Djj = np.stack([D[:, r, j] for j, r in enumerate(rd)], axis=1)[:, :, None]  # (P, m, 1)
    single, el0 = m == 1, shaped[0]
    for k in range(steps):
        w = phi_b @ z + G0 @ g_now  # (P, n, S)
        y0 = win[:, :, k] + Cb @ w  # (P, r, S)
        guess = 2.0 * g_now - g_prev
        for _ in range(corrections):  # Newton on g = f(y0 + D g), diagonal in the elements
            y = y0 + D @ guess
            if single:
                yy = {el0.reads[0]: y[:, rd[0]]}
                res = guess[:, 0] - el0.force(yy, rig)
                guess = guess - (res / (1.0 - el0.slope(yy, rig) * Djj[:, 0]))[:, None]
            else:
                ys = [{el.reads[0]: y[:, r]} for el, r in zip(shaped, rd)]
                res = guess - np.stack([el.force(yy, rig) for el, yy in zip(shaped, ys)], axis=1)
                slope = np.stack([el.slope(yy, rig) for el, yy in zip(shaped, ys)], axis=1)
                guess = guess - res / (1.0 - slope * Djj)
        z = w + G1 @ guess
        g_prev, g_now = g_now, guess
        out[:, :, k] = guess
    g = out[:, :, warm:, :].transpose(0, 1, 3, 2).reshape(P, m, S * core)[:, :, :N]
    return g, {"segments": S, "warmup_s": warm / fs_hz, "core_s": core / fs_hz, "corrections": corrections}

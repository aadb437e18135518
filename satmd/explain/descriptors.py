"""Scalar FRF descriptors: ξ_FRF (paper eq. 27) and physically direct ones.

``xi_frf``
    ``ξ = ‖Y − Y_nom‖₂ / ‖Y_nom‖₂`` on the U1 channel of the full response
    over the paper grid, ``Y_nom`` at (R=20, L=0.05, m2=0.3, kp=50e3) (SPEC §6).
``modal_descriptors``
    What the paper lists as future work ("resonance shifts, peak
    attenuation, anti-resonance location, or modal splitting"), read off the
    primary's receptance |U1| on a fine grid:

    - ``f1_hz``, ``f2_hz``: the two highest resonance peaks, lower first
      (parabolic interpolation of log|U1| around each grid maximum);
    - ``splitting_hz``: f2 − f1;
    - ``f_anti_hz``: the anti-resonance, the minimum of |U1| between them;
    - ``peak_db``: the highest peak, 20 log10 max|U1| (m/N);
    - ``attenuation_db``: 20 log10(max|U1_host| / max|U1|), the reduction of
      the worst peak against the host alone. The host alone is the same
      model with a vanishing absorber mass (m2 → 0 decouples the absorber
      exactly: U1 → F0 / (k1 + iωc1 − m1ω²)), so nothing is re-derived.

Every function takes a `Rig` whose fields may be arrays: one batched call.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import TINY
from ..physics import PAPER_GRID_HZ, Rig, frf

#: Reference point of ξ (SPEC §6).
NOMINAL = {"R": 20.0, "L": 0.05, "m2": 0.3, "kp": 50e3}
#: The SPEC §6 grid: 10 x 10 x 8 x 8 = 6400 samples.
XI_GRID = {
    "R": np.linspace(8.0, 60.0, 10),
    "L": np.linspace(0.032, 0.3, 10),
    "m2": np.linspace(0.3, 0.6, 8),
    "kp": np.linspace(50e3, 120e3, 8),
}
NAMES = ("R", "L", "m2", "kp")
#: Fine grid for the modal descriptors (0.2 Hz steps over the paper band).
FINE_GRID_HZ = np.linspace(40.0, 130.0, 451)
MODAL_NAMES = ("f1_hz", "f2_hz", "splitting_hz", "f_anti_hz", "peak_db", "attenuation_db")
_HOST_ALONE_M2 = 1e-12  # kg: the absorber decouples as m2 -> 0


def xi_frf(rig: Rig | None = None, freq=PAPER_GRID_HZ, nominal: dict | None = None, channel: str = "u1"):
    """ξ_FRF of each rig in the batch (eq. 27).

    Parameters
    ----------
    rig : Rig
        Fields may be arrays (a batch); default: the paper's rig.
    freq : frequencies [Hz] (default: the paper grid).
    nominal : rig values of the reference Y_nom (default: SPEC §6).
    channel : response channel (default u1).

    Returns
    -------
    ndarray
        ξ with the rig's batch shape.
    """
    rig = Rig() if rig is None else rig
    # the reference keeps the rig's other (fixed) parameters; they must be scalars
    base = Rig(**{n: _scalar(getattr(rig, n)) for n in Rig.names()})
    base = base.replace(**(NOMINAL if nominal is None else nominal))
    y = getattr(frf(freq, rig, outputs=(channel,)), channel)
    y_nom = getattr(frf(freq, base, outputs=(channel,)), channel)
    return np.linalg.norm(y - y_nom, axis=-1) / np.linalg.norm(y_nom)


def grid_rig(grid: dict | None = None, rig: Rig | None = None):
    """The full-factorial grid as a batched Rig and its (n, 4) inputs [R, L, m2, kp]."""
    grid = XI_GRID if grid is None else grid
    rig = Rig() if rig is None else rig
    mesh = np.meshgrid(*(np.asarray(grid[n], float) for n in NAMES), indexing="ij")
    X = np.stack([m.ravel() for m in mesh], axis=1)
    return rig.replace(**{n: X[:, j] for j, n in enumerate(NAMES)}), X


@dataclass(frozen=True)
class DescriptorData:
    """Inputs X (n, 4) in physical units [R, L, m2, kp] and descriptor targets."""

    X: np.ndarray
    targets: dict
    names: tuple = NAMES

    def __len__(self):
        return self.X.shape[0]


def xi_dataset(grid: dict | None = None, freq=PAPER_GRID_HZ, modal: bool = False) -> DescriptorData:
    """The SPEC §6 dataset: ξ (and optionally the modal descriptors) over the grid.

    Parameters
    ----------
    grid : {R, L, m2, kp: values} of the full-factorial grid (default: SPEC §6).
    freq : frequencies [Hz] of ξ (default: the paper grid).
    modal : add the modal descriptors.

    Returns
    -------
    DescriptorData
    """
    rig, X = grid_rig(grid)
    targets = {"xi": xi_frf(rig, freq)}
    if modal:
        targets.update(modal_descriptors(rig))
    return DescriptorData(X, targets)


def _parabolic(logm: np.ndarray, idx: np.ndarray, freq: np.ndarray):
    """Vertex of the parabola through (idx-1, idx, idx+1) per row: (frequency, log magnitude)."""
    n = logm.shape[-1]
    i = np.clip(idx, 1, n - 2)
    rows = np.arange(logm.shape[0])
    y0, y1, y2 = logm[rows, i - 1], logm[rows, i], logm[rows, i + 1]
    den = y0 - 2 * y1 + y2
    delta = np.where(np.abs(den) > 0, 0.5 * (y0 - y2) / np.where(den == 0, 1, den), 0.0)
    delta = np.where(idx == i, np.clip(delta, -0.5, 0.5), 0.0)  # grid ends: no interpolation
    df = freq[1] - freq[0]
    return freq[idx] + delta * df, y1 - 0.25 * (y0 - y2) * delta


def modal_descriptors(rig: Rig | None = None, freq=FINE_GRID_HZ) -> dict:
    """Resonances, splitting, anti-resonance and peak attenuation of |U1| (module doc).

    Parameters
    ----------
    rig : Rig
        Fields may be arrays (a batch); default: the paper's rig.
    freq : uniform frequency grid [Hz], fine enough to resolve the peaks.

    Returns
    -------
    dict
        Arrays with the rig's batch shape; NaN where fewer than two peaks lie inside the band.
    """
    rig = Rig() if rig is None else rig
    freq = np.asarray(freq, float)
    batch = rig.batch_shape
    mag = np.abs(frf(freq, rig, outputs=("u1",)).channel("u1")).reshape(-1, freq.size)
    logm = np.log(mag)
    n = mag.shape[0]
    inner = (logm[:, 1:-1] > logm[:, :-2]) & (logm[:, 1:-1] >= logm[:, 2:])
    peaks = np.where(np.pad(inner, ((0, 0), (1, 1))), logm, -np.inf)
    top = np.argsort(-peaks, axis=1)[:, :2]
    valid = np.isfinite(np.take_along_axis(peaks, top, axis=1)).all(axis=1)
    lo, hi = np.sort(top, axis=1).T
    f1, _ = _parabolic(logm, lo, freq)
    f2, _ = _parabolic(logm, hi, freq)
    cols = np.arange(freq.size)
    between = (cols[None, :] > lo[:, None]) & (cols[None, :] < hi[:, None])
    anti = np.argmin(np.where(between, logm, np.inf), axis=1)
    fa, _ = _parabolic(-logm, anti, freq)
    fa = np.where(between.any(axis=1), fa, np.nan)
    peak_log = np.max(logm, axis=1)
    host = frf(freq, rig.replace(m2=_HOST_ALONE_M2), outputs=("u1",)).channel("u1")
    host_peak = np.log(np.max(np.abs(host), axis=-1)).reshape(-1)
    host_peak = np.broadcast_to(host_peak, (n,)) if host_peak.size == 1 else host_peak
    nan = np.where(valid, 1.0, np.nan)
    out = {
        "f1_hz": f1 * nan,
        "f2_hz": f2 * nan,
        "splitting_hz": (f2 - f1) * nan,
        "f_anti_hz": fa * nan,
        "peak_db": 20 / np.log(10) * peak_log,
        "attenuation_db": 20 / np.log(10) * (host_peak - peak_log),
    }
    return {k: v.reshape(batch) for k, v in out.items()}


def modal_physics(rig: Rig | None = None) -> dict:
    """What the undamped physics says the modal descriptors are (no fit).

    - ``f_absorber_hz``: the absorber on its own spring, sqrt(kp/m2)/2π, where
      textbook TMD theory puts the primary's anti-resonance;
    - ``f_anti_roots_hz``: the anti-resonances of U1 with the shunt, the roots
      ω² of det[[Z22, Z23], [Z32, Z33]] = 0 (damping dropped),
      m2 L ω⁴ − (kp L + m2/Cp) ω² + (kp − e²/Cp)/Cp = 0, ascending (..., 2);
      they interlace with the modes, so one lies between any two adjacent peaks;
    - ``f_modes_hz``: the three undamped natural frequencies of
      (K − ω² diag(m1, m2, L)) x = 0, ascending (..., 3).

    For a stable rig (e² < kp Cp: the shorted piezo keeps a positive
    stiffness) modes and anti-resonances interlace; beyond it the negative
    roots are clipped to 0 Hz.

    Parameters
    ----------
    rig : Rig
        Fields may be arrays (a batch); default: the paper's rig.

    Returns
    -------
    dict
        Arrays with the rig's batch shape (``f_modes_hz`` with a trailing 3).
    """
    rig = Rig() if rig is None else rig
    b = np.broadcast_arrays(*(np.asarray(getattr(rig, n), float) for n in ("m1", "k1", "m2", "kp", "L", "e", "Cp")))
    m1, k1, m2, kp, L, e, Cp = b
    two_pi = 2 * np.pi
    f_abs = np.sqrt(kp / m2) / two_pi
    a, bb, c = m2 * L, kp * L + m2 / Cp, (kp - e * e / Cp) / Cp
    disc = np.sqrt(np.maximum(bb * bb - 4 * a * c, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        roots = np.stack([(bb - disc) / (2 * a), (bb + disc) / (2 * a)], axis=-1)
    f_roots = np.sqrt(np.maximum(roots, 0.0)) / two_pi
    K = np.zeros(m1.shape + (3, 3))
    K[..., 0, 0], K[..., 0, 1], K[..., 0, 2] = k1 + kp, -kp, e / Cp
    K[..., 1, 1], K[..., 1, 2], K[..., 2, 2] = kp, -e / Cp, 1 / Cp
    K = K + np.swapaxes(np.triu(K, 1), -1, -2)
    s = 1 / np.sqrt(np.stack([m1, m2, np.maximum(L, TINY)], axis=-1))  # mass-normalised: symmetric eigenproblem
    lam = np.linalg.eigvalsh(K * s[..., :, None] * s[..., None, :])
    return {"f_absorber_hz": f_abs, "f_anti_roots_hz": f_roots,
            "f_modes_hz": np.sqrt(np.maximum(lam, 0.0)) / two_pi}


def _scalar(v):
    """A fixed parameter of a batch (its first value: fixed parameters are scalars in practice)."""
    return v if np.ndim(v) == 0 else float(np.asarray(v, float).ravel()[0])

"""Inputs of an inverse model: any FRF brought onto the net's grid, and the forward check of a prediction.

The nets take (A1, A2) on one fixed grid (the paper's 60 points, 40-130 Hz).
Measured FRFs rarely sit on it. `prepare` brings them there:

- inside the data's span: cubic-spline interpolation of the complex FRF
  through the measured points (std columns interpolated linearly), a
  warning when the data are coarser than the grid;
- grid points outside the data's span (a narrow ``--band``, a short sweep):
  model-based, the forward model at the (R, L) fitted by least squares to the
  measured points (`satmd.identification.identify`, rig fixed), with a warning
  naming how many points were filled.

`forward_check` is the other half: every prediction goes back through the
forward model at the *measured* frequencies (those inside the grid's band)
and the residual is compared with what the model's own accuracy and the
noise explain. A rig unlike the training rig, or an effect the model lacks,
shows up there instead of passing silently.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..errors import DataError
from ..physics import Rig, frf
from .dataset import InverseDataset, features_to_complex

#: ``forward residual / expected residual`` above this marks a prediction the data do not support.
CHECK_LIMIT = 3.0
#: The net's accuracy on the forward residual when the fit recorded none (models saved before the check).
DEFAULT_RESIDUAL_REF = 0.01


@dataclass
class Inputs:
    """FRFs on the model grid (``a``: (n, 2, F) complex, ``std`` or None) and the measured points behind them.

    ``raw`` holds, per FRF, ``(freq, a (2, k), std (2, k) or None)``: the
    measured points inside the grid's band, which the forward check uses.
    """

    a: np.ndarray
    std: np.ndarray | None
    raw: list
    notes: list = field(default_factory=list)


def prepare(x, freq_hz, rig: Rig | None = None) -> Inputs:
    """Any accepted input as `Inputs` on ``freq_hz`` (see `satmd.inverse.InverseModel.as_complex`).

    Parameters
    ----------
    x : FRFData (channels a1, a2; any grid), a list of them, an `InverseDataset`,
        a `satmd.physics.Response` or dict with "a1", "a2", a complex array (2, F)
        or (n, 2, F), or raw real features (4F,) or (n, 4F), the arrays on ``freq_hz``
    freq_hz : the model's grid
    rig : the model's fixed mechanical parameters (for the model-based fill)

    Returns
    -------
    Inputs
    """
    from ..io import FRFData

    grid = np.asarray(freq_hz, float)
    if isinstance(x, InverseDataset):
        x = {"a1": x.a1, "a2": x.a2, "freq_hz": x.freq_hz}
    if hasattr(x, "a1") and hasattr(x, "freq_hz") and not isinstance(x, FRFData):  # a physics Response
        x = {"a1": np.asarray(x.a1), "a2": np.asarray(x.a2), "freq_hz": x.freq_hz}
    if isinstance(x, dict) and "freq_hz" in x and np.asarray(x["a1"]).ndim == 1:
        x = FRFData(np.asarray(x["freq_hz"], float), {"a1": x["a1"], "a2": x["a2"]})
    if isinstance(x, FRFData):
        x = [x]
    if isinstance(x, (list, tuple)) and x and all(isinstance(d, FRFData) for d in x):
        return _from_frfs(x, grid, rig)
    if isinstance(x, dict):
        if "freq_hz" in x:
            _check_same_grid(x["freq_hz"], grid, "the input")
        a = np.stack([np.asarray(x["a1"]), np.asarray(x["a2"])], axis=-2)
    else:
        arr = np.asarray(x)
        if np.iscomplexobj(arr):
            if arr.ndim < 2 or arr.shape[-2] != 2:
                raise DataError(f"complex input must have shape (2, F) or (n, 2, F), got {arr.shape}")
            a = arr
        else:
            arr = np.asarray(arr, float)
            if arr.shape[-1] != 4 * grid.size:
                raise DataError(f"real input must be features of length {4 * grid.size} "
                                f"([Re A1, Re A2, Im A1, Im A2]), got shape {arr.shape}")
            a = features_to_complex(arr.reshape(-1, 4 * grid.size))
    a = a.reshape(-1, 2, a.shape[-1]).astype(complex)
    if a.shape[-1] != grid.size:
        raise DataError(f"input has {a.shape[-1]} frequencies; the model uses {grid.size} "
                        f"({grid[0]:g}..{grid[-1]:g} Hz): pass FRFData to have it brought onto the grid")
    if not np.all(np.isfinite(a)):
        raise DataError("input contains NaN or infinite values")
    return Inputs(a, None, [(grid, ai, None) for ai in a])


def _check_same_grid(f, grid, what):
    f = np.asarray(f, float)
    if f.shape != grid.shape or not np.allclose(f, grid, rtol=1e-9, atol=1e-9):
        raise DataError(f"{what} has {f.size} frequencies; the model uses {grid.size} points "
                        f"{grid[0]:g}..{grid[-1]:g} Hz: pass FRFData to have it brought onto the grid")


def _from_frfs(datas, grid, rig):
    a, s, raw, notes = [], [], [], []
    for i, d in enumerate(datas):
        missing = [c for c in ACCEL_CHANNELS if c not in d.channels]
        if missing:
            raise DataError(f"the inverse model needs channels a1 and a2; the data lack {', '.join(missing)}")
        ai = np.stack([d["a1"], d["a2"]])
        si = np.stack([d.std["a1"], d.std["a2"]]) if all(c in d.std for c in ACCEL_CHANNELS) else None
        on_grid = d.freq_hz.shape == grid.shape and np.allclose(d.freq_hz, grid, rtol=1e-9, atol=1e-9)
        if not on_grid:
            label = d.meta.get("source") or (f"FRF {i + 1}" if len(datas) > 1 else "input")
            ai, si, note = to_grid(d.freq_hz, ai, si, grid, rig, label)
            notes += note
        keep = (d.freq_hz >= grid[0] * (1 - 1e-9)) & (d.freq_hz <= grid[-1] * (1 + 1e-9))
        raw.append((d.freq_hz[keep], np.stack([d["a1"][keep], d["a2"][keep]]),
                    None if si is None else np.stack([d.std["a1"][keep], d.std["a2"][keep]])))
        a.append(ai)
        s.append(si)
    std = np.stack(s) if all(v is not None for v in s) else None
    return Inputs(np.stack(a), std, raw, notes)


def to_grid(freq, a, std, grid, rig=None, label="input"):
    """One FRF brought onto ``grid``: spline inside the data's span, the least-squares forward model outside it.

    Parameters
    ----------
    freq : (k,) increasing frequencies of the data [Hz]
    a : (2, k) complex [A1, A2]
    std : (2, k) noise std or None
    grid : (F,) the model's grid
    rig : fixed mechanical parameters for the model-based fill (default: the paper's rig)
    label : how messages name the data (a file name)

    Returns
    -------
    (ndarray, ndarray or None, list of str) : (2, F) values, (2, F) std, one-line warnings for the caller.
    """
    from scipy.interpolate import CubicSpline

    freq = np.asarray(freq, float)
    inside = (grid >= freq[0] * (1 - 1e-9)) & (grid <= freq[-1] * (1 + 1e-9))
    near = (freq >= grid[0] - 3 * np.diff(grid).max()) & (freq <= grid[-1] + 3 * np.diff(grid).max())
    if inside.sum() < 2 or near.sum() < 4:
        raise DataError(f"{label}: {freq.size} points {freq[0]:g}..{freq[-1]:g} Hz hardly overlap the model's "
                        f"grid {grid[0]:g}..{grid[-1]:g} Hz: at least 4 measured points near it are needed")
    f, z = freq[near], a[:, near]
    out = np.empty((2, grid.size), complex)
    out[:, inside] = CubicSpline(f, z, axis=-1)(grid[inside])
    out_std = None
    if std is not None:
        out_std = np.stack([np.interp(grid, f, s[near]) for s in std])
    notes = []
    spacing = np.median(np.diff(f))
    if spacing > 1.01 * np.median(np.diff(grid)):
        notes.append(f"{label}: points every {spacing:.3g} Hz, coarser than the model's grid "
                     f"({np.median(np.diff(grid)):.3g} Hz): values between them are interpolated")
    if not inside.all():
        R, L = _least_squares_RL(f, z, None if std is None else std[:, near], rig)
        model = frf(grid[~inside], (rig or Rig()).replace(R=R, L=L), outputs=ACCEL_CHANNELS)
        out[:, ~inside] = np.stack([model.a1, model.a2])
        notes.append(f"{label}: data cover {freq[0]:g}..{freq[-1]:g} Hz, not the model's {grid[0]:g}..{grid[-1]:g} Hz: "
                     f"{int((~inside).sum())} of {grid.size} grid points were filled from the forward model fitted "
                     f"to the measured points (R {R:.4g} Ω, L {L:.4g} H); the prediction leans on that fit")
    return out, out_std, notes


def _least_squares_RL(freq, a, std, rig):
    """R, L of the rig fitted to the measured points (the model-based fill)."""
    from ..identification import identify
    from ..io import FRFData

    data = FRFData(freq, {"a1": a[0], "a2": a[1]}, {} if std is None else {"a1": std[0], "a2": std[1]})
    with warnings.catch_warnings():  # the forward check reports on the fit's quality, once
        warnings.simplefilter("ignore")
        fit = identify(data, rig=rig, free=("R", "L"), global_search=True, warn=False)
    return float(fit.values["R"]), float(fit.values["L"])


def forward_check(inputs: Inputs, R, L, rig: Rig | None, residual_ref: float, noise: float) -> dict:
    """The forward residual of each prediction against what the model's accuracy and the noise explain.

    Parameters
    ----------
    inputs : the prepared inputs (their measured points are used)
    R, L : predictions, arrays (n,)
    rig : fixed mechanical parameters of the model
    residual_ref : the net's own relative FRF error on in-distribution data
    noise : relative noise assumed where the data carry no std (the training level)

    Returns
    -------
    dict of arrays (n,): ``residual`` (||A(R̂, L̂) - A|| / ||A||), ``residual_expected``
    (sqrt(residual_ref² + noise share)), ``residual_ratio`` and ``explained``
    (ratio <= `CHECK_LIMIT`).
    """
    rig = Rig() if rig is None else rig
    res, exp = [], []
    for (f, a, s), r, l in zip(inputs.raw, np.asarray(R, float), np.asarray(L, float)):
        model = frf(f, rig.replace(R=r, L=max(l, 1e-9)), outputs=ACCEL_CHANNELS)
        assert model.a1 is not None and model.a2 is not None  # both were asked for
        norm2 = float(np.sum(np.abs(a) ** 2))
        res.append(np.linalg.norm(np.stack([model.a1, model.a2]) - a) / np.sqrt(norm2))
        sd = np.abs(a) * noise if s is None else s
        exp.append(np.sqrt(residual_ref ** 2 + 2 * float(np.sum(sd ** 2)) / norm2))  # Re and Im each carry σ²
    residual, expected = np.array(res), np.array(exp)
    ratio = residual / expected
    return {"residual": residual, "residual_expected": expected, "residual_ratio": ratio,
            "explained": ratio <= CHECK_LIMIT}


def check_message(check: dict, R, L, rig: Rig | None) -> str | None:
    """One line when some predictions do not explain their data, else None.

    Parameters
    ----------
    check : the result of `forward_check`
    R, L : the predictions, arrays (n,)
    rig : the model's fixed mechanical parameters (named in the message)

    Returns
    -------
    str or None
    """
    bad = np.flatnonzero(~check["explained"])
    if bad.size == 0:
        return None
    rig = Rig() if rig is None else rig
    k = int(bad[np.argmax(check["residual_ratio"][bad])])
    n = check["explained"].size
    which = "the prediction" if n == 1 else f"{bad.size} of {n} predictions (worst: FRF {k + 1})"
    return (f"{which} R {R[k]:.4g} Ω, L {L[k]:.4g} H does not explain the data: forward residual "
            f"{check['residual'][k]:.3g} (relative), {check['residual_ratio'][k]:.1f}x the "
            f"{check['residual_expected'][k]:.2g} that the model's accuracy and the noise explain; the data may come "
            f"from a rig unlike the training rig (m2 {float(rig.m2):g} kg, kp {float(rig.kp):g} N/m) or hold "
            f"effects the model lacks: do not trust R, L")


MAX_STD_SCALE = 1e3  # a calibration factor beyond this: the ensemble had no spread of its own to calibrate


def trust_check(out: dict, bounds: dict, no_std: str | None = None) -> str | None:
    """Keep every std finite and >= 0 and withdraw ``explained`` where the std says nothing; returns a note or None.

    Parameters
    ----------
    out : dict
        A prediction with arrays ``R_std``, ``L_std`` and (after `forward_check`)
        ``explained``; updated in place.
    bounds : dict
        ``{"R": (lo, hi), "L": (lo, hi)}`` of the training box.
    no_std : str or None
        Why the model gives no std at all (`NetStrategy.no_std`: a one-member
        ensemble, or a calibration factor beyond `MAX_STD_SCALE`, both a
        spread the ensemble does not have), or None. When given, ``R_std`` and
        ``L_std`` are NaN (no std, rather than 0 or 1e10, numbers that mean
        nothing) and ``explained`` is false: nothing says how far to trust R, L.

    Returns
    -------
    str or None
        Why some predictions are not to be trusted: no std (``no_std``), a std
        that is not finite (set to the box width), or one as wide as the whole box.
    """
    notes, distrust = [], None
    if no_std:
        for name in ("R", "L"):
            out[f"{name}_std"] = np.full(np.shape(out[name]), np.nan)
        notes.append(f"no std: {no_std}")
        distrust = np.ones(np.shape(out["R"]), dtype=bool)
    for name in () if no_std else ("R", "L"):
        span = float(bounds[name][1] - bounds[name][0])
        s = np.asarray(out[f"{name}_std"], dtype=float)
        bad = ~np.isfinite(s) | (s < 0)
        if bad.any():
            notes.append(f"{name}_std not finite: set to the box width {span:g}")
            s = np.where(bad, span, s)
        out[f"{name}_std"] = s
        wide = bad | (s >= span)
        if wide.any() and not bad.any():
            notes.append(f"{name}_std {float(np.max(s)):.3g} spans the whole training box ({span:g})")
        distrust = wide if distrust is None else distrust | wide
    assert distrust is not None  # set for R and L
    residual = np.asarray(out.get("residual", 0.0), dtype=float)
    if not np.all(np.isfinite(residual)):
        notes.append("the forward check is not finite (the model's rig cannot be computed)")
        distrust = distrust | ~np.isfinite(residual)
    if "explained" in out:
        out["explained"] = np.asarray(out["explained"]) & ~distrust
    return "; ".join(notes) + ": do not trust R, L" if notes else None

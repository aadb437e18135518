"""The few things use case III needs from an inverse model, in one place.

The explain package works with any object that follows the contract of
`satmd.inverse.InverseModel` (documented there):

- ``model.freq_hz`` (F,), ``model.bounds`` {"R": (lo, hi), "L": (lo, hi)};
- ``model.scaler_`` with ``mean`` and ``scale`` (4F,): the per-feature
  standardisation between raw features and network inputs;
- ``model.networks_``: torch modules mapping scaled float32 features (n, 4F)
  to normalised outputs (n, 2) in [0, 1];
- ``model.latent(x)``: (n, 64) activations of the penultimate layer;
- ``model.features(x)``: scaled network inputs for raw inputs.

Raw features are ``[Re A1, Re A2, Im A1, Im A2]`` over the grid, the ordering
of `satmd.physics.torch.features` (SPEC §1).
"""
from __future__ import annotations

import numpy as np

from ..errors import DataError, SatmdError

NET_KINDS = ("physics", "supervised", "hybrid")


def torch_module():
    try:
        import torch
    except ImportError as exc:  # pragma: no cover - exercised only without torch
        raise ImportError("satmd.explain's neural analyses need torch: pip install 'satmd[nn]'") from exc
    return torch


def check_net_model(model):
    """Refuse models without a network (the ``optimization`` kind) in one line."""
    kind = getattr(model, "kind", None)
    if kind not in NET_KINDS or not getattr(model, "networks_", None):
        raise SatmdError(f"use case III needs a trained network (kind physics, supervised or hybrid); "
                         f"this model is kind {kind!r}")


def complex_to_raw(a: np.ndarray) -> np.ndarray:
    """(..., 2, F) complex [A1, A2] -> (..., 4F) raw features [Re A1, Re A2, Im A1, Im A2]."""
    a = np.asarray(a)
    z = a.reshape(a.shape[:-2] + (-1,))
    return np.concatenate([z.real, z.imag], axis=-1)


def raw_to_complex(x: np.ndarray) -> np.ndarray:
    """Inverse of `complex_to_raw`: (..., 4F) -> (..., 2, F)."""
    x = np.asarray(x, float)
    half = x.shape[-1] // 2
    z = x[..., :half] + 1j * x[..., half:]
    return z.reshape(x.shape[:-1] + (2, half // 2))


def as_complex(x, n_freq: int | None = None) -> np.ndarray:
    """Accelerations (n, 2, F) complex from FRFData (or a list), anything with
    ``a1``/``a2`` (dataset, Response, dict), a complex (n, 2, F) array or raw
    real features (n, 4F)."""
    from ..io import FRFData

    if isinstance(x, FRFData):
        x = [x]
    if isinstance(x, (list, tuple)) and x and all(isinstance(d, FRFData) for d in x):
        a = np.stack([np.stack([d["a1"], d["a2"]]) for d in x])
    elif isinstance(x, dict) or hasattr(x, "a1"):
        get = (lambda c: x[c]) if isinstance(x, dict) else (lambda c: getattr(x, c))
        a = np.stack([np.asarray(get("a1")), np.asarray(get("a2"))], axis=-2)
    else:
        arr = np.asarray(x)
        if np.iscomplexobj(arr):
            if arr.ndim < 2 or arr.shape[-2] != 2:
                raise DataError(f"complex input must have shape (2, F) or (n, 2, F), got {arr.shape}")
            a = arr
        else:
            if arr.shape[-1] % 4:
                raise DataError(f"real input must be raw features of length 4F, got shape {arr.shape}")
            a = raw_to_complex(arr)
    a = np.asarray(a, complex).reshape(-1, 2, np.shape(a)[-1])
    if n_freq is not None and a.shape[-1] != n_freq:
        raise DataError(f"input has {a.shape[-1]} frequencies; the model uses {n_freq}")
    if not np.all(np.isfinite(a)):
        raise DataError("input contains NaN or infinite values")
    return a


def raw_features(model, x) -> np.ndarray:
    """Raw features (n, 4F) float64 of ``x`` on the model's grid."""
    return complex_to_raw(as_complex(x, np.size(model.freq_hz)))


def normalised_outputs_raw(model, X):
    """Ensemble-mean normalised outputs (n, 2), differentiable w.r.t. the raw features ``X``.

    Uses `satmd.inverse.normalised_outputs(..., raw=True)` for an
    InverseModel; any other object following the contract is evaluated the
    same way: standardise with ``scaler_``, average ``networks_``.
    """
    try:
        from ..inverse import InverseModel, normalised_outputs
    except ImportError:
        InverseModel = None
    if InverseModel is not None and isinstance(model, InverseModel):
        return normalised_outputs(model, X, raw=True)
    torch = torch_module()
    mean = torch.as_tensor(np.asarray(model.scaler_.mean), dtype=X.dtype)
    scale = torch.as_tensor(np.asarray(model.scaler_.scale), dtype=X.dtype)
    Xs = ((X - mean) / scale).float()
    return torch.stack([net(Xs) for net in model.networks_]).mean(dim=0)


def latent(model, raw: np.ndarray) -> np.ndarray:
    """(n, 64) penultimate activations for raw features (n, 4F)."""
    return np.asarray(model.latent(np.asarray(raw, float)), float)


def bounds_span(model) -> np.ndarray:
    b = model.bounds
    return np.array([b["R"][1] - b["R"][0], b["L"][1] - b["L"][0]], float)


def model_rig(model):
    """The fixed mechanical parameters of the model (default: the paper's rig)."""
    from ..physics import Rig

    rig = getattr(model, "rig", None)
    return rig if rig is not None else Rig()

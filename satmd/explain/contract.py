"""What use case III needs from an inverse model, written down once (`ExplainableModel`).

`satmd.inverse.InverseModel` follows this contract; so may any other object
(the tests use a small stand-in). The feature layout, ``[Re A1, Re A2, Im A1,
Im A2]`` over the grid (SPEC §1), is the inverse package's
(`satmd.inverse.dataset.complex_to_features`): explain does not redefine it.
"""
from __future__ import annotations

from typing import Any, Protocol, Sequence, runtime_checkable

import numpy as np

from ..errors import SatmdError
from ..inverse.dataset import complex_to_features


@runtime_checkable
class ExplainableModel(Protocol):
    """The contract `satmd.explain` relies on.

    Attributes
    ----------
    freq_hz : (F,) frequency grid [Hz] of the inputs.
    bounds : {"R": (lo, hi), "L": (lo, hi)}: output ranges (paper eq. 20).
    scaler_ : ``mean`` and ``scale`` (4F,): the standardisation from raw features to network inputs.
    networks_ : torch modules mapping scaled float32 features (n, 4F) to normalised outputs (n, 2) in [0, 1].
    rig : optional; the fixed mechanical parameters (default: the paper's rig).
    """

    freq_hz: np.ndarray
    bounds: dict
    scaler_: Any
    networks_: Sequence

    def as_complex(self, x) -> tuple:
        """Inputs as (n, 2, F) complex [A1, A2] on the model's grid, and their std (or None)."""

    def features(self, x) -> np.ndarray:
        """Scaled network inputs (n, 4F) for any input `as_complex` accepts."""

    def latent(self, x) -> np.ndarray:
        """(n, 64) activations of the penultimate layer."""


def torch_module():
    """torch, or one line naming the extra to install."""
    try:
        import torch
    except ImportError as exc:  # pragma: no cover - exercised only without torch
        raise ImportError("satmd.explain's neural analyses need torch: pip install 'satmd[nn]'") from exc
    return torch


def check_net_model(model):
    """Refuse, in one line, a model without a trained network (the ``optimization`` kind, or unfitted).

    Parameters
    ----------
    model : the model to check.

    Returns
    -------
    None
    """
    if not isinstance(model, ExplainableModel) or not getattr(model, "networks_", None):
        raise SatmdError(f"use case III needs a model with a trained network; this one "
                         f"(kind {getattr(model, 'kind', None)!r}) has none")


def raw_features(model, x) -> np.ndarray:
    """Raw features (n, 4F) float64 of ``x`` on the model's grid."""
    a, _ = model.as_complex(x)
    return complex_to_features(a)


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
    """Output ranges (R_max - R_min, L_max - L_min)."""
    b = model.bounds
    return np.array([b["R"][1] - b["R"][0], b["L"][1] - b["L"][0]], float)


def model_rig(model):
    """The fixed mechanical parameters of the model (default: the paper's rig)."""
    from ..physics import Rig

    rig = getattr(model, "rig", None)
    return rig if rig is not None else Rig()

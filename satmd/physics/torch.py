"""Differentiable torch twin of the forward model.

It runs the very same equations as the NumPy solver (`model.terms` and
`model.solve` are written with plain arithmetic), on torch tensors, in
complex128 or complex64, on CPU or GPU, and is differentiable in every rig
and effect parameter.

>>> import torch
>>> from satmd.physics import Rig, PAPER_GRID_HZ
>>> from satmd.physics.torch import frf
>>> R = torch.tensor(22.0, dtype=torch.float64, requires_grad=True)
>>> out = frf(PAPER_GRID_HZ, Rig(R=R))
>>> out["a1"].abs().sum().backward()
"""
from __future__ import annotations

import os
import warnings
from typing import Sequence

from ..conventions import ACCEL_CHANNELS
from ..errors import DataError

try:
    import torch
except ImportError as exc:  # pragma: no cover - exercised only without torch
    raise ImportError("satmd.physics.torch needs torch: pip install 'satmd[nn]'") from exc

from .effects import Effect
from .model import CHANNELS, solve, terms
from .rig import Rig

_REAL = {torch.complex128: torch.float64, torch.complex64: torch.float32}


def real_dtype(dtype: torch.dtype) -> torch.dtype:
    try:
        return _REAL[dtype]
    except KeyError:
        raise DataError(f"dtype must be torch.complex128 or torch.complex64, got {dtype}") from None


def _leaf(x, real, device):
    """A parameter as a tensor with a trailing frequency axis for broadcasting."""
    t = x if isinstance(x, torch.Tensor) else torch.as_tensor(x, dtype=real, device=device)
    t = t.to(dtype=real, device=device)
    return t.unsqueeze(-1) if t.ndim > 0 else t


def frf(
    freq_hz,
    rig: Rig | None = None,
    effects: Sequence[Effect] = (),
    dtype: torch.dtype = torch.complex128,
    device=None,
    outputs: Sequence[str] = CHANNELS,
    compiled: bool | None = None,
) -> dict:
    """FRFs as complex tensors of shape (*batch, n_freq), keyed by channel.

    Rig and effect parameters may be Python numbers, arrays or tensors
    (with ``requires_grad``); batched tensors broadcast like the NumPy model.

    ``compiled`` runs the closed form through `torch.compile`, which fuses its
    elementwise operations instead of launching one kernel each. None (the
    default) compiles on CUDA devices only and only when the environment sets
    ``SATMD_TORCH_COMPILE=1`` (opt-in: not yet measured on a GPU); when
    compiling fails the eager path (the reference) runs instead, with one warning.
    """
    rig = Rig() if rig is None else rig
    real = real_dtype(dtype)
    freq = freq_hz if isinstance(freq_hz, torch.Tensor) else torch.as_tensor(freq_hz, dtype=real, device=device)
    omega = 2.0 * torch.pi * freq.to(dtype=real, device=device)
    rig_t = Rig(**{n: _leaf(getattr(rig, n), real, device) for n in Rig.names()})
    effs_t = [eff.replace(**{p: _leaf(v, real, device) for p, v in eff.params.items()}) for eff in effects]
    if compiled is None:
        # opt-in until measured on a GPU: inductor cannot generate code for complex ops and may be slower
        compiled = omega.device.type == "cuda" and os.environ.get("SATMD_TORCH_COMPILE", "0") == "1"
    values = _compiled_closed_form(omega, rig_t, effs_t) if compiled else _closed_form(omega, rig_t, effs_t)
    unknown = [o for o in outputs if o not in CHANNELS]
    if unknown:
        raise DataError(f"unknown output channel(s) {unknown}")
    return {ch: values[ch].to(dtype) for ch in outputs}


def _closed_form(omega, rig, effects):
    return solve(terms(omega, rig, effects))


_COMPILED: dict = {}  # "fn": the compiled closed form, or "failed": why compiling did not work


def _compiled_closed_form(omega, rig, effects):
    if "failed" not in _COMPILED:
        try:
            fn = _COMPILED.setdefault("fn", torch.compile(_closed_form, dynamic=True))
            return fn(omega, rig, effects)
        except Exception as exc:  # noqa: BLE001 - any compiler failure: the eager path gives the same numbers
            _COMPILED["failed"] = f"{type(exc).__name__}: {exc}"
            warnings.warn(f"torch.compile of the twin failed, running it eagerly ({_COMPILED['failed'][:200]})",
                          RuntimeWarning, stacklevel=3)
    return _closed_form(omega, rig, effects)


def features(out: dict, channels: Sequence[str] = ACCEL_CHANNELS) -> torch.Tensor:
    """Real network features [Re(channels) flattened, Im(channels) flattened] (SPEC §1)."""
    z = torch.cat([out[c] for c in channels], dim=-1)
    return torch.cat([z.real, z.imag], dim=-1)

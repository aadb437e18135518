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

from typing import Sequence

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
        raise ValueError(f"dtype must be torch.complex128 or torch.complex64, got {dtype}") from None


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
) -> dict:
    """FRFs as complex tensors of shape (*batch, n_freq), keyed by channel.

    Rig and effect parameters may be Python numbers, arrays or tensors
    (with ``requires_grad``); batched tensors broadcast like the NumPy model.
    """
    rig = Rig() if rig is None else rig
    real = real_dtype(dtype)
    freq = freq_hz if isinstance(freq_hz, torch.Tensor) else torch.as_tensor(freq_hz, dtype=real, device=device)
    omega = 2.0 * torch.pi * freq.to(dtype=real, device=device)
    rig_t = Rig(**{n: _leaf(getattr(rig, n), real, device) for n in Rig.names()})
    effs_t = [eff.replace(**{p: _leaf(v, real, device) for p, v in eff.params.items()}) for eff in effects]
    values = solve(terms(omega, rig_t, effs_t))
    unknown = [o for o in outputs if o not in CHANNELS]
    if unknown:
        raise ValueError(f"unknown output channel(s) {unknown}")
    return {ch: values[ch].to(dtype) for ch in outputs}


def features(out: dict, channels: Sequence[str] = ("a1", "a2")) -> torch.Tensor:
    """Real network features [Re(channels) flattened, Im(channels) flattened] (SPEC §1)."""
    z = torch.cat([out[c] for c in channels], dim=-1)
    return torch.cat([z.real, z.imag], dim=-1)

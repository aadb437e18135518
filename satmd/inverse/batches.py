"""The training data on the device: input standardisation (`Scaler`) and one partition's tensors with its
epoch order (`Batches`), shared by `satmd.inverse.training` (which builds them) and `satmd.inverse.steps`
(which steps through them)."""
from __future__ import annotations

import math

import numpy as np
import torch

from .dataset import InverseDataset
from .objective import real_of


class Scaler:
    """Per-feature standardisation fitted on training features (stored in the model's metadata)."""

    def __init__(self, mean: np.ndarray, scale: np.ndarray):
        self.mean = np.asarray(mean, np.float64)
        self.scale = np.asarray(scale, np.float64)

    @classmethod
    def fit(cls, x: np.ndarray) -> "Scaler":
        x = np.asarray(x, np.float64)
        scale = x.std(axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        return cls(x.mean(axis=0), scale)

    def transform(self, x: np.ndarray) -> np.ndarray:
        return ((np.asarray(x, np.float64) - self.mean) / self.scale).astype(np.float32)

    def to_dict(self):
        return {"mean": self.mean.tolist(), "scale": self.scale.tolist()}

    @classmethod
    def from_dict(cls, d):
        return cls(np.array(d["mean"], float), np.array(d["scale"], float))


class Batches:
    """Tensors of one partition, resident on the training device."""

    def __init__(self, ds: InverseDataset, scaler: Scaler, bounds, device, dtype, members=None):
        self.n = len(ds)
        # members: per ensemble member, the indices of the samples it trains on (None: every member, every sample)
        self.members = None if members is None else [
            torch.as_tensor(np.flatnonzero(m), device=device) for m in np.asarray(members, bool)]
        self.n_epoch = self.n if self.members is None else max(len(m) for m in self.members)
        self.x = torch.as_tensor(scaler.transform(ds.features()), device=device)
        # per-feature noise scale in standardised units: |A| / feature scale
        mag = np.abs(np.concatenate([ds.a1, ds.a2], axis=-1))
        self.noise_unit = torch.as_tensor(np.concatenate([mag, mag], axis=-1) / scaler.scale, dtype=torch.float32,
                                          device=device)
        self.y = torch.as_tensor(ds.labels_normalised(bounds), dtype=torch.float32, device=device)
        target = np.stack([ds.a1, ds.a2], axis=1)
        self.target = torch.as_tensor(target, dtype=dtype, device=device)
        self.s_n = torch.as_tensor(np.abs(target).max(axis=(1, 2)), dtype=real_of(dtype), device=device)

    def epoch_order(self, gen) -> torch.Tensor:
        """One epoch's sample order: (n,) shared by all members, or (E, n_epoch), each member its own samples
        (a member with fewer samples than the largest starts its order again to fill the epoch)."""
        if self.members is None:
            return torch.randperm(self.n, generator=gen).to(self.x.device)
        rows = []
        for m in self.members:
            p = m[torch.randperm(len(m), generator=gen).to(m.device)]
            rows.append(p.repeat(math.ceil(self.n_epoch / len(m)))[:self.n_epoch])
        return torch.stack(rows)

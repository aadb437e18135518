"""The resolved settings of one training (`satmd.inverse.training.train_ensemble` and the phases of
`satmd.inverse.steps` read them; `satmd.inverse.model.InverseModel.train_config` builds them)."""
from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class TrainConfig:
    """Resolved training settings. Build it with `InverseModel.train_config` (the defaults live there)."""

    objective: str
    epochs: int
    warm_start_epochs: int
    batch_size: int
    lr: float
    physics_lr: float
    lr_final: float
    n_members: int
    noise: float
    seed: int
    device: str | None
    precondition: bool
    threads: int | None
    twin_dtype: str
    jacobian: str = "mobius"

    def to_dict(self):
        return asdict(self)

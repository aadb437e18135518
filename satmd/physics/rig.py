"""The rig: one frozen parameter object for the SATMD model (SPEC §2-3)."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from ..errors import DataError  # a ValueError: user-facing, one line

# Units and one-line roles, used in reports and CLI help.
PARAMETER_INFO = {
    "m1": ("kg", "primary mass"),
    "k1": ("N/m", "primary stiffness"),
    "c1": ("N s/m", "primary damping"),
    "cp": ("N s/m", "piezo damping"),
    "e": ("N/C·F", "electromechanical coupling"),
    "Cp": ("F", "piezo capacitance"),
    "m2": ("kg", "absorber mass"),
    "kp": ("N/m", "piezo stiffness"),
    "R": ("Ω", "shunt resistance"),
    "L": ("H", "shunt inductance"),
    "F0": ("N", "force amplitude"),
}

# Parameters that must be strictly positive / may be zero.
_POSITIVE = ("m1", "k1", "Cp", "m2", "kp", "F0")
_NON_NEGATIVE = ("c1", "cp", "R", "L", "e")


@dataclass(frozen=True)
class Rig:
    """Physical parameters of the SATMD (SI units).

    Every field may be a scalar or an array; arrays broadcast against each
    other, so ``Rig(R=np.linspace(5, 100, 10**5))`` is a batch of 10**5 rigs.
    Defaults are the paper's rig (SPEC §3).
    """

    m1: Any = 0.85
    k1: Any = 194e3
    c1: Any = 10.0
    cp: Any = 4.0
    e: Any = 0.65
    Cp: Any = 27e-6
    m2: Any = 0.518
    kp: Any = 111e3
    R: Any = 22.0
    L: Any = 0.064
    F0: Any = 1.0

    def replace(self, **changes) -> "Rig":
        unknown = set(changes) - set(self.names())
        if unknown:
            raise DataError(f"unknown rig parameter(s) {sorted(unknown)}; known: {', '.join(self.names())}")
        return dataclasses.replace(self, **changes)

    @staticmethod
    def names() -> tuple[str, ...]:
        return tuple(f.name for f in fields(Rig))

    def as_dict(self) -> dict:
        return {n: getattr(self, n) for n in self.names()}

    @property
    def batch_shape(self) -> tuple[int, ...]:
        return np.broadcast_shapes(*(np.shape(v) for v in self.as_dict().values()))

    def validate(self) -> "Rig":
        """Raise ValueError naming the first impossible parameter."""
        for name in _POSITIVE + _NON_NEGATIVE:
            value = getattr(self, name)
            if _is_traced(value):
                continue
            arr = np.asarray(value, dtype=float)
            if not np.all(np.isfinite(arr)):
                raise DataError(f"rig parameter {name} is not finite")
            if name in _POSITIVE and np.any(arr <= 0):
                raise DataError(f"rig parameter {name} must be > 0 (got {arr.min():g})")
            if name in _NON_NEGATIVE and np.any(arr < 0):
                raise DataError(f"rig parameter {name} must be >= 0 (got {arr.min():g})")
        return self


def _is_traced(value) -> bool:
    """True for torch tensors and forward-mode duals (validated elsewhere)."""
    return not isinstance(value, (int, float, np.ndarray, np.generic, list, tuple))


PAPER_GRID_HZ = np.linspace(40.0, 130.0, 60)

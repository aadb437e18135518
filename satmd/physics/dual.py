"""Sparse forward-mode duals for the model's intermediate quantities.

The entries of Z are written once, with ordinary arithmetic. Called with a
``Dual`` in place of a parameter, the same code returns each entry together
with its exact derivatives, so adding an effect never means writing its
derivative by hand. Only the cheap intermediate quantities go through duals;
the batched solve propagates tangents in closed form (see model.py).
"""
from __future__ import annotations

import numpy as np


class Dual:
    """A value with derivatives ``tangents[name] = d value / d name``."""

    __slots__ = ("value", "tangents")
    __array_priority__ = 1000  # make numpy defer to our reflected operators

    def __init__(self, value, tangents=None):
        self.value = value
        self.tangents = tangents or {}

    @staticmethod
    def variable(value, name: str) -> "Dual":
        return Dual(value, {name: 1.0})

    def __add__(self, other):
        if isinstance(other, Dual):
            t = dict(self.tangents)
            for k, v in other.tangents.items():
                t[k] = t[k] + v if k in t else v
            return Dual(self.value + other.value, t)
        return Dual(self.value + other, self.tangents)

    __radd__ = __add__

    def __neg__(self):
        return Dual(-self.value, {k: -v for k, v in self.tangents.items()})

    def __sub__(self, other):
        return self + (-other)

    def __rsub__(self, other):
        return (-self) + other

    def __mul__(self, other):
        if isinstance(other, Dual):
            t = {k: v * other.value for k, v in self.tangents.items()}
            for k, v in other.tangents.items():
                t[k] = t[k] + self.value * v if k in t else self.value * v
            return Dual(self.value * other.value, t)
        return Dual(self.value * other, {k: v * other for k, v in self.tangents.items()})

    __rmul__ = __mul__

    def __truediv__(self, other):
        if isinstance(other, Dual):
            return self * other.reciprocal()
        return Dual(self.value / other, {k: v / other for k, v in self.tangents.items()})

    def __rtruediv__(self, other):
        return self.reciprocal() * other

    def reciprocal(self):
        inv = 1.0 / self.value
        d = -inv * inv
        return Dual(inv, {k: v * d for k, v in self.tangents.items()})

    def __pow__(self, n):
        if n == 2:
            return self * self
        raise NotImplementedError("Dual supports only squaring")

    def exp(self):
        ev = np.exp(self.value)
        return Dual(ev, {k: v * ev for k, v in self.tangents.items()})

    def sqrt(self):
        sv = np.sqrt(self.value)
        return Dual(sv, {k: v * (0.5 / sv) for k, v in self.tangents.items()})


def value(x):
    return x.value if isinstance(x, Dual) else x


def tangent(x, name):
    """d x / d name, or None when x does not depend on name."""
    if isinstance(x, Dual):
        return x.tangents.get(name)
    return None


def exp(x):
    """exp for floats, arrays, torch tensors and duals alike."""
    if isinstance(x, Dual):
        return x.exp()
    if hasattr(x, "exp") and not isinstance(x, (np.ndarray, np.generic)):
        return x.exp()  # torch.Tensor
    return np.exp(x)

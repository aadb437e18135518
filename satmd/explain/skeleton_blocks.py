"""The blocks of the product skeletons (`satmd.explain.skeletons`): each knows its value,
its derivatives by its inner constants (for `satmd.explain.varpro`'s Jacobian), its
node count and how it is written.

Factors of the product: `Affine`, `Square`, `Exp` (written as powers), `Inverse`.
Terms added with weight one (no outer constant): `UnitPower` ``B^x`` and `ShiftedPower`
``(x + a)^m``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Affine:
    """``x_lead + a + Σ b_j x_j`` (``cv`` the variables with a free coefficient)."""

    lead: int
    cv: tuple = ()

    @property
    def n_params(self):
        return 1 + len(self.cv)

    @property
    def nodes(self):
        return 3 + 3 * len(self.cv)

    def value(self, p, Zt):
        """Scale-free: ``1 + w_lead x_lead + Σ w_j x_j``."""
        out = 1.0 + p[0] * Zt[self.lead]
        for w, j in zip(p[1:], self.cv):
            out = out + w * Zt[j]
        return out

    def text(self, p):
        """``(scale, text)`` with value = scale · text; the largest weight is written bare."""
        vs = (self.lead, *self.cv)
        k = int(np.argmax(np.abs(p)))
        s = float(p[k])
        if abs(s) < 1e-12:
            return 1.0, "1"
        terms = [f"x{vs[k]}", f"({1.0 / s:.10g})"] + [f"({p[i] / s:.10g})*x{v}" for i, v in enumerate(vs) if i != k]
        return s, "(" + " + ".join(terms) + ")"

    def grad(self, p, Zt):
        """Derivatives of `value` by each constant."""
        return [Zt[self.lead]] + [Zt[j] for j in self.cv]

    def offset_value(self, p, Zt):
        """Offset form: ``x_lead + p0 + Σ p_j x_j`` (inside a square)."""
        out = Zt[self.lead] + p[0]
        for b, j in zip(p[1:], self.cv):
            out = out + b * Zt[j]
        return out

    def offset_grad(self, p, Zt):
        return [np.ones_like(Zt[self.lead])] + [Zt[j] for j in self.cv]

    def offset_text(self, p):
        return "(" + " + ".join([f"x{self.lead}", f"({p[0]:.10g})"]
                                + [f"({b:.10g})*x{j}" for b, j in zip(p[1:], self.cv)]) + ")"


@dataclass(frozen=True)
class Square:
    """``A² [+ x_bare]`` (``A`` in its offset form)."""

    inner: Affine
    bare: int | None = None

    @property
    def n_params(self):
        return self.inner.n_params

    @property
    def nodes(self):
        return self.inner.nodes + 2 + (2 if self.bare is not None else 0)

    def value(self, p, Zt):
        out = self.inner.offset_value(p, Zt) ** 2
        return out if self.bare is None else out + Zt[self.bare]

    def grad(self, p, Zt):
        a = self.inner.offset_value(p, Zt)
        return [2.0 * a * g for g in self.inner.offset_grad(p, Zt)]

    def text(self, p):
        sq = f"{self.inner.offset_text(p)}**2"
        return 1.0, sq if self.bare is None else f"({sq} + x{self.bare})"


@dataclass(frozen=True)
class Exp:
    """``exp(Σ b_j x_j)``, written as the product of powers ``Π B_j^x_j`` (``B_j = e^b_j``):
    the same function, three nodes a variable (``Pow``, the base, the symbol) where the
    ``exp`` of a weighted sum pays for the ``exp``, the sum and every ``Mul``."""

    vs: tuple

    @property
    def n_params(self):
        return len(self.vs)

    @property
    def nodes(self):
        return 3 * len(self.vs)

    def value(self, p, Zt):
        return np.exp(sum(b * Zt[j] for b, j in zip(p, self.vs)))

    def grad(self, p, Zt):
        v = self.value(p, Zt)
        return [v * Zt[j] for j in self.vs]

    def text(self, p):
        return 1.0, "*".join(f"({np.exp(b):.10g})**x{j}" for b, j in zip(p, self.vs))


@dataclass(frozen=True)
class UnitPower:
    """``B^x_v`` added with weight one: a curved main effect for the three nodes of a
    linear term ``c·x_v`` (c0 absorbs its value 1 at x_v = 0; its slope there is ln B)."""

    v: int
    unit_weight = True

    @property
    def n_params(self):
        return 1

    @property
    def nodes(self):
        return 3

    def value(self, p, Zt):
        return np.exp(p[0] * Zt[self.v])

    def grad(self, p, Zt):
        return [self.value(p, Zt) * Zt[self.v]]

    def text(self, p):
        return 1.0, f"({np.exp(p[0]):.10g})**x{self.v}"


@dataclass(frozen=True)
class ShiftedPower:
    """``(x_v + a)^m`` added with weight one, five nodes: a main effect with its own
    level (``a^m`` at x_v = 0), slope and curvature. Its level can stand in for c0, so a
    skeleton with one may go without (`Skeleton.intercept`): then it costs a node more
    than the linear term and the c0 it replaces. Defined where ``x_v + a > 0``."""

    v: int
    unit_weight = True

    @property
    def n_params(self):
        return 2

    @property
    def nodes(self):
        return 5

    def value(self, p, Zt):
        return (Zt[self.v] + p[0]) ** p[1]

    def grad(self, p, Zt):
        base = Zt[self.v] + p[0]
        power = base ** p[1]
        return [p[1] * power / base, power * np.log(base)]

    def text(self, p):
        return 1.0, f"(x{self.v} + ({p[0]:.10g}))**({p[1]:.10g})"


@dataclass(frozen=True)
class Inverse:
    """``1 / B`` for an affine form or a square."""

    inner: object

    @property
    def n_params(self):
        return self.inner.n_params

    @property
    def nodes(self):
        return self.inner.nodes + 2

    def value(self, p, Zt):
        return 1.0 / self.inner.value(p, Zt)

    def grad(self, p, Zt):
        b = self.inner.value(p, Zt)
        return [-g / (b * b) for g in self.inner.grad(p, Zt)]

    def text(self, p):
        s, t = self.inner.text(p)
        return 1.0 / s, f"1/{t}"

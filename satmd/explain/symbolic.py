"""Sympy helpers for symbolic distillation: parsing, node counting, compact forms, polishing.

Counting rule (``node_count``): the number of nodes of sympy's expression
tree after sympy's automatic canonicalisation, i.e. ``len(list(
sympy.preorder_traversal(expr)))``. Every operator node (n-ary ``Add`` and
``Mul`` count once, ``Pow`` once), every symbol and every number is one
node. Subtraction is ``Add`` with a negative coefficient, division is ``Pow``
with exponent -1 and ``square`` is ``Pow`` with exponent 2. Of the algebraically
identical forms tried by `compact` (as given, expanded, common factors pulled
out, over a common denominator) the smallest count is used, for the paper's
formula exactly as for ours.
"""
from __future__ import annotations

import numpy as np

try:
    import sympy as sp
except ImportError as exc:  # pragma: no cover - exercised only without sympy
    raise ImportError("symbolic distillation needs sympy: pip install 'satmd[symbolic]'") from exc

#: The paper's distilled formula (PySR, SPEC §6), in z-scored x0..x3 = R, L, m2, kp.
PAPER_FORMULA = "1.69 + 0.02*(x3 - x1 - 2.77 - 0.28*x2)*((x1 - 3.14)**2 + x0)"
#: The paper's reported metrics for it.
PAPER_METRICS = {"mae_train": 0.0849, "mae_test": 0.0882, "r2_train": 0.874, "r2_test": 0.863}


def symbols(n: int) -> tuple:
    return sp.symbols(f"x0:{n}", real=True)


def parse(text: str, n_vars: int) -> sp.Expr:
    """An infix string in x0..x{n-1} (``^`` or ``**`` for powers) -> sympy."""
    xs = symbols(n_vars)
    local = {str(s): s for s in xs}
    local.update({f"X{i + 1}": s for i, s in enumerate(xs)})  # operon's default names
    return sp.sympify(text.replace("^", "**"), locals=local)


def node_count(expr) -> int:
    """Nodes of the sympy expression tree (see the module docstring)."""
    return sum(1 for _ in sp.preorder_traversal(sp.sympify(expr)))


def compact(expr: sp.Expr, max_nodes: int = 80) -> sp.Expr:
    """The smallest (by `node_count`) of a few algebraically identical forms.

    Expressions larger than ``max_nodes`` are returned as given (the
    rewrites get slow and never make a large polynomial small).
    """
    forms = [expr]
    if node_count(expr) > max_nodes:
        return expr
    for f in (sp.expand, sp.factor_terms, sp.together):
        try:
            forms.append(f(expr))
        except Exception:  # pragma: no cover - sympy corner cases
            pass
    return min(forms, key=node_count)


def round_floats(expr: sp.Expr, digits: int = 4) -> sp.Expr:
    """Round every float constant to ``digits`` significant digits; whole
    numbers become integers (so ``1.0*x`` reads, and counts, as ``x``)."""
    reps = {}
    for c in expr.atoms(sp.Float):
        v = float(f"{float(c):.{digits}g}")
        reps[c] = sp.Integer(int(v)) if v.is_integer() and abs(v) < 1e6 else sp.Float(v)
    return expr.xreplace(reps)


def paper_complexity() -> int:
    return node_count(compact(parse(PAPER_FORMULA, 4)))


def evaluate(expr: sp.Expr, Z: np.ndarray) -> np.ndarray:
    """Evaluate ``expr`` in x0.. on z-scored inputs Z (n, d)."""
    Z = np.asarray(Z, float)
    xs = symbols(Z.shape[1])
    fn = sp.lambdify(xs, expr, "numpy")
    with np.errstate(all="ignore"):
        out = np.asarray(fn(*Z.T), float)
    return np.broadcast_to(out, (Z.shape[0],)).astype(float)


def polish(expr: sp.Expr, Z: np.ndarray, y: np.ndarray, max_nfev: int = 200) -> sp.Expr:
    """Refit the float constants of ``expr`` by least squares on (Z, y); structure unchanged.

    Integers (exponents, the -1 of subtraction) stay fixed. Returns the input
    when the refit does not lower the squared error.
    """
    from scipy.optimize import least_squares

    consts = sorted(expr.atoms(sp.Float), key=lambda c: sp.default_sort_key(c))
    if not consts:
        return expr
    ps = sp.symbols(f"p0:{len(consts)}")
    template = expr.xreplace(dict(zip(consts, ps)))
    xs = symbols(Z.shape[1])
    fn = sp.lambdify((ps, xs), template, "numpy")
    Zt = np.asarray(Z, float).T
    y = np.asarray(y, float)

    def residual(p):
        with np.errstate(all="ignore"):
            r = np.broadcast_to(np.asarray(fn(p, Zt), float), y.shape) - y
        return np.where(np.isfinite(r), r, 1e6)

    p0 = np.array([float(c) for c in consts])
    try:
        sol = least_squares(residual, p0, max_nfev=max_nfev, method="lm" if y.size >= p0.size else "trf")
    except Exception:  # pragma: no cover - defensive: keep the unpolished expression
        return expr
    if not np.all(np.isfinite(sol.x)) or np.sum(residual(sol.x) ** 2) >= np.sum(residual(p0) ** 2):
        return expr
    return template.xreplace({p: sp.Float(v) for p, v in zip(ps, sol.x)})

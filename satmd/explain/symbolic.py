"""Sympy helpers for symbolic distillation: parsing, node counting, compact forms, polishing.

Counting rule (``node_count``): the number of nodes of sympy's expression
tree after sympy's automatic canonicalisation, i.e. ``len(list(
sympy.preorder_traversal(expr)))``. Every operator node (n-ary ``Add`` and
``Mul`` count once, ``Pow`` once), every symbol and every number is one
node. Subtraction is ``Add`` with a negative coefficient, division is ``Pow``
with exponent -1 and ``square`` is ``Pow`` with exponent 2. Of the algebraically
identical forms tried by `compact` (as given, expanded, common factors pulled
out, over a common denominator, a coefficient pulled out of a sum in a product,
``exp(a x)`` as the power ``(e^a)^x``) the smallest count is used, for the paper's
formula exactly as for ours.
"""
from __future__ import annotations

import re

import numpy as np

from ..conventions import TINY

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
    text = _LARGE_INTEGER_POWER.sub(lambda m: f"**{float(m.group(1))!r}", text.replace("^", "**"))
    return sp.sympify(text, locals=local)


#: ``** n`` with a whole n of more than three digits: parsed as a float, since sympy would
#: otherwise compute ``2**1000000000`` exactly (and `expanded_terms` treats it as no expansion).
_LARGE_INTEGER_POWER = re.compile(r"\*\*\s*(\d{4,})(?![\d.eE])")


def node_count(expr) -> int:
    """Nodes of the sympy expression tree (see the module docstring).

    Parameters
    ----------
    expr : sympy expression or a string sympy can parse.

    Returns
    -------
    int
    """
    return sum(1 for _ in sp.preorder_traversal(sp.sympify(expr)))


def binary_node_count(expr) -> int:
    """Nodes of the formula written as a binary tree, the way PySR counts
    complexity: an n-ary sum or product costs n − 1 operators, ``a − b`` and
    ``a / b`` one operator each, ``x²`` one (``square``), other powers two
    (``pow`` and the exponent), a function one. `node_count`'s n-ary rule makes
    long sums and products cheaper; both rules are reported so a comparison
    can be read either way. Count the `compact` form (sympy distributes a
    number over a sum as it parses).

    Parameters
    ----------
    expr : sympy expression or a string sympy can parse.

    Returns
    -------
    int
    """
    def count(e):
        if e.is_Atom:
            return 1
        if e.is_Add or e.is_Mul:
            args, negate = list(e.args), 0
            if e.is_Mul:  # a unit coefficient is not written; −1 alone is a negation
                units = [a for a in args if a.is_Number and float(abs(a)) == 1.0]
                args = [a for a in args if a not in units] or [sp.Integer(1)]
                negate = int(any(float(u) < 0 for u in units))
            total = len(args) - 1 + negate
            for a in args:
                if e.is_Add and a.is_Mul and a.args[0].is_Number and a.args[0] < 0:  # a − b
                    a = -a
                elif e.is_Mul and a.is_Pow and a.exp == -1:  # a / b
                    a = a.base
                total += count(a)
            return total
        if e.is_Pow:
            return count(e.base) + (1 if e.exp == 2 else 2 if e.exp == -1 else 1 + count(e.exp))
        return 1 + sum(count(a) for a in e.args)

    return count(sp.sympify(expr))


#: Most terms an expansion may produce (`expanded_terms`); past it `compact` does not expand.
#: A few dozen nodes can hold ``(x0 + x1 + x2 + 1)**40``, whose expansion has 12 341 terms
#: and grew a report to 24 GB: the bound keeps every rewrite within a few MB.
MAX_EXPANDED_TERMS = 200


def expanded_terms(expr, cap: int = MAX_EXPANDED_TERMS) -> int:
    """An upper bound on the number of terms ``sympy.expand`` gives (saturating just above ``cap``).

    Sums add, products multiply, a positive integer power ``(t1 + ... + tk)**n`` gives
    ``C(n + k - 1, k - 1)`` (the multinomial count); a function is expanded inside, so its
    argument's count is its own cost. Computed without expanding anything.
    """
    from math import comb

    def terms(e) -> int:
        if isinstance(e, sp.Add):
            return min(cap + 1, sum(terms(a) for a in e.args))
        if isinstance(e, sp.Mul):
            out = 1
            for a in e.args:
                out = min(cap + 1, out * terms(a))
            return out
        if isinstance(e, sp.Pow):
            k = terms(e.base)
            n = e.exp
            if n.is_Integer and n > 1 and k > 1:
                return cap + 1 if int(n) > cap else min(cap + 1, comb(int(n) + k - 1, k - 1))
            return max(k, terms(n))
        return max([1] + [terms(a) for a in e.args])

    return terms(sp.sympify(expr))


def _bounded_expand(expr):
    """``sympy.expand`` when it stays within `MAX_EXPANDED_TERMS`, else the expression as given."""
    return sp.expand(expr) if expanded_terms(expr) <= MAX_EXPANDED_TERMS else expr


def compact(expr: sp.Expr, max_nodes: int = 80) -> sp.Expr:
    """The smallest (by `node_count`) of a few algebraically identical forms.

    Expressions larger than ``max_nodes`` are returned as given (the
    rewrites get slow and never make a large polynomial small); nor is anything
    expanded into more than `MAX_EXPANDED_TERMS` terms (`expanded_terms`), so the
    memory `compact` needs is bounded whatever formula a search returns.
    """
    forms = [expr]
    if node_count(expr) > max_nodes:
        return expr
    for f in (_bounded_expand, sp.factor_terms, sp.together):
        try:
            forms.append(f(expr))
        except Exception:  # pragma: no cover - sympy corner cases
            pass
    forms += [_exp_as_powers(f) for f in forms]
    return _monic(min(forms, key=node_count))


def _exp_as_powers(expr: sp.Expr) -> sp.Expr:
    """``exp(a x + b y + k + f)`` -> ``e^k (e^a)^x (e^b)^y exp(f)`` wherever that is no longer:
    a power of a number costs three nodes, a weighted term inside ``exp`` three
    plus the ``exp`` and the sum."""
    reps = {}
    for e in expr.atoms(sp.exp):
        parts, rest = [], []
        for term in sp.Add.make_args(_bounded_expand(e.args[0])):
            coeff, var = term.as_coeff_Mul()
            if var == 1 or var.is_Symbol:
                parts.append(sp.Pow(sp.Float(np.exp(float(coeff))), var))
            else:
                rest.append(term)
        power = sp.Mul(*parts, sp.exp(sp.Add(*rest)))
        if parts and node_count(power) <= node_count(e):
            reps[e] = power
    return expr.xreplace(reps) if reps else expr


def _monic(expr: sp.Expr) -> sp.Expr:
    """Pull a float coefficient out of a sum inside a product, ``(a x + b) f``
    -> ``a (x + b/a) f``, wherever that shortens the tree."""
    best, size = expr, node_count(expr)
    improved = True
    while improved:
        improved = False
        for prod in sp.preorder_traversal(best):
            if not isinstance(prod, sp.Mul):
                continue
            for k, inner in enumerate(prod.args):
                if not isinstance(inner, sp.Add):
                    continue
                for term in inner.args:
                    coeff, rest = term.as_coeff_Mul()
                    if not coeff.is_Number or coeff == 0 or coeff == 1:
                        continue
                    monic = sp.Add(*(rest if t is term else t / coeff for t in inner.args))
                    others = prod.args[:k] + prod.args[k + 1:]
                    trial = best.xreplace({prod: sp.Mul(coeff, monic, *others)})
                    if node_count(trial) < size:
                        best, size, improved = trial, node_count(trial), True
                        break
                if improved:
                    break
            if improved:
                break
    return best


def round_floats(expr: sp.Expr, digits: int = 4) -> sp.Expr:
    """Round every float constant to ``digits`` significant digits; whole
    numbers become integers (so ``1.0*x`` reads, and counts, as ``x``)."""
    reps = {}
    for c in expr.atoms(sp.Float):
        v = float(f"{float(c):.{digits}g}")
        reps[c] = sp.Integer(int(v)) if v.is_integer() and abs(v) < 1e6 else sp.Float(v)
    return expr.xreplace(reps)


def paper_complexity() -> int:
    """Node count of the paper's formula in its most compact form.

    Returns
    -------
    int
    """
    return node_count(compact(parse(PAPER_FORMULA, 4)))


def evaluate(expr: sp.Expr, Z: np.ndarray) -> np.ndarray:
    """Evaluate ``expr`` in x0.. on z-scored inputs Z (n, d)."""
    Z = np.asarray(Z, float)
    xs = symbols(Z.shape[1])
    fn = sp.lambdify(xs, expr, "numpy")
    with np.errstate(all="ignore"):
        out = np.asarray(fn(*Z.T), float)
    return np.broadcast_to(out, (Z.shape[0],)).astype(float)


def _sse(expr: sp.Expr, Z: np.ndarray, y: np.ndarray) -> float:
    with np.errstate(over="ignore"):
        r = evaluate(expr, Z) - y
        sse = float(np.sum(r * r))
    return sse if np.isfinite(sse) else np.inf


def _neutral_values(expr: sp.Expr) -> list:
    """(float, value) pairs that drop it: 1 for a factor of a product, 0 for a term of a sum."""
    out = []
    for node in sp.preorder_traversal(expr):
        neutral = sp.Integer(1) if isinstance(node, sp.Mul) else sp.Integer(0) if isinstance(node, sp.Add) else None
        if neutral is not None:
            out += [(a, neutral) for a in node.args if isinstance(a, sp.Float) and (a, neutral) not in out]
    return out


def prune(expr: sp.Expr, Z: np.ndarray, y: np.ndarray, rtol: float = 1e-4, max_rows: int = 1000,
          max_nfev: int = 1000) -> sp.Expr:
    """Drop the constants the others can absorb, keeping the fit.

    A search returns trees such as ``0.999*(42.8*x3 + 100.5)*(...)**2``
    whose constants are redundant (a scale can move into a neighbouring
    factor). Each float factor of a product is tried at 1 and each float
    term of a sum at 0; the rest are refitted (`polish`) and the change is kept when
    the squared error grows by at most ``rtol`` (relative) and the tree
    shrinks. Repeats until nothing more can go. The trials use at most
    ``max_rows`` evenly spaced rows; the result is refitted on all of them.
    """
    Z = np.asarray(Z, float)
    y = np.asarray(y, float)
    rows = np.unique(np.linspace(0, y.size - 1, min(y.size, max_rows)).astype(int))
    Zs, ys = Z[rows], y[rows]
    best, best_sse = expr, _sse(expr, Zs, ys)
    if not np.isfinite(best_sse):
        return expr
    changed = True
    while changed:
        changed = False
        size = node_count(best)
        for c, value in _neutral_values(best):
            trial = best.xreplace({c: value})
            if trial.is_number or node_count(trial) >= size:
                continue
            trial = polish(trial, Zs, ys, max_nfev=max_nfev)
            sse = _sse(trial, Zs, ys)
            if sse <= best_sse * (1.0 + rtol) + TINY:
                best, best_sse, changed = trial, min(best_sse, sse), True
                break
    return expr if best is expr else polish(best, Z, y, max_nfev=max_nfev)


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
        return np.clip(np.where(np.isfinite(r), r, 1e6), -1e6, 1e6)  # a huge value counts as a failed one

    p0 = np.array([float(c) for c in consts])
    try:
        sol = least_squares(residual, p0, max_nfev=max_nfev, method="lm" if y.size >= p0.size else "trf")
    except Exception:  # pragma: no cover - defensive: keep the unpolished expression
        return expr
    if not np.all(np.isfinite(sol.x)) or np.sum(residual(sol.x) ** 2) >= np.sum(residual(p0) ** 2):
        return expr
    return template.xreplace({p: sp.Float(v) for p, v in zip(ps, sol.x)})

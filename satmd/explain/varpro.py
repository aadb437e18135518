"""Variable projection: fitting the constants of one product skeleton (`satmd.explain.skeletons`).

A skeleton ``c0 + c1·Π F + Σ c_k·E_k + Σ U`` (c0 optional) is linear in its outer constants
c and nonlinear in the inner ones p (the factors' offsets, weights and rates;
``U`` the unit-weight powers). For each p the best c is a linear least-squares
solve, so only p is searched (Golub & Pereyra 1973): Levenberg-Marquardt on
the projected residual ``r(p) = -P⊥(p) (y - U(p))``, where P⊥ projects out
``[1, columns(p)]``. Its Jacobian is Kaufman's (1975)
``J ≈ P⊥ (∂A/∂p · c + ∂U/∂p)``, built from the derivatives each block declares:
one projection per Jacobian where finite differences cost one residual per
constant. Kaufman's form drops a term that vanishes at a zero residual; it
converges like the full Jacobian (Ruhe & Wedin 1980).
"""
from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dpotrs
from scipy.optimize import least_squares

from .skeletons import Skeleton, initial

#: Columns whose scaled normal matrix has a Cholesky pivot below this (squared) are
#: treated as rank-deficient and solved by ``lstsq`` (minimum norm).
_PIVOT = 1e-12


class _Projector:
    """Least squares on ``A = [1, cols...]`` (the column of ones optional), factored once: the residual and
    Kaufman's Jacobian at one point share the factor (each made its own: a fifth of a ranking search's time).

    The normal equations of the centred, column-scaled columns (a few columns: far cheaper
    than ``lstsq``); nearly dependent columns get ``lstsq``'s minimum-norm answer."""

    def __init__(self, cols: list, intercept: bool = True):
        A = np.column_stack(cols)
        self.intercept = intercept
        self.means = A.mean(axis=0) if intercept else np.zeros(A.shape[1])
        self.C = A - self.means if intercept else A
        self.chol = None
        norms = np.sqrt(np.einsum("ij,ij->j", self.C, self.C))
        if np.all(norms > 0) and np.all(np.isfinite(norms)):
            self.norms, self.Cs = norms, self.C / norms
            try:
                chol = np.linalg.cholesky(self.Cs.T @ self.Cs)
            except np.linalg.LinAlgError:
                chol = None
            if chol is not None and np.min(np.diag(chol)) ** 2 > _PIVOT:
                self.chol = chol

    def solve(self, V: np.ndarray) -> np.ndarray:
        """``B`` minimising ``‖C B − V‖`` for the centred columns C, right-hand sides V (n, k) centred alike."""
        if self.chol is not None:
            return dpotrs(self.chol, self.Cs.T @ V, lower=1)[0] / self.norms[:, None]  # cho_solve's LAPACK call
        return np.linalg.lstsq(self.C, V, rcond=None)[0]

    def project(self, y: np.ndarray):
        """Residual ``A c − y`` and coefficients c (intercept first): `project`."""
        ym = y.mean() if self.intercept else 0.0
        yc = y - ym
        b = self.solve(yc[:, None])[:, 0]
        return self.C @ b - yc, np.array([ym - self.means @ b, *b])

    def kaufman(self, target: np.ndarray, derivatives: list) -> np.ndarray:
        """Kaufman's Jacobian ``P⊥ (∂A/∂p · c + ∂U/∂p)`` of the projected residual (module docstring):
        ``derivatives`` as `Skeleton.derivatives` gives them. One solve gives c and the projections."""
        D = np.column_stack([target] + [g for _, g in derivatives])
        if self.intercept:
            D = D - D.mean(axis=0)
        B = self.solve(D)
        c = B[:, 0]  # the outer constants (but c0)
        R = D[:, 1:] - self.C @ B[:, 1:]  # P⊥ of each derivative
        scale = np.array([1.0 if col is None else c[col] for col, _ in derivatives])
        return R * scale


def project(cols: list, y: np.ndarray, intercept: bool = True):
    """Residual ``A c − y`` and coefficients c of y on ``A = [1, cols...]`` by least squares.

    Parameters
    ----------
    cols : the non-constant columns, each (n,).
    y : (n,) target.
    intercept : with the column of ones (else its coefficient is 0).

    Returns
    -------
    (ndarray, ndarray)
        The residual (n,) and the coefficients (intercept first).
    """
    return _Projector(cols, intercept).project(y)


def _kaufman(cols: list, target: np.ndarray, derivatives: list, intercept: bool = True) -> np.ndarray:
    """Kaufman's Jacobian of the projected residual at the columns ``cols`` (`_Projector.kaufman`)."""
    return _Projector(cols, intercept).kaufman(target, derivatives)


#: Two starts agree on the best when their R² differ by less than this ...
AGREE = 1e-6
#: ... and their inner constants by less than this (relative, each constant): the same optimum,
#: not two points of one degenerate basin (weights running off to 1e5 reach nearly equal R²
#: from different places, and which of them a start reaches is round-off).
AGREE_CONSTANTS = 1e-3


def _agreed(ends: list, best, sst: float) -> bool:
    """Whether another start reached the best one's optimum: R² within `AGREE` and the
    same inner constants (within `AGREE_CONSTANTS`). ``ends``: every start's solution."""
    def same(sol):
        scale = np.maximum(1.0, np.abs(best.x))
        return (2.0 * (sol.cost - best.cost) <= AGREE * sst
                and bool(np.all(np.abs(sol.x - best.x) <= AGREE_CONSTANTS * scale)))
    return sum(same(sol) for sol in ends) >= 2


def fit(sk: Skeleton, Zt: np.ndarray, y: np.ndarray, starts: int = 2, seed: int = 0, max_nfev: int | None = None,
        p0=None, tol: float = 1e-8, max_starts: int | None = None):
    """Variable-projection fit of one skeleton.

    Parameters
    ----------
    sk : the skeleton.
    Zt : (d, n) inputs, one row a variable.
    y : (n,) target.
    starts : starts of Levenberg-Marquardt (the best is kept).
    max_starts : with more than ``starts``, starts go on (up to ``max_starts``) until two of
        them reach the same best optimum (`_agreed`): a scale-free product has degenerate
        basins (weights to 0 or to infinity) that one start in four or so falls into, and
        which basin a start falls into can turn on round-off, i.e. on the BLAS and the
        machine. Two starts agreeing on the best makes the result a property of the data.
    seed : seed of the starts after the first.
    max_nfev : evaluation cap per start (default 25 per inner constant + 25).
    p0 : inner constants of the first start (a warm start); else `skeletons.initial`'s.
    tol : relative tolerance on the cost and the constants (``ftol``, ``xtol``): a search
        that only ranks skeletons can stop earlier than a final fit.

    Returns
    -------
    (float, ndarray | None, ndarray | None)
        Training R², inner constants, outer constants (``(-inf, None, None)`` when no start succeeds).
    """
    rng = np.random.default_rng(seed)
    sst = float(np.sum((y - y.mean()) ** 2)) or 1.0
    bad = np.full(y.shape, 1e3)

    last: list = [None, None]  # the last constants and their parts: the Jacobian follows the residual at one point

    def parts(p):
        if last[0] is not None and np.array_equal(p, last[0]):
            return last[1]
        cols, target = sk.columns(p, Zt), y - sk.offset(p, Zt)
        ok = all(np.isfinite(c.sum()) for c in cols) and np.isfinite(np.sum(target))
        last[:] = [np.array(p, copy=True), (_Projector(cols, sk.intercept) if ok else None, target)]
        return last[1]

    def residual(p):
        with np.errstate(all="ignore"):
            projector, target = parts(p)
            return projector.project(target)[0] if projector is not None else bad

    def jacobian(p):
        with np.errstate(all="ignore"):
            projector, target = parts(p)
            if projector is None:
                return np.zeros((y.size, p.size))
            J = projector.kaufman(target, sk.derivatives(p, Zt))
        return J if np.all(np.isfinite(J)) else np.zeros((y.size, p.size))

    best, ends = None, []
    for s in range(max(starts, max_starts or 0)):
        if s >= starts and best is not None and _agreed(ends, best, sst):
            break
        try:
            start = np.asarray(p0, float) if (p0 is not None and s == 0) else initial(sk, s, rng)
            sol = least_squares(residual, start, jac=jacobian, method="lm", ftol=tol, xtol=tol,
                                max_nfev=max_nfev or 25 * (sk.n_inner + 1))
        except (ValueError, np.linalg.LinAlgError):
            continue
        ends.append(sol)
        if best is None or sol.cost < best.cost:
            best = sol
    if best is None:
        return -np.inf, None, None
    with np.errstate(all="ignore"):
        r, c = project(sk.columns(best.x, Zt), y - sk.offset(best.x, Zt), sk.intercept)
    return 1.0 - float(r @ r) / sst, best.x, c

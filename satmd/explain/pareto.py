"""Scoring distilled formulas: the split, metrics, cross-validated R², typed Pareto entries and the front."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from sklearn.metrics import mean_absolute_error, r2_score
from sklearn.model_selection import train_test_split

from ..errors import DataError

_METRICS = ("r2_train", "mae_train", "r2_test", "mae_test")


def _symbolic():
    """The sympy helpers, imported on first use (sympy is an optional dependency)."""
    from . import symbolic

    return symbolic


def metrics(expr, Ztr, Zte, ytr, yte) -> dict:
    """R² and MAE of ``expr`` on a training and a test part (−inf / inf where it is not finite).

    Parameters
    ----------
    expr : sympy expression in x0..
    Ztr, Zte : inputs of the two parts
    ytr, yte : targets of the two parts

    Returns
    -------
    dict
        ``r2_train``, ``mae_train``, ``r2_test``, ``mae_test``.
    """
    symbolic = _symbolic()
    out = {}
    for part, Z, y in (("train", Ztr, ytr), ("test", Zte, yte)):
        p = symbolic.evaluate(expr, Z)
        ok = np.all(np.isfinite(p))
        out[f"r2_{part}"] = float(r2_score(y, p)) if ok else float("-inf")
        out[f"mae_{part}"] = float(mean_absolute_error(y, p)) if ok else float("inf")
    return out


def cv_r2(expr, Z, y, folds: int = 5, seed: int = 0) -> float:
    """Mean R² of ``expr`` over ``folds``-fold cross-validation, constants refitted
    (`symbolic.polish`) on each fold's training part.

    Parameters
    ----------
    expr : sympy expression in x0..
    Z, y : rows to cross-validate on (never the test rows).
    folds : number of folds.
    seed : seed of the fold assignment.

    Returns
    -------
    float
    """
    from sklearn.model_selection import KFold

    symbolic = _symbolic()
    scores = []
    for fit_rows, held in KFold(int(folds), shuffle=True, random_state=seed).split(Z):
        e = symbolic.polish(expr, Z[fit_rows], y[fit_rows])
        scores.append(metrics(e, Z[fit_rows], Z[held], y[fit_rows], y[held])["r2_test"])
    return float(np.mean(scores))


@dataclass(frozen=True)
class ParetoEntry(Mapping):
    """One distilled candidate: its size, train/test metrics and expression.

    ``r2_val`` (R² on the validation share) and ``r2_cv`` (cross-validated R² of a finalist) are
    None when not computed; ``chosen`` marks the back end's own choice. It reads as the mapping
    it replaced (``entry["r2_test"]``, ``{**entry}``, ``"r2_val" in entry``): the keys are the
    fields computed, ``chosen`` never among them.
    """

    complexity: int
    r2_train: float
    mae_train: float
    r2_test: float
    mae_test: float
    expression: object  # sympy expression
    r2_val: float | None = None
    r2_cv: float | None = None
    chosen: bool = field(default=False, compare=False)

    def _keys(self) -> tuple:
        optional = tuple(k for k in ("r2_val", "r2_cv") if getattr(self, k) is not None)
        return ("complexity", *_METRICS, "expression", *optional)

    def __getitem__(self, key):
        if key not in self._keys():
            raise KeyError(key)
        return getattr(self, key)

    def __iter__(self):
        return iter(self._keys())

    def __len__(self) -> int:
        return len(self._keys())

    def to_dict(self) -> dict:
        """The entry as a JSON-ready dict (the expression as text).

        Returns
        -------
        dict
        """
        return {**self, "expression": str(self.expression)}


def score(expr, Ztr, Zte, ytr, yte, Zval=None, yval=None, chosen: bool = False) -> ParetoEntry:
    """The Pareto entry of ``expr``: node count, train/test metrics and, given a validation share, its R².

    Parameters
    ----------
    expr : sympy expression in x0..
    Ztr, Zte, ytr, yte : the training and test parts
    Zval, yval : the validation share (None: none)
    chosen : whether the back end chose it

    Returns
    -------
    ParetoEntry
    """
    m = metrics(expr, Ztr, Zte, ytr, yte)
    r2_val = metrics(expr, Zval, Zval, yval, yval)["r2_train"] if Zval is not None else None
    return ParetoEntry(_symbolic().node_count(expr), m["r2_train"], m["mae_train"], m["r2_test"], m["mae_test"],
                       expr, r2_val=r2_val, chosen=chosen)


def pareto_front(entries: list, key: str = "r2_train") -> list:
    """Entries not dominated in (complexity low, ``key`` high), simplest first.

    Parameters
    ----------
    entries : ParetoEntry (or mappings with ``complexity`` and ``key``)
    key : the score to maximise

    Returns
    -------
    list
    """
    front, best = [], -np.inf
    for e in sorted(entries, key=lambda e: (e["complexity"], -e[key])):
        if e[key] > best:
            front.append(e)
            best = e[key]
    return front


def split(X, y, test_size=0.2, seed=42, zscore=True):
    """z-score X with whole-data statistics (unless ``zscore`` is False), then the
    80/20 split. Returns Z_tr, Z_te, y_tr, y_te, mean, std."""
    X = np.asarray(X, float)
    y = np.asarray(y, float).ravel()
    if X.ndim != 2 or X.shape[0] != y.size:
        raise DataError(f"X must be (n, d) and y (n,); got {X.shape} and {y.shape}")
    keep = np.all(np.isfinite(X), axis=1) & np.isfinite(y)
    X, y = X[keep], y[keep]
    if y.size < 10:
        raise DataError(f"need at least 10 finite samples, got {y.size}")
    mean = X.mean(axis=0) if zscore else np.zeros(X.shape[1])
    std = X.std(axis=0) if zscore else np.ones(X.shape[1])
    std = np.where(std > 0, std, 1.0)
    Z = (X - mean) / std
    Ztr, Zte, ytr, yte = train_test_split(Z, y, test_size=test_size, random_state=seed)
    return Ztr, Zte, ytr, yte, mean, std


@dataclass(frozen=True)
class Parts:
    """The rows of a distillation: training (search ``fit`` + ``val`` share) and test, z-scored."""

    Ztr: np.ndarray
    Zte: np.ndarray
    ytr: np.ndarray
    yte: np.ndarray
    mean: np.ndarray
    std: np.ndarray
    Zfit: np.ndarray
    yfit: np.ndarray
    Zval: np.ndarray | None
    yval: np.ndarray | None

    @classmethod
    def make(cls, X, y, test_size: float, seed: int, zscore: bool, validation: float) -> "Parts":
        """`split`, then the validation share of the training rows (seed ``seed + 1``).

        Parameters
        ----------
        X, y : inputs and target
        test_size, seed, zscore : as `split`
        validation : share of the training rows held out (0: none)

        Returns
        -------
        Parts
        """
        Ztr, Zte, ytr, yte, mean, std = split(X, y, test_size, seed, zscore)
        if validation:
            Zfit, Zval, yfit, yval = train_test_split(Ztr, ytr, test_size=validation, random_state=seed + 1)
        else:
            Zfit, yfit, Zval, yval = Ztr, ytr, None, None
        return cls(Ztr, Zte, ytr, yte, mean, std, Zfit, yfit, Zval, yval)

    @property
    def d(self) -> int:
        """Number of inputs."""
        return self.Ztr.shape[1]

    def score(self, expr, chosen: bool = False) -> ParetoEntry:
        """The Pareto entry of ``expr`` on these parts.

        Parameters
        ----------
        expr : sympy expression
        chosen : whether the back end chose it

        Returns
        -------
        ParetoEntry
        """
        return score(expr, self.Ztr, self.Zte, self.ytr, self.yte, self.Zval, self.yval, chosen)


@dataclass(frozen=True)
class Finish:
    """What becomes of a candidate: constants refitted (``polish``), absorbable ones dropped
    (``prune``), the rest rounded to ``digits`` significant digits."""

    polish: bool
    prune: bool
    digits: int

    def __call__(self, expr, Z, y):
        """The finished expression, constants fitted on ``Z``, ``y``."""
        symbolic = _symbolic()
        if self.polish:
            expr = symbolic.polish(expr, Z, y)
        if self.prune:
            expr = symbolic.prune(expr, Z, y)
        return symbolic.round_floats(symbolic.compact(symbolic.round_floats(expr, self.digits)), self.digits)

"""From the optimum to a `FitResult`: fit statistics, covariance, information criteria, warnings."""
from __future__ import annotations

import warnings as _warnings

import numpy as np

from ..errors import DataWarning, IdentifiabilityWarning, PinnedParameterWarning, PoorFitWarning, WarningRecord
from ..numerics import lag1_autocorrelation
from ..conventions import TINY
from .covariance import parameter_covariance
from .result import FitResult

# poor-fit thresholds: relative error beyond which the model "reproduces little of the data", and
# lag-1 autocorrelation of the residuals along frequency beyond which they are structured, not noise
POOR_REL_ERROR = 0.5
STRUCTURED_LAG1 = 0.5
MATERIAL_REL_ERROR = 1e-3


def build_result(problem, theta, nominal, nfev, wall, opt, reg) -> FitResult:
    r, J = problem.residuals_and_jacobian(theta)
    chi2 = float(r @ r)
    n, k = r.size, len(theta)
    dof = max(n - k, 1)
    chi2_red = chi2 / dof
    names = problem.names
    pinned = _pinned(problem, theta, nominal)
    free = np.array([nm not in pinned for nm in names])
    # pinned parameters are held at their bound (no std); the others get the covariance given them
    cov, cond = parameter_covariance(J, r, problem.scales(theta), free, problem.weighted)
    std = np.sqrt(np.abs(np.diag(cov)))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    if problem.weighted:
        aic, bic = chi2 + 2 * k, chi2 + k * np.log(n)
    else:
        base = n * np.log(max(chi2, TINY) / n)
        aic, bic = base + 2 * k, base + k * np.log(n)
    if problem.pair is None:
        half = r.size // 2  # r = [Re, Im] of (model - data)/σ: the prediction without another model call
        pred = problem.target + (r[:half] + 1j * r[half:]).reshape(problem.target.shape) * problem.sigma
    else:  # r is whitened across channels: evaluate the model once more
        pred = problem.prediction(theta)
    peak = np.abs(problem.target).max()  # norms of scaled arrays: no overflow for any finite data
    rel = float(_norm((pred - problem.target) / peak) / _norm(problem.target / peak))
    fit_pct = {}
    for c, y, yh in zip(problem.channels, problem.target / peak, pred / peak):
        spread = _norm(y - y.mean())
        fit_pct[c] = float(100 * (1 - _norm(yh - y) / spread)) if spread > 0 else float("nan")
    beyond = rel
    if problem.weighted and problem.pair is None:  # the poor-fit warning reads the error beyond the noise
        power = float(np.sum(np.abs(problem.target / problem.sigma) ** 2))
        beyond = beyond_noise(rel, chi2, 2 * problem.target.size, power)
    warnings = _fit_warnings(problem, theta, r, beyond, chi2_red, dof, pinned)
    for i, nm in enumerate(names):
        if nm in pinned:
            continue
        if not np.isfinite(std[i]) or (theta[i] != 0 and std[i] / abs(theta[i]) > 1):
            rel_std = std[i] / abs(theta[i] or 1)
            how = f"relative std {rel_std:.3g}" if np.isfinite(rel_std) else "its std is unbounded"
            warnings.append(WarningRecord(f"{nm} is not identifiable from these data ({how})", IdentifiabilityWarning))
    for i in range(k):
        for j in range(i + 1, k):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.99:
                warnings.append(WarningRecord(f"{names[i]} and {names[j]} are strongly correlated ({corr[i, j]:+.4f}): "
                                              "the data constrain a combination of them", IdentifiabilityWarning))
    if cond > 1e12 and free.any():
        warnings.append(WarningRecord(f"ill-conditioned problem (condition number {cond:.3g})", IdentifiabilityWarning))
    return FitResult(
        names=names,
        values={nm: float(v) for nm, v in zip(names, theta)},
        std={nm: float(s) for nm, s in zip(names, std)},
        correlation=corr,
        covariance=cov,
        chi2=chi2,
        chi2_reduced=chi2_red,
        dof=dof,
        n_data=n,
        aic=float(aic),
        bic=float(bic),
        rel_error=rel,
        fit_percent=fit_pct,
        nfev=int(nfev),
        wall_time=float(wall),
        success=bool(opt.success),
        message=str(opt.message),
        weighted=problem.weighted,
        condition_number=cond,
        warnings=tuple(warnings),
        start={nm: float(v) for nm, v in zip(names, nominal)},
        reg=reg,
        pinned=pinned,
        _problem=problem,
    )


def _norm(x) -> float:
    """Euclidean norm of a complex array (plain sums: np.linalg.norm's BLAS dot crawls on a busy machine)."""
    return float(np.sqrt(np.sum(x.real**2 + x.imag**2)))


def _pinned(problem, theta, nominal) -> tuple:
    """Names of parameters on a bound (within 1 % of it, or 1e-6 of the nominal scale for a zero bound).

    The trust-region solver keeps iterates strictly inside, so a parameter the
    data push beyond its bound ends close to it rather than on it.
    """
    out = []
    for p, v, s in zip(problem.params, theta, problem.scales(nominal)):
        for b in (p.lower, p.upper):
            if np.isfinite(b) and abs(v - b) <= (1e-2 * abs(b) if b != 0 else 1e-6 * s):
                out.append(p.name)
                break
    return tuple(out)


def beyond_noise(rel: float, chi2: float, n: int, power: float) -> float:
    """The relative error on what the data carry above their noise (see `adequacy.rel_error_beyond_noise`).

    Parameters
    ----------
    rel : the plain relative error.
    chi2 : Σ |residual / σ|² over the n real numbers fitted.
    n : their count (2 per complex point).
    power : Σ |data / σ|².

    Returns
    -------
    float
        sqrt(max(χ² − n, 0) / (power − n)), or ``rel`` when smaller, when the data hold signal above their
        noise (power > 2n); else ``rel``.
    """
    if not (np.isfinite(rel) and np.isfinite(chi2) and np.isfinite(power) and power > 2 * n):
        return rel
    return min(rel, float(np.sqrt(max(chi2 - n, 0.0) / (power - n))))


def _lag1(r, n_series) -> float:
    """Pooled lag-1 autocorrelation along frequency of the weighted residual (≈ 0 for noise)."""
    return lag1_autocorrelation(r.reshape(n_series, -1))  # about 0, the residual's expectation


def _fit_warnings(problem, theta, r, rel, chi2_red, dof, pinned) -> list:
    """Poor-fit and pinned-parameter warnings, as `WarningRecord` of PoorFitWarning / PinnedParameterWarning."""
    out = []
    for nm in pinned:
        p = problem.params[problem.names.index(nm)]
        v = theta[problem.names.index(nm)]
        side = "lower" if abs(v - p.lower) <= abs(v - p.upper) else "upper"
        out.append(WarningRecord(f"{nm} is pinned at its {side} bound ({v:.6g}): the data push it beyond the "
                                 "model's range; it gets no std (check units, frequency axis and channels)",
                                 PinnedParameterWarning))
    if rel >= POOR_REL_ERROR:
        out.append(WarningRecord(f"poor fit: relative FRF error {rel:.3g}: the model reproduces little of the data "
                                 "(a different structure, or wrong channels, units or frequency axis?)", PoorFitWarning))
    if problem.weighted and chi2_red > 1.5 and chi2_red > 1 + 5 * np.sqrt(2 / dof):
        out.append(WarningRecord(f"poor fit: reduced chi-square {chi2_red:.3g} with the data's std ({dof} dof): "
                                 "the model does not fit within the noise", PoorFitWarning))
    n_series = 2 * len(problem.channels)
    rho = _lag1(r, n_series)
    n_freq = r.size // n_series
    # structure matters only when the misfit does: beyond the given noise, or (noise unknown) beyond
    # 0.1 % of the data, below which a model reproduces an FRF better than it can be measured
    material = chi2_red > 1 + 3 * np.sqrt(2 / dof) if problem.weighted else rel > MATERIAL_REL_ERROR
    if material and rho > max(STRUCTURED_LAG1, 4 / np.sqrt(r.size)) and n_freq > 4:
        out.append(WarningRecord(f"poor fit: residuals are structured along frequency (lag-1 autocorrelation "
                                 f"{rho:.2f}; noise gives about 0): the model misses something systematic",
                                 PoorFitWarning))
    return out


# the categories `identify` emits; the others (identifiability) stay on the result
EMITTED = (PoorFitWarning, PinnedParameterWarning)


def emit_warnings(result: FitResult):
    """Emit the result's warnings of the `EMITTED` categories (poor fit, pinned parameter) as Python warnings.

    Parameters
    ----------
    result : FitResult
        Its other warnings (correlation, conditioning) stay on the result only.
    """
    for w in result.warnings:
        category = getattr(w, "category", DataWarning)
        if issubclass(category, EMITTED):
            _warnings.warn(str(w), category, stacklevel=3)

"""FitResult: what an engineer wants to read after a fit."""
from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np
from scipy import stats
from scipy.optimize import brentq, least_squares

from ..io.frfdata import FRFData
from ..physics.rig import PARAMETER_INFO


@dataclass(frozen=True)
class FitResult:
    """Outcome of `satmd.identify`.

    ``std`` comes from the Jacobian covariance (JᵀJ)⁻¹, scaled by χ²_red when
    the data carry no std (then the noise level is estimated from the fit).
    Jacobian intervals are approximate for a nonlinear model;
    ``confidence_intervals()`` gives profile-likelihood intervals.

    Information criteria: with std given, χ² is −2 log L up to a constant,
    so AIC = χ² + 2k and BIC = χ² + k ln n; without std they use
    n ln(χ²/n) in place of χ² (as lmfit does).
    """

    names: tuple
    values: dict
    std: dict
    correlation: np.ndarray
    covariance: np.ndarray
    chi2: float
    chi2_reduced: float
    dof: int
    n_data: int
    aic: float
    bic: float
    rel_error: float
    fit_percent: dict
    nfev: int
    wall_time: float
    success: bool
    message: str
    weighted: bool
    condition_number: float
    warnings: tuple
    start: dict
    reg: float = 0.0
    _problem: object = field(default=None, repr=False, compare=False)

    # --- derived views -----------------------------------------------------
    @property
    def rig(self):
        """The rig with the fitted values."""
        return self._problem.apply(self.theta)[0]

    @property
    def effects(self):
        return self._problem.apply(self.theta)[1]

    @property
    def theta(self) -> np.ndarray:
        return np.array([self.values[n] for n in self.names])

    @property
    def channels(self):
        return self._problem.channels

    def prediction(self, freq_hz=None) -> FRFData:
        """The fitted model's FRFs (on the data grid by default)."""
        from ..physics import frf

        f = self._problem.omega_hz if freq_hz is None else np.asarray(freq_hz, float)
        rig, effects = self._problem.apply(self.theta)
        r = frf(f, rig, effects, outputs=self.channels)
        return FRFData(f, {c: r.channel(c) for c in self.channels}, {}, {"source": "fitted model"})

    def standardized_residuals(self) -> dict:
        """(model − data)/σ per channel, complex (σ = std or the eq. 13 scale)."""
        p = self._problem
        z = (p.prediction(self.theta) - p.target) / p.sigma
        return {c: z[k] for k, c in enumerate(p.channels)}

    # --- reporting ---------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "parameters": dict(self.values),
            "std": dict(self.std),
            "correlation": {a: {b: float(self.correlation[i, j]) for j, b in enumerate(self.names)}
                            for i, a in enumerate(self.names)},
            "chi2": self.chi2,
            "chi2_reduced": self.chi2_reduced,
            "dof": self.dof,
            "aic": self.aic,
            "bic": self.bic,
            "rel_error": self.rel_error,
            "fit_percent": dict(self.fit_percent),
            "noise": "given" if self.weighted else "estimated",
            "condition_number": self.condition_number,
            "warnings": list(self.warnings),
            "nfev": self.nfev,
            "wall_time_s": self.wall_time,
            "success": self.success,
        }

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    def report(self) -> str:
        """Plain-text fit report (in the spirit of lmfit's fit_report)."""
        noise = "std from the data" if self.weighted else "no std in the data: σ = max|x| per channel, χ² rescaled"
        lines = [
            "[[Fit statistics]]",
            f"    channels           = {', '.join(self.channels)}",
            f"    data points        = {self.n_data} (real and imaginary parts)",
            f"    free parameters    = {len(self.names)}",
            f"    function evals     = {self.nfev}",
            f"    wall time          = {self.wall_time:.3f} s",
            f"    noise model        = {noise}",
            f"    chi-square         = {self.chi2:.6g}",
            f"    reduced chi-square = {self.chi2_reduced:.6g}",
            f"    Akaike info crit   = {self.aic:.6g}",
            f"    Bayesian info crit = {self.bic:.6g}",
            f"    relative FRF error = {self.rel_error:.3e}",
            "    fit (NRMSE)        = " + ", ".join(f"{c} {v:.2f} %" for c, v in self.fit_percent.items()),
            "[[Variables]]",
        ]
        for n in self.names:
            v, s = self.values[n], self.std[n]
            unit = PARAMETER_INFO.get(n, ("", ""))[0]
            rel = f"({100 * s / abs(v):.3g} %)" if v else ""
            init = self.start.get(n)
            lines.append(f"    {n:<10} = {v:.8g} +/- {s:.3g} {rel} {unit}  (init = {init:.6g})")
        pairs = [(abs(self.correlation[i, j]), self.names[i], self.names[j], self.correlation[i, j])
                 for i in range(len(self.names)) for j in range(i + 1, len(self.names))]
        pairs = sorted((p for p in pairs if p[0] > 0.1), reverse=True)
        if pairs:
            lines.append("[[Correlations]] (unreported correlations are < 0.100)")
            lines += [f"    C({a}, {b}) = {c:+.4f}" for _, a, b, c in pairs]
        if self.warnings:
            lines.append("[[Warnings]]")
            lines += [f"    {w}" for w in self.warnings]
        return "\n".join(lines)

    def __str__(self):
        return self.report()

    # --- profile likelihood ------------------------------------------------
    def confidence_intervals(self, level: float = 0.95, names=None, max_steps: int = 12) -> dict:
        """Profile-likelihood intervals {name: (lo, hi)}.

        For each parameter the others are re-optimised along a scan; the
        interval is where χ² rises by the χ²₁ quantile (scaled by χ²_red when
        the noise was estimated).
        """
        from .problem import Problem

        p = self._problem
        delta = stats.chi2.ppf(level, 1) * (1.0 if self.weighted else self.chi2_reduced)
        out = {}
        for i, name in enumerate(names or self.names):
            i = self.names.index(name)
            others = [n for n in self.names if n != name]
            best = self.theta
            s = self.std[name] if np.isfinite(self.std[name]) and self.std[name] > 0 else abs(best[i]) * 1e-3 + 1e-12
            warm = {"x": np.delete(best, i)}

            def profile(v):
                rig, effects = p.apply(np.where(np.arange(len(best)) == i, v, best))
                if not others:
                    return float(np.sum(p.residuals(np.array([v])) ** 2)) - self.chi2
                sub = Problem(p.data, rig, others, p.channels, effects,
                              {q.name: (q.lower, q.upper) for q in p.params if q.name != name}, p.scale_mode)
                x0 = np.clip(warm["x"], sub.lower, sub.upper)
                sc = sub.scales(x0)

                def fj(x):
                    r, J = sub.residuals_and_jacobian(x0 + sc * x)
                    return r, J * sc

                fit = least_squares(lambda x: fj(x)[0], np.zeros_like(x0), jac=lambda x: fj(x)[1],
                                    bounds=((sub.lower - x0) / sc, (sub.upper - x0) / sc), method="trf",
                                    x_scale="jac", max_nfev=100)
                warm["x"] = x0 + sc * fit.x
                return 2 * fit.cost - self.chi2

            bounds = []
            for direction in (-1, 1):
                warm["x"] = np.delete(best, i)
                lim = p.params[i].lower if direction < 0 else p.params[i].upper
                step, prev = s, best[i]
                found = None
                for _ in range(max_steps):
                    v = best[i] + direction * step
                    if (v - lim) * direction >= 0:
                        v = lim
                    if profile(v) > delta:
                        found = brentq(lambda u: profile(u) - delta, min(prev, v), max(prev, v), xtol=s * 1e-3)
                        break
                    if v == lim:
                        break
                    prev, step = v, step * 2
                bounds.append(found if found is not None else (-np.inf if direction < 0 else np.inf))
            out[name] = tuple(bounds)
        return out


def build_result(problem, theta, nominal, nfev, wall, opt, reg) -> FitResult:
    r, J = problem.residuals_and_jacobian(theta)
    chi2 = float(r @ r)
    n, k = r.size, len(theta)
    dof = max(n - k, 1)
    chi2_red = chi2 / dof
    # covariance through relative scaling: well conditioned even for kp ~ 1e5 beside L ~ 1e-2
    sc = problem.scales(theta)
    Js = J * sc
    u, sv, vt = np.linalg.svd(Js, full_matrices=False)
    cond = float((sv[0] / sv[-1]) ** 2) if sv[-1] > 0 else np.inf
    with np.errstate(divide="ignore"):
        inv_sv2 = np.where(sv > sv[0] * 1e-14, 1.0 / sv**2, np.inf)
    cov_s = (vt.T * inv_sv2) @ vt if np.all(np.isfinite(inv_sv2)) else np.full((k, k), np.inf)
    cov = cov_s * np.outer(sc, sc) * (1.0 if problem.weighted else chi2_red)
    std = np.sqrt(np.abs(np.diag(cov)))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    if problem.weighted:
        aic, bic = chi2 + 2 * k, chi2 + k * np.log(n)
    else:
        base = n * np.log(max(chi2, 1e-300) / n)
        aic, bic = base + 2 * k, base + k * np.log(n)
    pred = problem.prediction(theta)
    rel = float(np.linalg.norm(pred - problem.target) / np.linalg.norm(problem.target))
    fit_pct = {}
    for c, y, yh in zip(problem.channels, problem.target, pred):
        fit_pct[c] = float(100 * (1 - np.linalg.norm(yh - y) / np.linalg.norm(y - y.mean())))
    names = problem.names
    warnings = []
    for i, nm in enumerate(names):
        if not np.isfinite(std[i]) or (theta[i] != 0 and std[i] / abs(theta[i]) > 1):
            warnings.append(f"{nm} is not identifiable from these data (relative std {std[i] / abs(theta[i] or 1):.3g})")
    for i in range(k):
        for j in range(i + 1, k):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > 0.99:
                warnings.append(f"{names[i]} and {names[j]} are strongly correlated ({corr[i, j]:+.4f}): "
                                f"the data constrain a combination of them")
    if cond > 1e12:
        warnings.append(f"ill-conditioned problem (condition number {cond:.3g})")
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
        _problem=problem,
    )

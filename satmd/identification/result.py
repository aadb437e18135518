"""FitResult: what an engineer wants to read after a fit."""
from __future__ import annotations

import json
import math
from typing import Any
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..io.frfdata import FRFData
from .fit_report import fit_report
from .intervals import check_level, describe_interval, intervals_to_dict, profile_intervals

__all__ = ["FitResult", "describe_interval", "intervals_to_dict"]  # the interval helpers live in .intervals


@dataclass(frozen=True)
class FitResult:
    """Outcome of `satmd.identify`.

    ``std`` comes from the Jacobian covariance (JᵀJ)⁻¹ when the data carry a
    std. Without one the fit is relative (σ = max|x| per channel) and the
    noise is estimated from the residuals: the covariance is then the
    heteroscedasticity-consistent sandwich (HC3) — measured noise grows with
    |A| near resonances, so one pooled residual variance would make the
    intervals too narrow — and `intervals` use Student-t quantiles with the
    residual degrees of freedom. Jacobian intervals are approximate for a
    nonlinear model; ``confidence_intervals()`` gives profile-likelihood
    intervals.

    Parameters pinned at a bound are listed in ``pinned`` and get no std
    (NaN; None in `to_dict`). ``warnings`` says when the fit is poor (the
    model cannot represent the data), a parameter is pinned or not
    identifiable, or the problem is ill-conditioned.

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
    pinned: tuple = ()
    _problem: Any = field(default=None, repr=False, compare=False)  # the fitted Problem
    _assessor: object = field(default=None, repr=False, compare=False)  # fit -> Adequacy (set by identify)

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

        if freq_hz is None:  # as the data see it (through the estimator's smoothing, if any)
            f, pred = self._problem.freq_hz, self._problem.prediction(self.theta)
            return FRFData(f, {c: pred[k] for k, c in enumerate(self.channels)}, {}, {"source": "fitted model"})
        f = np.asarray(freq_hz, float)
        rig, effects = self._problem.apply(self.theta)
        r = frf(f, rig, effects, outputs=self.channels)
        return FRFData(f, {c: r.channel(c) for c in self.channels}, {}, {"source": "fitted model"})

    def standardised_residuals(self) -> dict:
        """(model − data)/σ per channel, complex (σ = std or the eq. 13 scale)."""
        p = self._problem
        z = p.standardise(p.prediction(self.theta))  # whitened across channels when their noise is correlated
        return {c: z[k] for k, c in enumerate(p.channels)}

    def standardized_residuals(self) -> dict:
        """Deprecated spelling of `standardised_residuals`.

        Returns
        -------
        dict
        """
        import warnings

        warnings.warn("FitResult.standardized_residuals is deprecated; use standardised_residuals",
                      DeprecationWarning, stacklevel=2)
        return self.standardised_residuals()

    @cached_property
    def adequacy(self):
        """Whether the SATMD model can describe these data at all (an `Adequacy` of
        `satmd.identification.adequacy`, set up by `identify`; None for a result made otherwise);
        computed on first use (a failed fit is refitted under the usual reading mistakes to name one)."""
        return None if self._assessor is None else self._assessor(self)

    @property
    def model_adequate(self) -> bool:
        """``adequacy.adequate``: False when the model cannot describe the data (see `adequacy`)."""
        return self.adequacy is None or self.adequacy.adequate

    # --- public views of the fitted problem (callers never reach into _problem) ---
    @property
    def data(self) -> FRFData:
        """The data the model was fitted to (with the std used, when estimated)."""
        return self._problem.data

    @property
    def freq_hz(self) -> np.ndarray:
        """Frequencies of the fitted points [Hz]."""
        return self._problem.freq_hz

    @property
    def sigma(self) -> dict:
        """σ per channel on the data grid: the std, or the eq. 13 scale when the data carry none."""
        return {c: self._problem.sigma[k] for k, c in enumerate(self._problem.channels)}

    def residuals(self) -> dict:
        """model − data per channel, complex, unweighted (divide by `sigma` for standardised)."""
        p = self._problem
        r = p.prediction(self.theta) - p.target
        return {c: r[k] for k, c in enumerate(p.channels)}

    # --- reporting ---------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-ready summary. Never holds NaN or inf: such numbers are None and
        ``null_reasons`` says why, keyed by their path (``"std.m2"``; one
        ``"correlation"`` entry for the matrix)."""
        why = {}

        def num(x, path, reason):
            x = float(x)
            if math.isfinite(x):
                return x
            why[path] = reason
            return None

        def no_std(n):
            return ("pinned at a bound: no confident std" if n in self.pinned
                    else "not identifiable from these data (singular or ill-determined Jacobian)")

        lo_hi = self.intervals()
        return {
            "parameters": {n: num(v, f"parameters.{n}", "not finite") for n, v in self.values.items()},
            "std": {n: num(s, f"std.{n}", no_std(n)) for n, s in self.std.items()},
            "interval_95": {n: [num(lo, f"interval_95.{n}", no_std(n)), num(hi, f"interval_95.{n}", no_std(n))]
                            for n, (lo, hi) in lo_hi.items()},
            "pinned": list(self.pinned),
            "correlation": {a: {b: num(self.correlation[i, j], "correlation",
                                       "undefined where a parameter has no std")
                                for j, b in enumerate(self.names)}
                            for i, a in enumerate(self.names)},
            "chi2": num(self.chi2, "chi2", "not finite"),
            "chi2_reduced": num(self.chi2_reduced, "chi2_reduced", "not finite"),
            "dof": self.dof,
            "aic": num(self.aic, "aic", "not finite"),
            "bic": num(self.bic, "bic", "not finite"),
            "rel_error": num(self.rel_error, "rel_error", "not finite"),
            "fit_percent": {c: num(v, f"fit_percent.{c}", "the channel is constant: NRMSE undefined")
                            for c, v in self.fit_percent.items()},
            "noise": "given" if self.weighted else "estimated",
            "covariance": "jacobian" if self.weighted else "sandwich (HC3), Student-t intervals",
            "condition_number": num(self.condition_number, "condition_number", "singular Jacobian"),
            "warnings": list(self.warnings),
            **(self.adequacy.to_dict() if self.adequacy is not None else {}),
            "nfev": self.nfev,
            "wall_time_s": self.wall_time,
            "success": self.success,
            "null_reasons": why,
        }

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    def report(self) -> str:
        """Plain-text fit report (in the spirit of lmfit's fit_report; formatted by `fit_report`)."""
        text = fit_report(self)
        return text if self.model_adequate else text + "\n" + self.adequacy.report()

    def __str__(self):
        return self.report()

    # --- intervals -------------------------------------------------------------
    def quantile(self, level: float = 0.95) -> float:
        """Two-sided quantile q for intervals ``value ± q·std``.

        Parameters
        ----------
        level : confidence level in (0, 1).

        Returns
        -------
        float
            Normal quantile when the data gave the std; Student t with the
            residual degrees of freedom when the noise was estimated.
        """
        from scipy import stats  # heavy: imported where used, not at `import satmd`

        check_level(level)
        p = 0.5 + level / 2
        return float(stats.norm.ppf(p) if self.weighted else stats.t.ppf(p, self.dof))

    @property
    def ci95(self) -> dict:
        """{name: [lo, hi]}: the 95 % Jacobian intervals, spelt as every other result spells them."""
        return {n: [float(a), float(b)] for n, (a, b) in self.intervals(0.95).items()}

    def intervals(self, level: float = 0.95) -> dict:
        """Jacobian (Wald) intervals, value ± `quantile` · std.

        Parameters
        ----------
        level : confidence level in (0, 1).

        Returns
        -------
        dict
            {name: (lo, hi)}; NaN for a parameter without std (pinned at a bound).
        """
        q = self.quantile(level)
        return {n: (self.values[n] - q * self.std[n], self.values[n] + q * self.std[n]) for n in self.names}

    def confidence_intervals(self, level: float = 0.95, names=None, max_steps: int = 12) -> dict:
        """Profile-likelihood intervals {name: (lo, hi)}.

        For each parameter the others are re-optimised along a scan outwards
        from the fit; the interval ends where χ² rises by the χ²₁ quantile.
        Without std in the data the threshold is the Student-t quantile
        (residual dof) squared times the estimated noise variance, adjusted by
        the ratio of the sandwich to the naive variance (so the profile agrees
        with `std` when the model is locally linear).

        Parameters
        ----------
        level : confidence level in (0, 1).
        names : parameters to profile (default all).
        max_steps : doubling steps of the outward scan, starting at one std.

        Returns
        -------
        dict
            {name: (lo, hi)}. A side that the data do not close — χ² stays
            below the threshold up to the parameter's bound or over
            ``max_steps`` steps — is -inf (unbounded below) or +inf
            (unbounded above); `describe_interval` and `intervals_to_dict`
            turn them into text and JSON.
        """
        return profile_intervals(self._problem, self, level, names, max_steps)

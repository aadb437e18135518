"""NonlinearFit: the outcome of `fit_nonlinear` (values, ci95, per-level errors, equivalent-linear values)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ...physics import Rig
    from ...physics.nonlinear import NonlinearElement


@dataclass(frozen=True)
class NonlinearFit:
    """A rig with one nonlinear element fitted to several recordings by time-domain output error.

    Parameters
    ----------
    element : the fitted NonlinearElement (None for a linear fit).
    rig : the fitted Rig (free parameters at their fitted values).
    values : {name: value} of every fitted parameter (rig fields and the element's, by name).
    std : {name: standard deviation} (sandwich covariance: residual colour allowed).
    ci95 : {name: [lo, hi]} 95 % intervals.
    levels : drive level [N] of each recording (`numerics.force_level`: RMS about the mean), in the order given.
    rel_error : RMS over recordings and channels of RMS(residual) / RMS(measured) after the fit (one
        figure, as `FitResult.rel_error`).
    rel_error_per_level : {level index: {"a1", "a2"}: RMS(residual) / RMS(measured)}.
    equivalent_linear : {linear parameter: [value per recording]} from the fitted element.
    cost : final ½ Σ r² (weighted residuals).
    nfev : model evaluations (each a batched simulation of every recording).
    wall_time : seconds.
    settings : what was fitted and how (seconds used, skipped start, weights).
    """

    element: NonlinearElement | None
    rig: Rig
    values: dict
    std: dict
    ci95: dict
    levels: list
    rel_error: float
    rel_error_per_level: dict
    equivalent_linear: dict
    cost: float
    nfev: int
    wall_time: float
    settings: dict = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The element's SPEC §8b name, or ``"linear"``."""
        return self.element.name if self.element is not None else "linear"

    def finding(self) -> dict:
        """The SPEC §9 ``nonlinear.findings`` entry for this fit."""
        if self.element is None:
            return {}
        names = self.element.parameter_names
        return {"name": self.element.name,
                "parameters": {k: float(self.values[k]) for k in names if k in self.values},
                "ci95": {k: [float(v) for v in self.ci95[k]] for k in names if k in self.ci95},
                "equivalent": [], "equivalent_linear": {k: [float(x) for x in v]
                                                        for k, v in self.equivalent_linear.items()},
                "explanation": self.element.explain(self.rig)}

    def to_dict(self) -> dict:
        """JSON-ready dict."""
        return {"model": self.name, "values": {k: float(v) for k, v in self.values.items()},
                "std": {k: float(v) for k, v in self.std.items()},
                "ci95": {k: [float(x) for x in v] for k, v in self.ci95.items()},
                "levels": [float(x) for x in self.levels],
                "rel_error": float(self.rel_error),
                "rel_error_per_level": {str(k): {c: float(e) for c, e in v.items()}
                                        for k, v in self.rel_error_per_level.items()},
                "equivalent_linear": {k: [float(x) for x in v] for k, v in self.equivalent_linear.items()},
                "cost": float(self.cost), "nfev": int(self.nfev), "wall_time": float(self.wall_time),
                "settings": dict(self.settings), "finding": self.finding()}

    def report(self) -> str:
        """Values with 95 % intervals, and the time-domain error per level."""
        lines = [f"time-domain fit ({self.name}) of {len(self.levels)} recording(s), "
                 f"{self.nfev} evaluations, {self.wall_time:.1f} s"]
        for k, v in self.values.items():
            lo, hi = self.ci95.get(k, (np.nan, np.nan))
            lines.append(f"  {k:>6s} = {v:.6g}   95 % [{lo:.6g}, {hi:.6g}]")
        for i, lev in enumerate(self.levels):
            e = self.rel_error_per_level.get(i, {})
            lines.append(f"  level {lev:.3g} N: error a1 {100 * e.get('a1', np.nan):.2f} %, "
                         f"a2 {100 * e.get('a2', np.nan):.2f} %")
        if self.element is not None:
            lines.append("  " + self.element.explain(self.rig))
        return "\n".join(lines)

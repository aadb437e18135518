"""Retuning over time: track a drifting rig through a series of FRFs and retune at each step.

Each step is identified warm-started from the previous step's values (local
least squares; the first step uses the global search), then tuned. The
figure compares the objective with retuning against keeping the first step's
optimal setting.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ..conventions import DEFAULT_FREE, PAPER_BAND_HZ
from ..errors import DataError, renamed_keyword
from ..physics.rig import Rig
from .laws import OPEN_CIRCUIT_R
from .objective import Objective
from .result import clean, db
from ..validation import NAMES, Band, validate_params


@dataclass(frozen=True)
class RetuneResult:
    """Per step: identified parameters, the retuned setting and the objective with the
    retuned setting, with the first step's setting kept fixed and with the shunt open."""

    labels: tuple
    parameters: tuple  # dicts of identified values
    designs: tuple  # dicts: optimal setting per step
    value_retuned: np.ndarray
    value_fixed: np.ndarray
    value_open: np.ndarray
    fixed_design: dict
    objective: str
    output: str
    band_hz: tuple
    wall_time: float = 0.0
    results: tuple = field(default=(), repr=False, compare=False)  # TuneResult per step

    @property
    def retuning_gain_db(self) -> np.ndarray:
        """How much lower the objective is with retuning than with the fixed setting (dB)."""
        return 20 * np.log10(self.value_fixed / self.value_retuned)

    def to_dict(self) -> dict:
        steps = []
        for i, lab in enumerate(self.labels):
            steps.append({"label": lab, "parameters": self.parameters[i], "design": self.designs[i],
                          "value_retuned": self.value_retuned[i], "value_fixed": self.value_fixed[i],
                          "attenuation_db_vs_open_circuit": {
                              "retuned": db(self.value_open[i] / self.value_retuned[i]),
                              "fixed": db(self.value_open[i] / self.value_fixed[i])},
                          "retuning_gain_db": self.retuning_gain_db[i]})
        return clean({"objective": self.objective, "output": self.output, "band_hz": list(self.band_hz),
                      "fixed_design": self.fixed_design, "steps": steps})

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    def report(self) -> str:
        names = list(self.designs[0])
        pnames = [k for k in self.parameters[0] if k not in names]
        head = "    " + f"{'step':<16}" + "".join(f"{p:>11}" for p in pnames) + "".join(f"{n:>11}" for n in names) \
            + f"{'retuned dB':>12}{'fixed dB':>10}{'gain dB':>9}"
        lines = ["[[Retuning over time]] (attenuation vs open circuit; fixed = the first step's setting "
                 + ", ".join(f"{k} = {v:.4g}" for k, v in self.fixed_design.items()) + ")", head]
        for i, lab in enumerate(self.labels):
            lines.append("    " + f"{str(lab)[:15]:<16}"
                         + "".join(f"{self.parameters[i][p]:>11.5g}" for p in pnames)
                         + "".join(f"{self.designs[i][n]:>11.5g}" for n in names)
                         + f"{db(self.value_open[i] / self.value_retuned[i]):>12.2f}"
                         + f"{db(self.value_open[i] / self.value_fixed[i]):>10.2f}"
                         + f"{self.retuning_gain_db[i]:>9.2f}")
        return "\n".join(lines)

    def __str__(self):
        return self.report()

    def figure(self):
        from ..plots import pyplot

        plt = pyplot()
        x = np.arange(len(self.labels))
        fig, ax = plt.subplots(figsize=(7.5, 4.0))
        unit = "m/N" if self.output == "u1" else "m/s²/N"
        for values, style, label in ((self.value_fixed, dict(color="tab:orange", ls="--", marker="s"),
                                      "fixed (first step's setting)"),
                                     (self.value_retuned, dict(color="tab:blue", marker="o"), "retuned at every step")):
            ax.plot(x, 20 * np.log10(values), label=label, **style)
        ax.set_xticks(x)
        ax.set_xticklabels([str(s) for s in self.labels], rotation=30, ha="right", fontsize=8)
        what = "peak" if self.objective == "hinf" else "RMS"
        ax.set_ylabel(f"{what} of |{self.output.upper()}| [dB re 1 {unit}]")
        ax.set_title(f"retuning a drifting rig ({self.band_hz[0]:g}–{self.band_hz[1]:g} Hz): up to "
                     f"{np.max(self.retuning_gain_db):.2f} dB lower than the fixed setting", fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        return fig

    def plot(self, path=None):
        fig = self.figure()
        from ..plots import save

        return fig if path is None else save(fig, path)


@validate_params({"rig": [None, Rig], "free": [NAMES], "labels": [None, NAMES], "band_hz": [Band()],
                  "band": [None, Band()], "design": [NAMES]})
def retune(
    series: Sequence,
    rig: Rig | None = None,
    free: Sequence[str] = DEFAULT_FREE,
    labels: Sequence[str] | None = None,
    objective: str = "hinf",
    output: str = "u1",
    band_hz: tuple[float, float] = PAPER_BAND_HZ,
    design: Sequence[str] = ("R", "L"),
    bounds: dict | None = None,
    band: tuple[float, float] | None = None,
    **tune_options,
) -> RetuneResult:
    """Identify each FRF of a drifting rig (warm-started) and retune at each step.

    The first step is identified with the global search, each later one by
    local least squares from the previous step's values; each fit is then
    tuned with `satmd.tune`.

    Parameters
    ----------
    series : sequence of FRFData
        The measurements, in time order (at least one).
    rig : Rig, optional
        Fixed parameters of the model (default: the paper's rig).
    free : sequence of str
        Parameters identified at each step.
    labels : sequence of str, optional
        Names of the steps, one per FRF (default: each FRFData's
        ``meta["label"]``, else its index).
    objective : {"hinf", "h2"}
        Peak (H∞) or RMS (H2) of ``output`` over ``band_hz``, as `satmd.tune`.
    output : {"u1", "a1"}
        Primary displacement or primary acceleration, as `satmd.tune`.
    band_hz : (float, float)
        Band (lo, hi) of the objective in Hz (``band=``, its former name, still works and warns).
    design : sequence of str
        Rig fields tuned at each step.
    bounds : dict, optional
        ``{name: (lo, hi)}`` search bounds of the design (defaults as `satmd.tune`).
    band : (float, float), optional
        The former name of ``band_hz`` (deprecated: it warns).
    **tune_options
        Further keywords for `satmd.tune` (``robust``, ``n_search``, ``seed``,
        ...); the closed-form check is always off.

    Returns
    -------
    RetuneResult
        Per step: the label, the identified parameters, the retuned design and
        the objective with it (``value_retuned``), with the first step's design
        kept (``value_fixed``, ``fixed_design``) and with the shunt open
        (``value_open``); ``retuning_gain_db``, ``results`` (the `TuneResult`
        of each step) and ``figure()`` / ``report()``.

    Raises
    ------
    DataError
        An empty series, or a number of labels other than the number of FRFs.
    """
    from ..identification import identify
    from .core import tune

    t0 = time.perf_counter()
    series = list(series)
    if not series:
        raise DataError("retune needs at least one FRF")
    if labels is None:
        labels = [d.meta.get("label", str(i)) for i, d in enumerate(series)]
    if len(labels) != len(series):
        raise DataError(f"{len(labels)} labels for {len(series)} FRFs")
    band_hz = renamed_keyword(band, band_hz, "retune")
    obj = Objective(objective, output, tuple(band_hz))
    prev, results = None, []
    fixed: dict = {}  # the first setting, kept through the series
    fixed_values, open_values = [], []
    for data in series:
        fit = identify(data, rig, free, start=prev, global_search=prev is None, warn=False)
        prev = dict(fit.values)
        res = tune(fit, objective, output, band_hz, bounds, design, closed_form_check=False, **tune_options)
        results.append(res)
        if not fixed:
            fixed = dict(res.design)
        fixed_values.append(float(obj(fit.rig.replace(**fixed), fit.effects)[0]))
        open_values.append(float(obj(fit.rig.replace(R=OPEN_CIRCUIT_R), fit.effects)[0]))
    return RetuneResult(
        labels=tuple(labels), parameters=tuple(r.model_parameters for r in results),
        designs=tuple(r.design for r in results), value_retuned=np.array([r.value for r in results]),
        value_fixed=np.array(fixed_values), value_open=np.array(open_values), fixed_design=fixed,
        objective=objective, output=output, band_hz=obj.band, wall_time=time.perf_counter() - t0,
        results=tuple(results))

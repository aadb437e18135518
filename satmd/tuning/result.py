"""TuneResult: the optimal setting, what it buys, and the evidence (SPEC §10 JSON)."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..jsonsafe import jsonable
from ..physics.rig import PARAMETER_INFO


def db(ratio: float) -> float:
    """20·log10(ratio); NaN when undefined (cleaned to null in JSON)."""
    return 20.0 * math.log10(ratio) if ratio > 0 and np.isfinite(ratio) else float("nan")


def clean(x):
    """JSON-ready copy: NumPy scalars to Python, NaN/inf to None (`satmd.jsonsafe.jsonable`)."""
    return jsonable(x)


@dataclass(frozen=True)
class TuneResult:
    """Outcome of `satmd.tune`.

    ``value`` is the objective (H∞ peak or H2 RMS of |U1| or |A1| over the
    band, nominal model) at the optimal ``design``; ``current_value`` at the
    current setting and ``open_circuit_value`` with the shunt open (R → ∞).
    ``closed_forms`` lists the classical laws that apply, each with its
    design, value and distance from the optimum in dB; ``robust`` summarises
    robust tuning (None unless asked for).
    """

    objective: str
    output: str
    band_hz: tuple
    design: dict
    value: float
    current_design: dict
    current_value: float
    open_circuit_value: float
    bounds: dict
    model_parameters: dict
    model_effects: list
    model_source: str
    peaks_hz: tuple
    closed_forms: tuple = ()
    robust: dict | None = None
    notes: tuple = ()
    nfev: int = 0
    wall_time: float = 0.0
    _rig: Any = field(default=None, repr=False, compare=False)  # model with the optimal design (a Rig)
    _current_rig: Any = field(default=None, repr=False, compare=False)
    _effects: tuple = field(default=(), repr=False, compare=False)

    # --- derived figures --------------------------------------------------------
    @property
    def attenuation_db(self) -> dict:
        return {"vs_current": db(self.current_value / self.value),
                "vs_open_circuit": db(self.open_circuit_value / self.value)}

    @property
    def unit(self) -> str:
        return "m/N" if self.output == "u1" else "m/s²/N"

    def response(self, freq_hz=None) -> dict:
        """Complex ``output`` of the tuned, current and open-circuit rigs (nominal model)."""
        from ..physics import frf
        from .laws import OPEN_CIRCUIT_R
        from .objective import band_grid

        f = band_grid(self.band_hz, 0.001) if freq_hz is None else np.asarray(freq_hz, float)
        rigs = {"tuned": self._rig, "current": self._current_rig,
                "open circuit": self._current_rig.replace(R=OPEN_CIRCUIT_R)}
        out = {"freq_hz": f}
        for k, r in rigs.items():
            out[k] = frf(f, r, list(self._effects), outputs=(self.output,)).channel(self.output)
        return out

    # --- reporting ---------------------------------------------------------------
    def to_dict(self, details: bool = False) -> dict:
        """The SPEC §10 document; ``details`` adds closed forms, peaks, notes and the model source."""
        out = {
            "objective": self.objective,
            "output": self.output,
            "band_hz": list(self.band_hz),
            "design": dict(self.design),
            "value": self.value,
            "current": {"design": dict(self.current_design), "value": self.current_value},
            "attenuation_db": self.attenuation_db,
            "model": {"parameters": dict(self.model_parameters), "effects": list(self.model_effects)},
            "robust": self.robust,
        }
        if details:
            out["details"] = {"model_source": self.model_source, "open_circuit_value": self.open_circuit_value,
                              "bounds": {k: list(v) for k, v in self.bounds.items()},
                              "peaks_hz": list(self.peaks_hz), "closed_forms": list(self.closed_forms),
                              "notes": list(self.notes), "nfev": self.nfev, "wall_time_s": self.wall_time}
        return clean(out)

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    def report(self) -> str:
        what = "peak (H∞)" if self.objective == "hinf" else "RMS (H2)"
        att = self.attenuation_db
        lines = ["[[Shunt tuning]]",
                 f"    objective          = {what} of |{self.output.upper()}| over {self.band_hz[0]:g}–"
                 f"{self.band_hz[1]:g} Hz",
                 f"    model              = {self.model_source}",
                 "    model parameters   = " + (", ".join(f"{k} = {v:.6g}" for k, v in self.model_parameters.items())
                                               or "(as given)"),
                 "    effects            = " + (", ".join(e["name"] for e in self.model_effects) or "none"),
                 "[[Setting]]",
                 f"    {'':<6} {'optimal':>12} {'current':>12}  unit"]
        for n in self.design:
            unit = PARAMETER_INFO.get(n, ("", ""))[0]
            lines.append(f"    {n:<6} {self.design[n]:>12.5g} {self.current_design[n]:>12.5g}  {unit}   "
                         f"(bounds {self.bounds[n][0]:g}–{self.bounds[n][1]:g})")
        lines += ["[[Result]]",
                  f"    optimal            = {self.value:.5g} {self.unit}",
                  f"    current setting    = {self.current_value:.5g} {self.unit}",
                  f"    open circuit       = {self.open_circuit_value:.5g} {self.unit}",
                  f"    attenuation        = {att['vs_current']:.2f} dB vs current, "
                  f"{att['vs_open_circuit']:.2f} dB vs open circuit",
                  "    peaks at optimum   = " + ", ".join(f"{f:.2f} Hz" for f in self.peaks_hz)]
        if self.closed_forms:
            lines.append("[[Classical closed forms on this rig]] (dB above the optimum)")
            for c in self.closed_forms:
                setting = ", ".join(f"{k} = {v:.4g}" for k, v in c["design"].items())
                gap = c.get("gap_db")
                gap_text = f"{gap:+.3f} dB" if gap is not None and np.isfinite(gap) else "n/a"
                lines.append(f"    {c['name']}: {setting} -> {gap_text}  ({c['note']})")
        if self.robust:
            r = self.robust
            g = r["guaranteed_attenuation_db"]
            q = 100 * r["quantile"]
            lines += [f"[[Robust tuning]] ({r['n_draws']} draws of {', '.join(r['parameters'])} from the "
                      f"{r['source']})",
                      f"    {q:g} % quantile at the robust optimum  = {r['value_quantile']:.5g} {self.unit}",
                      f"    {q:g} % quantile at the nominal optimum = "
                      f"{r['nominal_optimum']['value_quantile']:.5g} {self.unit} "
                      f"(design " + ", ".join(f"{k} = {v:.5g}" for k, v in r["nominal_optimum"]["design"].items())
                      + ")",
                      f"    guaranteed attenuation ({q:g} % of draws) = {g['vs_current']:.2f} dB vs current, "
                      f"{g['vs_open_circuit']:.2f} dB vs open circuit"]
        if self.notes:
            lines.append("[[Notes]]")
            lines += [f"    {n}" for n in self.notes]
        return "\n".join(lines)

    def __str__(self):
        return self.report()

    def figure(self):
        """|output| in dB before (current), after (tuned) and with the shunt open."""
        from ..plots import pyplot

        plt = pyplot()
        from matplotlib.ticker import NullFormatter, ScalarFormatter  # after pyplot() chose the backend

        r = self.response()
        fig, ax = plt.subplots(figsize=(7.5, 4.2))
        styles = {"open circuit": {"color": "0.6", "ls": ":"}, "current": {"color": "tab:orange"},
                  "tuned": {"color": "tab:blue", "lw": 1.8}}
        values = {"open circuit": self.open_circuit_value, "current": self.current_value, "tuned": self.value}
        for k in ("open circuit", "current", "tuned"):
            ax.plot(r["freq_hz"], 20 * np.log10(np.abs(r[k])), label=f"{k}: {values[k]:.3g} {self.unit}", **styles[k])
        if self.objective == "hinf":
            ax.axhline(20 * np.log10(self.value), color="tab:blue", lw=0.6, ls="--")
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel(f"|{self.output.upper()}| [dB re 1 {self.unit}]")
        att = self.attenuation_db
        ax.set_title(f"{'H∞' if self.objective == 'hinf' else 'H2'} tuning: " +
                     ", ".join(f"{k} = {v:.4g}" for k, v in self.design.items()) +
                     f"  ({att['vs_current']:.1f} dB vs current)", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        return fig

    def plot(self, path=None):
        """Draw `figure` into ``path`` (written atomically); returns the figure when no path."""
        fig = self.figure()
        if path is None:
            return fig
        from ..plots import save

        return save(fig, path)


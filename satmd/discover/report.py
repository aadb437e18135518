"""DiscoveryReport: the SPEC §9 document, a plain-language report and a figure."""
from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from ..physics.rig import PARAMETER_INFO

SCHEMA = "satmd-discovery/1"


@dataclass(frozen=True)
class DiscoveryReport:
    significant_mismatch: bool
    noise: str  # "given" or "estimated"
    mismatch_bands_hz: list
    effects: list  # dicts: name, parameters, equivalent, delta_bic, explanation
    parameters: dict
    fit_before: dict
    fit_after: dict
    # --- details (not part of the JSON schema) ---
    nominal_fit: object = field(default=None, repr=False, compare=False)
    final_fit: object = field(default=None, repr=False, compare=False)
    discrepancy: object = field(default=None, repr=False, compare=False)
    p_values: dict = field(default_factory=dict, repr=False, compare=False)
    whiteness: dict = field(default_factory=dict, repr=False, compare=False)
    wall_time: float = 0.0

    def to_dict(self) -> dict:
        return {
            "schema": SCHEMA,
            "significant_mismatch": bool(self.significant_mismatch),
            "noise": self.noise,
            "mismatch_bands_hz": [[round(a, 4), round(b, 4)] for a, b in self.mismatch_bands_hz],
            "effects": [{k: e[k] for k in ("name", "parameters", "equivalent", "delta_bic", "explanation")}
                        for e in self.effects],
            "parameters": dict(self.parameters),
            "fit_before": dict(self.fit_before),
            "fit_after": dict(self.fit_after),
        }

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    @property
    def effect_names(self) -> list:
        return [e["name"] for e in self.effects]

    def report(self) -> str:
        noise = ("the std columns of the file" if self.noise == "given"
                 else "an estimate from the residual's roughness (no std in the file)")
        lines = ["[[Missing-physics discovery]]",
                 f"    noise model: {noise}",
                 f"    nominal fit: χ²_red = {self.fit_before['chi2_reduced']:.3g}, "
                 f"relative error {self.fit_before['rel_error']:.3g} "
                 f"(p = {self.p_values.get('global', float('nan')):.2g} globally, "
                 f"{self.p_values.get('band', float('nan')):.2g} in the worst band)"]
        if not self.significant_mismatch:
            lines.append("    The nominal model fits within the noise: no missing physics is needed.")
            return "\n".join(lines)
        bands = ", ".join(f"{a:.1f}–{b:.1f} Hz" for a, b in self.mismatch_bands_hz) or "spread over the band"
        lines.append(f"    significant mismatch located at: {bands}")
        for i, e in enumerate(self.effects, 1):
            lines.append(f"  {i}. {e['name']}: {e['explanation']}")
            if e.get("equivalent"):
                lines.append(f"     equally good explanations (|ΔBIC| < 10): {', '.join(e['equivalent'])} "
                             "— these FRFs cannot tell them apart")
        lines.append(f"    after: χ²_red = {self.fit_after['chi2_reduced']:.3g}, "
                     f"relative error {self.fit_after['rel_error']:.3g}")
        lines.append("    fitted free parameters: " + ", ".join(f"{k} = {v:.6g}" for k, v in self.parameters.items()))
        return "\n".join(lines)

    def __str__(self):
        return self.report()

    def figure(self):
        """Measured vs nominal vs augmented FRFs and standardised residuals, bands shaded."""
        from ..plots import fit_figure

        data = self.nominal_fit._problem.data
        curves = [("nominal model", self.nominal_fit.prediction().channels, {"color": "tab:orange", "lw": 1.0})]
        resid = [("nominal", self.nominal_fit.standardized_residuals(), {"color": "tab:orange", "lw": 0.8})]
        if self.final_fit is not None and self.final_fit is not self.nominal_fit:
            pred = dict(self.final_fit.prediction().channels)
            z = dict(self.final_fit.standardized_residuals())
            label = " + ".join(n for n in self.effect_names if n != "unexplained") or "model"
            if self.discrepancy is not None:
                sig = self.final_fit._problem.sigma
                for k, c in enumerate(self.final_fit.channels):
                    pred[c] = pred[c] + self.discrepancy.correction[c]
                    z[c] = z[c] + self.discrepancy.correction[c] / sig[k]
                label += " + smooth discrepancy"
            curves.append((f"with {label}", pred, {"color": "tab:blue", "lw": 1.2}))
            resid.append(("augmented", z, {"color": "tab:blue", "lw": 0.8}))
        title = ("discovery: " + (", ".join(self.effect_names) if self.effects else "no missing physics")
                 + f"  (χ²_red {self.fit_before['chi2_reduced']:.3g} → {self.fit_after['chi2_reduced']:.3g})")
        return fit_figure(data, curves, resid, bands=self.mismatch_bands_hz, title=title)

    def plot(self, path):
        from ..plots import save

        return save(self.figure(), path)


def explain(name: str, params: dict, rig, shifts: dict) -> str:
    """One or two sentences of plain engineering language for a found effect."""
    if name == "sensor_gain":
        parts = []
        for ch, label in (("gain_a1", "accelerometer 1 (primary)"), ("gain_a2", "accelerometer 2 (absorber)")):
            g = params[ch]
            word = "high" if g > 1 else "low"
            parts.append(f"{label} reads {abs(g - 1) * 100:.1f} % {word}")
        text = "; ".join(parts) + " (calibration error)"
    elif name == "time_delay":
        tau = params["tau_s"]
        text = (f"the acquisition {'lags' if tau > 0 else 'leads'} by {abs(tau) * 1e3:.3g} ms on both channels "
                f"(a phase error of {np.degrees(2 * np.pi * 100 * abs(tau)):.2g}° at 100 Hz)")
    elif name == "structural_damping":
        eta = params["eta"]
        text = (f"the host structure has hysteretic loss η = {eta:.3g} (loss factor), "
                f"as much damping at resonance as c = {eta * float(rig.k1) / (2 * np.pi * 50):.3g} N·s/m at 50 Hz")
    elif name == "dielectric_loss":
        text = f"the piezo's dielectric is lossy: tan δ = {params['tan_delta']:.3g}"
    elif name == "shunt_capacitance":
        cs = params["Cs"]
        text = f"a stray capacitance of {cs * 1e6:.3g} µF ({100 * cs / float(rig.Cp):.2g} % of Cp) sits across the shunt"
    elif name == "extra_mode":
        text = (f"an unmodelled host mode at {params['f_hz']:.1f} Hz with {100 * params['mass_ratio']:.2g} % of the "
                f"primary mass (ζ = {params['zeta']:.2g})")
    elif name.startswith("parameter_offset:"):
        p = name.split(":", 1)[1]
        v, nominal = params["value"], float(getattr(rig, p))
        unit = PARAMETER_INFO[p][0]
        text = (f"the fixed parameter {p} is {v:.4g} {unit}, {100 * (v / nominal - 1):+.1f} % from its nominal "
                f"{nominal:.4g} {unit}")
    else:
        text = name
    moved = [f"{k} {100 * s:+.2g} %" for k, s in shifts.items() if abs(s) > 1e-3]
    if moved:
        text += "; accounting for it moves " + ", ".join(moved)
    return text

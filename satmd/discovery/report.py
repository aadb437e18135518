"""DiscoveryReport: the SPEC §9 document, a plain-language report and a figure."""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from .findings import NONLINEAR_KINDS, UNEXPLAINED
from ..conventions import MIN_DELTA_BIC

if TYPE_CHECKING:
    from ..identification.adequacy import Adequacy
    from .nonlinear.distortion import NonlinearReport

SCHEMA = "satmd-discovery/1"


@dataclass(frozen=True)
class DiscoveryReport:
    significant_mismatch: bool
    noise: str  # "given" or "estimated"
    mismatch_bands_hz: list
    judged: tuple  # Judged: every candidate with its verdict; the named ones, most important first, are `effects`
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
    # --- from recordings: how the FRFs were estimated, and what the chain did (SPEC §9) ---
    estimator: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)  # the chain's measurement findings (dicts), no candidate's
    nonlinear: NonlinearReport | None = None  # (SPEC §9 ``nonlinear`` block), when time data or levels were given
    adequacy: Adequacy | None = None  # (SPEC §9 ``model_adequate``); None: adequate (nothing spoke against it)

    @property
    def model(self):
        """A structure's `satmd.structure.StructureModel` (linear part and joint, SPEC §11), or None."""
        return getattr(self.nonlinear, "model", None)

    @property
    def effects(self) -> list:
        """The named physics (`EffectFinding`, most important first)."""
        return [j.finding for j in self.judged if j.status == "named"]

    @property
    def set_aside(self) -> dict:
        """{candidate: [Reason]} the search stretched past a plausible magnitude (those set aside because the
        data are nonlinear are told in the ``nonlinear`` block)."""
        return {j.name: list(j.reasons) for j in self.judged
                if j.status == "set_aside" and not any(r.kind in NONLINEAR_KINDS for r in j.reasons)}

    @property
    def withdrawn(self) -> list:
        """Candidates the search named before the model was found not to describe the data."""
        return [j.name for j in self.judged if j.status == "withdrawn"]

    @property
    def measurement(self) -> list:
        """SPEC §9 ``measurement``: the chain's findings, then each candidate the estimator or the noise could
        make (dicts: name, explanation, remedy, corrected)."""
        return list(self.notes) + [j.note for j in self.judged if j.status == "measurement" and j.note]

    def rejudged(self, applies_to, status: str, reasons, **changes) -> "DiscoveryReport":
        """The report with a later rule's verdict: each named candidate that ``applies_to(judged)`` picks gets
        ``status`` for ``reasons``; ``changes`` are the other fields that verdict changes.

        Parameters
        ----------
        applies_to : predicate on a named `Judged` (True: the rule applies to it).
        status : one of `findings.STATUSES`.
        reasons : the `Reason` objects of the verdict.
        **changes : other fields of the report to set alongside (``nonlinear``, ``adequacy``, ...).

        Returns
        -------
        DiscoveryReport
        """
        from dataclasses import replace

        judged = tuple(j.judged(status, reasons) if j.status == "named" and applies_to(j) else j for j in self.judged)
        return replace(self, judged=judged, **changes)

    @property
    def model_adequate(self) -> bool:
        """False when the SATMD model, with any vocabulary effects, cannot describe the data (then no effects)."""
        return self.adequacy is None or bool(self.adequacy.adequate)

    @property
    def adequacy_reasons(self) -> list:
        """The evidence against the model (`Reason` objects; empty when adequate)."""
        return [] if self.adequacy is None else list(self.adequacy.reasons)

    def to_dict(self) -> dict:
        chain = {}
        if self.estimator:
            chain = {"estimator": {k: v for k, v in self.estimator.items() if k != "measurement"},
                     "measurement": [{k: m[k] for k in ("name", "explanation", "remedy")} for m in self.measurement]}
        return {
            "schema": SCHEMA,
            "significant_mismatch": bool(self.significant_mismatch),
            "noise": self.noise,
            "model_adequate": self.model_adequate,
            "adequacy_reasons": [r.to_dict() for r in self.adequacy_reasons],
            "mismatch_bands_hz": [[round(a, 4), round(b, 4)] for a, b in self.mismatch_bands_hz],
            "effects": [e.to_dict() for e in self.effects],
            "parameters": dict(self.parameters),
            "fit_before": dict(self.fit_before),
            "fit_after": dict(self.fit_after),
        } | chain | ({"nonlinear": self.nonlinear.to_dict()} if self.nonlinear is not None else {}) | (
            {"set_aside": [{"name": n, "reasons": [r.to_dict() for r in rs]} for n, rs in self.set_aside.items()]}
            if self.set_aside else {}) | (
            {"withdrawn": list(self.withdrawn)} if self.withdrawn else {})  # their reasons: adequacy_reasons

    def to_json(self, **kw) -> str:
        return json.dumps(self.to_dict(), **kw)

    @property
    def effect_names(self) -> list:
        return [e.name for e in self.effects]

    def report(self) -> str:
        noise = ("the std columns of the file" if self.noise == "given"
                 else "an estimate from the residual's roughness (no std in the file)")
        if self.estimator:
            from ..signal.estimate import describe_estimate

            noise = "the std of the FRF estimate (from the recording's own noise)"
            lines = ["[[Missing-physics discovery]]",
                     f"    from a recording: {describe_estimate(self)}"]
            lines += [f"    measurement: {m['name']}: {m['explanation']} (remedy: {m['remedy']})"
                      for m in self.measurement]
        else:
            lines = ["[[Missing-physics discovery]]"]
            lines += [f"    note: {m['name']}: {m['explanation']} (remedy: {m['remedy']})" for m in self.measurement]
        lines += [f"    noise model: {noise}",
                 f"    nominal fit: χ²_red = {self.fit_before['chi2_reduced']:.3g}, "
                 f"relative error {self.fit_before['rel_error']:.3g} "
                 f"(p = {self.p_values.get('global', float('nan')):.2g} globally, "
                 f"{self.p_values.get('band', float('nan')):.2g} in the worst band)"]
        if not self.model_adequate:
            assert self.adequacy is not None  # only an Adequacy says "not adequate"
            lines.append(f"    MODEL NOT ADEQUATE: {self.adequacy.summary}. No physics is named: the SATMD model, "
                         "with any vocabulary effects, does not describe these data.")
            lines += [f"      - {r.kind}: {r.message}" for r in self.adequacy_reasons  # the summary's said above
                      if r.message != self.adequacy.summary]
            if self.withdrawn:
                lines.append(f"    withdrawn: {', '.join(self.withdrawn)} (what the search fitted before the model was "
                             "found not to describe the data)")
            return self._with_nonlinear(lines)
        if not self.significant_mismatch:
            lines.append("    The nominal model fits within the noise: no missing physics is needed.")
            return self._with_nonlinear(lines)
        bands = ", ".join(f"{a:.1f}–{b:.1f} Hz" for a, b in self.mismatch_bands_hz) or "spread over the band"
        lines.append(f"    significant mismatch located at: {bands}")
        for i, e in enumerate(self.effects, 1):
            lines.append(f"  {i}. {e.name}: {e.explanation}")
            if e.equivalent:
                lines.append(f"     equally good explanations (|ΔBIC| < {MIN_DELTA_BIC:g}): {', '.join(e.equivalent)} "
                             "— these FRFs cannot tell them apart")
        for name, reasons in self.set_aside.items():
            why = "; ".join(r.message for r in reasons) or "stretched past a plausible magnitude"
            lines.append(f"    set aside: {name} improved the fit only when stretched ({why}); the nominal fit is "
                         "good and plausible, so it is not named")
        lines.append(f"    after: χ²_red = {self.fit_after['chi2_reduced']:.3g}, "
                     f"relative error {self.fit_after['rel_error']:.3g}")
        lines.append("    fitted free parameters: " + ", ".join(f"{k} = {v:.6g}" for k, v in self.parameters.items()))
        return self._with_nonlinear(lines)

    def _with_nonlinear(self, lines) -> str:
        if self.nonlinear is not None:
            lines = lines + [self.nonlinear.report()]
        return "\n".join(lines)

    def __str__(self):
        return self.report()

    def figure(self):
        """Measured vs nominal vs augmented FRFs and standardised residuals, bands shaded; for a structure whose
        joint was located (SPEC §11), the sensors with the joint, the evidence per place and the model's fit."""
        from ..plots import fit_figure

        joint = self._joint_finding()
        if joint is not None:
            return self._structure_figure(joint)

        data = self.nominal_fit.data
        curves = [("nominal model", self.nominal_fit.prediction().channels, {"color": "tab:orange", "lw": 1.0})]
        resid = [("nominal", self.nominal_fit.standardised_residuals(), {"color": "tab:orange", "lw": 0.8})]
        if self.final_fit is not None and self.final_fit is not self.nominal_fit:
            pred = dict(self.final_fit.prediction().channels)
            z = dict(self.final_fit.standardised_residuals())
            label = " + ".join(n for n in self.effect_names if n != UNEXPLAINED) or "model"
            if self.discrepancy is not None:
                sig = self.final_fit.sigma
                for c in self.final_fit.channels:
                    pred[c] = pred[c] + self.discrepancy.correction[c]
                    z[c] = z[c] + self.discrepancy.correction[c] / sig[c]
                label += " + smooth discrepancy"
            curves.append((f"with {label}", pred, {"color": "tab:blue", "lw": 1.2}))
            resid.append(("augmented", z, {"color": "tab:blue", "lw": 0.8}))
        title = ("discovery: " + (", ".join(self.effect_names) if self.effects else "no missing physics")
                 + f"  (χ²_red {self.fit_before['chi2_reduced']:.3g} → {self.fit_after['chi2_reduced']:.3g})")
        return fit_figure(data, curves, resid, bands=self.mismatch_bands_hz, title=title)

    def _joint_finding(self):
        """The ``joint`` finding of the nonlinear block (a structure's joint located among its sensors), or None."""
        found = [f for f in getattr(self.nonlinear, "findings", []) or [] if f.get("name") == "joint"]
        return found[0] if found and found[0].get("location") else None

    def _structure_figure(self, joint):
        from types import SimpleNamespace

        from ..structure.figures import draw_structure_discovery

        where = SimpleNamespace(location=joint["location"], between=tuple(joint["between"]), law=joint["law"],
                                detected=True)
        a, b = joint["between"]
        return draw_structure_discovery(where, self.model, title=f"discovery: a joint between {a} and {b} "
                                                                  f"({joint['law']}); not a SATMD rig")

    def plot(self, path):
        from ..plots import save

        return save(self.figure(), path)


def describe_effect(effect, rig, shifts: dict) -> str:
    """A found effect in plain words: what the effect says of itself, then what it moves."""
    text = effect.explain(rig)
    moved = [f"{k} {100 * s:+.2g} %" for k, s in shifts.items() if abs(s) > 1e-3]
    if moved:
        text += "; accounting for it moves " + ", ".join(moved)
    return text


def describe_unexplained(bands_hz, structured_fraction: float, n_terms: int) -> str:
    """The ``unexplained`` verdict in plain words, from the numbers of the finding."""
    bands = ", ".join(f"{a:.1f}–{b:.1f} Hz" for a, b in bands_hz) or "the whole band"
    kind = "mostly structured" if structured_fraction > 0.5 else "mostly sharp or noise-like"
    return (f"significant mismatch remains at {bands} that no vocabulary effect explains; a smooth data-driven "
            f"correction removes {100 * structured_fraction:.0f} % of the remaining χ² ({n_terms} Chebyshev "
            f"terms), so the missing physics is {kind}")

"""Typed findings of a discovery: what was computed, apart from how it is told.

`discover` builds these from its fits; `report.py` only formats them. Each
finding's ``to_dict()`` is its entry in the SPEC §9 ``effects`` list.
"""
from __future__ import annotations

from dataclasses import dataclass, field

UNEXPLAINED = "unexplained"  # the report's verdict when no vocabulary effect explains the mismatch

_SCHEMA_KEYS = ("name", "parameters", "equivalent", "delta_bic", "explanation")


@dataclass(frozen=True)
class EffectFinding:
    """One effect found in the data (or the ``unexplained`` verdict).

    Parameters
    ----------
    name : effect name as in SPEC §8, e.g. ``"extra_mode"``.
    parameters : fitted values of the effect's own parameters.
    equivalent : other effects that explain the data as well (|ΔBIC| < `MIN_DELTA_BIC`).
    delta_bic : how much BIC rises when the effect is removed.
    explanation : the finding in plain words (written by ``report.py`` from the numbers here).
    shifts : relative change of each free parameter when the effect is accounted for.
    """

    name: str
    parameters: dict
    equivalent: list
    delta_bic: float
    explanation: str
    shifts: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The SPEC §9 entry: name, parameters, equivalent, delta_bic, explanation."""
        return {"name": self.name, "parameters": dict(self.parameters), "equivalent": list(self.equivalent),
                "delta_bic": self.delta_bic, "explanation": self.explanation}

    def __getitem__(self, key: str):
        # read access by the JSON keys, as when effects were plain dicts (satmd <= 0.1)
        if key not in _SCHEMA_KEYS:
            raise KeyError(key)
        return getattr(self, key)


@dataclass(frozen=True)
class UnexplainedFinding(EffectFinding):
    """Significant mismatch that no vocabulary effect explains, with what a smooth correction made of it.

    Parameters
    ----------
    bands_hz : where the mismatch remains after the best vocabulary model.
    structured_fraction : share of the remaining χ² a smooth data-driven correction removes.
    n_terms : Chebyshev terms the correction kept, over all channels.
    """

    bands_hz: list = field(default_factory=list)
    structured_fraction: float = 0.0
    n_terms: int = 0


_NONLINEAR_KEYS = ("name", "between", "location", "law", "parameters", "ci95", "equivalent", "equivalent_linear",
                   "character", "modes", "explanation", "moving", "direction", "fit")


@dataclass(frozen=True)
class NonlinearFinding:
    """One finding of the ``nonlinear`` block (SPEC §9): a named element, or ``nonlinear_unexplained``.

    Parameters
    ----------
    name : an element's SPEC §8b name, or ``nonlinear_unexplained``.
    parameters, ci95 : the element's fitted coefficients and their 95 % intervals.
    equivalent : elements (or moving parameters) the data cannot tell from this one.
    equivalent_linear : {linear parameter: value per level} (or a one-mode reading per level).
    explanation : the finding in words.
    moving, direction : the linear parameter that moves with level and which way (named elements).
    character : hardening / softening / level-dependent damping (a generic system).
    modes : per resonance, how it changes with level (a structure the SATMD model cannot describe).
    between, location, law : a structure's joint (``name`` ``joint``, SPEC §11): the two sensors (or a sensor
        and ``ground``) it acts between, every place ranked by ΔBIC, and its law.
    fit : the joint's model against the linear one, NRMSE per recording and channel (SPEC §11).

    Read access by the JSON keys (``finding["name"]``, ``finding.get("modes")``) is kept, as for
    `EffectFinding`; the optional fields that are None are absent there.
    """

    name: str
    parameters: dict = field(default_factory=dict)
    ci95: dict = field(default_factory=dict)
    equivalent: list = field(default_factory=list)
    equivalent_linear: dict = field(default_factory=dict)
    explanation: str = ""
    moving: str | None = None
    direction: str | None = None
    character: str | None = None
    modes: list | None = None
    between: list | None = None
    location: list | None = None
    law: str | None = None
    fit: dict | None = None

    def to_dict(self) -> dict:
        """The SPEC §9 entry (the optional fields when set)."""
        return {k: getattr(self, k) for k in _NONLINEAR_KEYS if getattr(self, k) is not None}

    def __getitem__(self, key: str):
        if key not in _NONLINEAR_KEYS or getattr(self, key) is None:
            raise KeyError(key)
        return getattr(self, key)

    def __contains__(self, key) -> bool:
        return key in _NONLINEAR_KEYS and getattr(self, key) is not None

    def get(self, key: str, default=None):
        """The value of a JSON key, or ``default`` when it is absent."""
        return self[key] if key in self else default


#: What became of a candidate (SPEC §9): ``named`` physics; ``set_aside`` (the search stretched it, or the data
#: are nonlinear and it stands in for that); ``measurement`` (the estimator or the noise could make it);
#: ``withdrawn`` (named, then the model was found not to describe the data at all).
STATUSES = ("named", "set_aside", "measurement", "withdrawn")

#: Reason kinds that set a candidate aside because the data are nonlinear (told in the ``nonlinear`` block).
NONLINEAR_KINDS = ("distortion", "level_dependence")


@dataclass(frozen=True)
class Judged:
    """One candidate of a discovery and the verdict on it: every candidate ends here, with one status.

    Parameters
    ----------
    name : the candidate's name (an effect of SPEC §8, or ``unexplained``).
    status : one of `STATUSES`.
    reasons : `Reason` objects saying why it is not named (empty when named).
    finding : what the candidate says of the data (None for a candidate the search set aside unfitted).
    note : the ``measurement`` entry (name, explanation, remedy, corrected) when the status is ``measurement``.
    """

    name: str
    status: str = "named"
    reasons: tuple = ()
    finding: EffectFinding | None = None
    note: dict | None = None

    def __post_init__(self):
        if self.status not in STATUSES:
            raise ValueError(f"status {self.status!r}: one of {', '.join(STATUSES)}")
        if self.status != "named" and not self.reasons:
            raise ValueError(f"{self.name}: a candidate that is not named needs a reason")

    def judged(self, status: str, reasons) -> "Judged":
        """The same candidate under another verdict."""
        from dataclasses import replace

        return replace(self, status=status, reasons=tuple(reasons))

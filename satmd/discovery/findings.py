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

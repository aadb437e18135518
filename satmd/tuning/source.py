"""What `satmd.tune` tunes: a Rig, a FitResult or a DiscoveryReport resolved to one model (`ResolvedModel`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..conventions import DEFAULT_FREE
from ..errors import DataError
from ..physics.rig import Rig

RIG_FREE = DEFAULT_FREE  # what a Rig reports as its model parameters


@dataclass(frozen=True)
class ResolvedModel:
    """The model a tuning runs on, whatever it was given as.

    ``rig`` and ``effects`` are the model; ``source`` says in words where it came from;
    ``parameters`` are its reported values; ``uncertain`` is (names, values, covariance) of a fit
    (None for a Rig); ``notes`` are what the tuning report says about the model; ``span`` is the
    measured frequency range (lo, hi) in Hz, None for a Rig.
    """

    rig: Rig
    effects: tuple
    source: str
    parameters: dict
    uncertain: tuple | None = None
    notes: tuple = ()
    span: tuple | None = None

    def __iter__(self):
        """The fields in the order of the former 7-tuple (rig, effects, source, parameters, uncertain,
        notes, span), so ``rig, effects, ... = resolve_model(...)`` keeps working."""
        return iter((self.rig, list(self.effects), self.source, self.parameters, self.uncertain, list(self.notes),
                     self.span))


def model_verdict(model):
    """The adequacy verdict (`Adequacy`) a fit or discovery report carries; None for a Rig (a model by
    definition).

    Parameters
    ----------
    model : Rig, FitResult or DiscoveryReport

    Returns
    -------
    Adequacy or None
    """
    from ..discovery.report import DiscoveryReport
    from ..identification.result import FitResult

    if isinstance(model, DiscoveryReport):
        from ..identification.adequacy import Adequacy

        return model.adequacy if model.adequacy is not None else Adequacy(True)
    if isinstance(model, FitResult):
        return model.adequacy
    return None


def is_augmented(model) -> bool:
    """Whether ``model`` is a discovery report tuned on its augmented model (nominal + effects found).

    Parameters
    ----------
    model : Rig, FitResult or DiscoveryReport

    Returns
    -------
    bool
    """
    from ..discovery.report import DiscoveryReport

    final: Any = getattr(model, "final_fit", None)  # a FitResult
    return (isinstance(model, DiscoveryReport) and model.significant_mismatch and final is not None
            and final is not model.nominal_fit and bool(final.effects))


def resolve_model(model, effects=()) -> ResolvedModel:
    """The model to tune: a Rig as given, a fit at its values, a discovery report's augmented or nominal fit.

    Parameters
    ----------
    model : Rig, FitResult or DiscoveryReport
    effects : effects of the model when ``model`` is a Rig (refused otherwise)

    Returns
    -------
    ResolvedModel
    """
    from ..identification.result import FitResult

    if isinstance(model, Rig):
        if model.batch_shape != ():
            raise DataError("tune takes a single rig, not a batch")
        model.validate()
        params = {k: float(getattr(model, k)) for k in RIG_FREE}
        return ResolvedModel(model, tuple(effects), "the given rig", params)
    if effects:
        raise DataError("effects= is for a Rig model; a fit or discovery report carries its own effects")
    notes: list = []
    fit, source = _from_report(model, notes)
    if fit is None:
        if not isinstance(model, FitResult):
            raise DataError(f"model must be a Rig, a FitResult or a DiscoveryReport, got {type(model).__name__}")
        fit, source = model, "identified model"
    f = fit.freq_hz
    notes.append(f"model identified from {len(f)} points over {f[0]:.1f}–{f[-1]:.1f} Hz; the current setting is "
                 "the identified one")
    return ResolvedModel(fit.rig, tuple(fit.effects), source, {k: float(v) for k, v in fit.values.items()},
                         (tuple(fit.names), fit.theta, np.asarray(fit.covariance)), tuple(notes),
                         (float(f[0]), float(f[-1])))


def _from_report(model, notes: list):
    """(fit, source) of a DiscoveryReport, its notes appended to ``notes``; (None, '') for anything else."""
    from ..discovery.findings import UNEXPLAINED
    from ..discovery.report import DiscoveryReport

    if not isinstance(model, DiscoveryReport):
        return None, ""
    fit = model.final_fit if model.final_fit is not None else model.nominal_fit
    found = [e["name"] for e in model.effects if e["name"] != UNEXPLAINED]
    if model.significant_mismatch and found:
        source = f"augmented model (nominal + {', '.join(found)}): discovery found a significant mismatch"
        notes.append(f"tuned on the augmented model: {source.split(': ', 1)[1]} and modelled it with "
                     f"{', '.join(found)}")
    elif model.significant_mismatch:
        fit, source = model.nominal_fit, "nominal model (a significant mismatch was found but not explained)"
    else:
        source = "nominal model (discovery found no significant mismatch)"
    if UNEXPLAINED in model.effect_names:
        notes.append("part of the mismatch is unexplained by the vocabulary: the tuning cannot account for it")
    nl = getattr(model, "nonlinear", None)
    if nl is not None and nl.detected:  # a linear design at one level; the levels call for tune_nonlinear
        named = [f["name"] for f in nl.findings if f.get("parameters")]
        how = (f"tune across the drive levels with the named element: satmd.tuning.nonlinear.tune_nonlinear "
               f"(satmd tune ... --nonlinear {named[0]} --levels ...)" if named else
               "record the rig at the drive levels it will see and name the element before tuning across them")
        notes.append(f"discovery detected nonlinearity: this linear design holds at the level of the data it was "
                     f"fitted to only; {how}")
    return fit, source

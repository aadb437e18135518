"""`satmd.tune`: from a model of the rig (a Rig, a fit, a discovery report) to the best setting.

`tune` takes flat keywords (one validated table, `TUNE_CONSTRAINTS`) and runs in steps, each on a
small frozen object: the model resolved (`ResolvedModel`, `satmd.tuning.source`), the problem set up
(`TuneProblem`: objective, search box, current setting), the nominal search (`SearchPlan`), robust
tuning (`Robustness`), then the notes and the result. Adding an option means one keyword in the
signature, one entry in the table and its use in the step it concerns.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Sequence

import numpy as np

from ..errors import DataError, renamed_keyword
from ..physics.effects import Effect
from ..physics.rig import Rig
from ..validation import NAMES, Band, Interval, Options, SequenceOf, Whole, validate_params
from .laws import OPEN_CIRCUIT_R, closed_forms
from .objective import OBJECTIVES, OUTPUTS, Objective
from .optimiser import DesignSpace, Minimum, minimise
from .result import TuneResult, db
from .robust import make_draws, robust_optimum
from .source import RIG_FREE, ResolvedModel, is_augmented, model_verdict, resolve_model
from ..conventions import PAPER_BAND_HZ

__all__ = ["tune", "TUNE_CONSTRAINTS", "Robustness", "SearchPlan", "TuneProblem", "ResolvedModel",
           "resolve_model", "model_verdict", "RIG_FREE", "DEFAULT_BAND"]

DEFAULT_BAND = PAPER_BAND_HZ


#: What every keyword of `tune` may be (`satmd.validation`); the model itself is checked by `resolve_model`.
TUNE_CONSTRAINTS = {
    "objective": [Options(OBJECTIVES)],
    "output": [Options(OUTPUTS)],
    "band_hz": [Band()],
    "band": [None, Band()],
    "bounds": [None, dict],
    "design": [NAMES],
    "robust": [bool],
    "quantile": [Interval(Real, 0.5, 1, "hi")],
    "effects": [SequenceOf(Effect)],
    "current": [None, dict],
    "uncertainty": [None, dict],
    "n_draws": [Interval(Whole, 1)],
    "n_search": [None, Interval(Whole, 0)],
    "n_starts": [Interval(Whole, 0)],
    "closed_form_check": [bool],
    "seed": [Interval(Integral, 0)],
    "force": [bool],
}


@dataclass(frozen=True)
class Robustness:
    """Robust tuning: minimise the ``quantile`` of the objective over ``n_draws`` parameter draws.

    ``uncertainty`` ({parameter: standard deviation}) overrides the fit's covariance.
    """

    quantile: float = 0.95
    uncertainty: dict | None = None
    n_draws: int = 128


@dataclass(frozen=True)
class SearchPlan:
    """The nominal search: ``n_search`` Sobol points, ``n_starts`` local runs, ``seed``."""

    n_search: int
    n_starts: int
    seed: int

    @classmethod
    def make(cls, n_search: int | None, n_starts: int, seed: int, objective: str, dim: int) -> "SearchPlan":
        """The plan, ``n_search`` defaulting to 512·2^(dim−1) points for H∞, half that for H2, at most 4096.

        Parameters
        ----------
        n_search : Sobol points, or None for the default
        n_starts : local Nelder–Mead runs
        seed : seed of the Sobol design
        objective : "hinf" or "h2"
        dim : number of design variables

        Returns
        -------
        SearchPlan
        """
        if n_search is None:  # the H2 surface is smooth (no ridges): half the points find its basin
            n_search = min(4096, (512 if objective == "hinf" else 256) * 2 ** (dim - 1))
        return cls(int(n_search), n_starts, seed)


@dataclass(frozen=True)
class TuneProblem:
    """What is searched: the resolved model, the objective, the design box and the current setting."""

    model: ResolvedModel
    obj: Objective
    space: DesignSpace
    now: dict  # the current setting {name: value}
    current_rig: Rig

    @property
    def rig(self) -> Rig:
        """The nominal rig."""
        return self.model.rig

    @property
    def effects(self) -> list:
        """The nominal model's effects."""
        return list(self.model.effects)

    def value(self, x) -> float:
        """The objective at design values ``x`` (in ``space.names`` order).

        Parameters
        ----------
        x : design values

        Returns
        -------
        float
        """
        return float(self.obj(self.space.apply(self.rig, x), self.effects)[0])


@validate_params(TUNE_CONSTRAINTS)
def tune(
    model,
    objective: str = "hinf",
    output: str = "u1",
    band_hz: tuple[float, float] = DEFAULT_BAND,
    bounds: dict | None = None,
    design: Sequence[str] = ("R", "L"),
    robust: bool = False,
    quantile: float = 0.95,
    *,
    band: tuple[float, float] | None = None,
    effects: Sequence[Effect] = (),
    current: dict | None = None,
    uncertainty: dict | None = None,
    n_draws: int = 128,
    n_search: int | None = None,
    n_starts: int = 3,
    closed_form_check: bool = True,
    seed: int = 0,
    force: bool = False,
) -> TuneResult:
    """Best setting of the design variables (the shunt's R and L by default).

    Parameters
    ----------
    model : Rig, FitResult or DiscoveryReport
        The rig to tune. A FitResult is tuned at its fitted values (and its
        covariance serves robust tuning); a DiscoveryReport on its augmented
        model (nominal + the effects found) when it found a significant
        mismatch, else on the nominal fit.
    objective : "hinf" (the true peak of |output| over the band) or "h2"
        (its RMS over the band)
    output : "u1" (primary displacement) or "a1" (primary acceleration as measured)
    band_hz : (lo, hi) in Hz (``band=``, its former name, still works and warns)
    bounds : {name: (lo, hi)}; defaults R ∈ [0.1, 1000] Ω, L ∈ [1e-3, 5] H,
        others a decade either side of the current value. Searched in log space.
    design : rig fields to design (any of R, L, kp, cp, m2, ...)
    robust : minimise the ``quantile`` of the objective over draws of the
        uncertain parameters (fit covariance, or ``uncertainty``) instead of
        the nominal objective
    quantile : the quantile minimised by robust tuning (default 0.95)
    band : the former name of ``band_hz`` (deprecated: it warns)
    effects : effects of the model when ``model`` is a Rig
    current : the current setting {name: value} (default: the model's values)
    uncertainty : {parameter: standard deviation}, independent Gaussian
        draws; overrides the fit covariance
    n_draws : draws for robust tuning (fixed draws: a deterministic objective)
    n_search : Sobol points of the global search (default 512·2^(D−1) for H∞, half that
        for H2, at most 4096)
    n_starts : local Nelder–Mead runs from the best distinct points
    closed_form_check : evaluate the classical closed forms on this rig
    seed : seeds the Sobol design and the draws
    force : tune even when the fit or discovery report says the SATMD model cannot describe the data
        (``model_adequate`` false); without it such a model is refused with a DataError

    Returns
    -------
    TuneResult
    """
    t0 = time.perf_counter()
    band_hz = renamed_keyword(band, band_hz, "tune")
    forced = _refuse_inadequate(model, force)
    resolved = resolve_model(model, effects)
    notes = list(resolved.notes)
    if forced:
        notes.append(f"tuned although the SATMD model cannot describe these data (forced): {forced}")
    problem = _set_up(resolved, Objective(objective, output, tuple(band_hz)), design, current, bounds, notes)
    plan = SearchPlan.make(n_search, n_starts, seed, objective, problem.space.dim)
    rob = Robustness(float(quantile), uncertainty, n_draws) if robust else None
    draws = make_draws(resolved.uncertain, rob.uncertainty, resolved.rig, problem.effects, problem.space.names,
                       rob.n_draws, seed) if rob else None
    best = _search_nominal(problem, plan)
    x, value, robust_summary, nfev = problem.space.values(best.u), float(np.exp(best.fun)), None, best.nfev
    if rob and draws is not None:
        x, robust_summary, n = robust_optimum(problem.obj, problem.space, problem.rig, problem.effects, draws,
                                              rob.quantile, [best.u, *best.starts[1:2]], problem.now, x)
        nfev += n
        value = problem.value(x)
        notes.append(f"robust: the setting minimises the {100 * rob.quantile:g} % quantile of the objective over "
                     f"{draws.n} draws; 'value' is the nominal model's at that setting")
    if is_augmented(model):  # what finding the left-out physics is worth here
        notes.append(_naive_note(model, problem, value, bounds, design, current, plan))
    hit = problem.space.on_bound(x)
    if hit:
        notes.append(f"{', '.join(hit)} ended on a bound of the search box: widen `bounds` to look further")
    forms = _closed_forms(problem, objective, value) if closed_form_check else ()
    return _result(problem, objective, output, x, value, forms, robust_summary, notes, nfev, t0)


def _refuse_inadequate(model, force: bool) -> str:
    """The inadequacy verdict's summary when the model is inadequate and forced ('' when adequate);
    a DataError when inadequate and not forced."""
    verdict = model_verdict(model)
    if verdict is None or verdict.adequate:
        return ""
    if not force:
        raise DataError(f"the SATMD model cannot describe these data: {verdict.summary}; not tuned "
                        "(force=True tunes anyway)")
    return verdict.summary


def _set_up(resolved: ResolvedModel, obj: Objective, design, current, bounds, notes: list) -> TuneProblem:
    """The problem: the current setting (the model's, or ``current``) and the design box; a note when the
    band reaches beyond the measured span."""
    span = resolved.span
    if span and (obj.band[0] < span[0] or obj.band[1] > span[1]):
        notes.append(f"the band {obj.band[0]:g}–{obj.band[1]:g} Hz reaches beyond the measured "
                     f"{span[0]:.1f}–{span[1]:.1f} Hz: the model extrapolates there")
    design = tuple(design)
    rig = resolved.rig
    now = {n: float(np.ravel(getattr(rig, n))[0]) for n in design if n in Rig.names()}
    if current:
        unknown = set(current) - set(design)
        if unknown:
            raise DataError(f"current setting given for {sorted(unknown)}, which are not design variables")
        now.update({k: float(v) for k, v in current.items()})
    space = DesignSpace.build(design, now, bounds)
    return TuneProblem(resolved, obj, space, now, rig.replace(**now))


def _search_nominal(problem: TuneProblem, plan: SearchPlan) -> Minimum:
    """The nominal objective minimised in log space, from the Sobol design and the current setting."""
    space, rig, effects, obj = problem.space, problem.rig, problem.effects, problem.obj

    def nominal_batch(u):
        return np.log(obj(space.apply(rig, space.values(u)), effects))

    def nominal_one(u):
        return float(np.log(obj(space.apply(rig, space.values(u)), effects)[0]))

    start_now = np.clip(space.unit([problem.now[n] for n in space.names]), 0, 1)
    return minimise(nominal_batch, nominal_one, space.dim, plan.n_search, plan.n_starts, plan.seed,
                    extra_starts=[start_now])


def _naive_note(model, problem: TuneProblem, value: float, bounds, design, current, plan: SearchPlan) -> str:
    """The setting tuned on the nominal model instead, and what it costs on the augmented one (a comparison:
    the nominal fit is tuned even when it alone does not describe the data, which the found physics explains)."""
    naive = tune(model.nominal_fit, problem.obj.kind, problem.obj.output, problem.obj.band, bounds, design,
                 current=current, n_search=plan.n_search, n_starts=plan.n_starts, closed_form_check=False,
                 seed=plan.seed, force=True)
    at_naive = problem.obj(problem.space.apply(problem.rig, [naive.design[n] for n in problem.space.names]),
                           problem.effects)[0]
    cost = db(float(at_naive) / value)
    return ("tuned on the nominal model instead, the setting would be "
            + ", ".join(f"{k} = {v:.4g}" for k, v in naive.design.items())
            + f": {cost:.2f} dB worse on the augmented model")


def _closed_forms(problem: TuneProblem, objective: str, value: float) -> tuple:
    """The classical closed forms that apply to this rig, each with its value and gap to the optimum."""
    forms = []
    for c in closed_forms(problem.rig, problem.effects, problem.space.names, objective, problem.obj.band):
        full = dict(problem.now, **c["design"])
        v = float(problem.obj(problem.rig.replace(**full), problem.effects)[0])
        forms.append({**c, "value": v, "gap_db": db(v / value)})
    return tuple(forms)


def _result(problem: TuneProblem, objective: str, output: str, x, value: float, forms: tuple,
            robust_summary, notes: list, nfev: int, t0: float) -> TuneResult:
    """The TuneResult at design values ``x``: current and open-circuit values, peaks, model, notes."""
    obj, space, rig, effects, resolved = problem.obj, problem.space, problem.rig, problem.effects, problem.model
    current_value = float(obj(problem.current_rig, effects)[0])
    open_value = float(obj(problem.current_rig.replace(R=OPEN_CIRCUIT_R), effects)[0])
    _, fpk, vpk = obj.evaluate(space.apply(rig, x), effects)
    peaks = tuple(sorted({round(float(f), 4) for f, v in zip(fpk[0], vpk[0]) if v >= 0.1 * vpk[0].max()}))
    return TuneResult(
        objective=objective, output=output, band_hz=obj.band, design=space.as_dict(x), value=value,
        current_design=dict(problem.now), current_value=current_value, open_circuit_value=open_value,
        bounds=space.bounds_dict(),
        model_parameters={k: v for k, v in resolved.parameters.items() if k not in space.names},
        model_effects=[{"name": e.name, "parameters": {k: float(v) for k, v in e.params.items()}} for e in effects],
        model_source=resolved.source, peaks_hz=peaks, closed_forms=forms, robust=robust_summary,
        notes=tuple(notes), nfev=int(nfev), wall_time=time.perf_counter() - t0, _rig=space.apply(rig, x),
        _current_rig=problem.current_rig, _effects=tuple(effects))

"""Model selection over the vocabulary: greedy forward steps, backward checks, swaps.

Every model is the nominal model with the free parameters (m2, kp, R, L by
default) plus a set of effects, fitted by `identify`. Models are compared by
BIC. An effect enters only when (i) the current model still fails the
calibrated mismatch test and (ii) it lowers BIC by more than
``min_delta_bic`` (10: "very strong" evidence on Kass & Raftery's scale).
After each step every earlier effect must still earn its place (backward
elimination), and each effect is swapped for every other candidate: a swap
that fits better is taken; one within ``min_delta_bic`` is reported as an
equivalent explanation, because FRFs alone cannot tell them apart.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..conventions import MIN_DELTA_BIC
from ..numerics import distinct_best
from ..identification import identify
from ..identification.problem import Problem
from ..io.frfdata import CHANNELS
from ..physics.effects import at_rest
from .candidates import candidate_starts

if TYPE_CHECKING:
    from ..identification import FitResult
    from ..io.frfdata import FRFData
    from ..physics import Rig



@dataclass
class Model:
    names: tuple  # effect names, in the order found
    effects: list  # fitted Effect objects
    fit: FitResult

    @property
    def bic(self):
        return self.fit.bic


@dataclass
class Search:
    data: FRFData
    rig: Rig | None
    base_free: tuple
    channels: tuple
    candidates: tuple
    cache: dict = field(default_factory=dict)  # frozenset(names) -> best Model found for that set
    tried: set = field(default_factory=set)  # (parent names, added name) already fitted
    log: list = field(default_factory=list)

    def options(self, model: Model):
        """The candidates ``model`` can grow by: not in it, and leaving the data a residual degree of freedom
        (a coarse FRF of a few lines cannot carry every effect's parameters; such a model is not fitted)."""
        n_lines = self.data.freq_hz.size
        for name in self.candidates:
            if name in model.names:
                continue
            if n_lines > len(self.free_names(list(model.effects) + [at_rest(name, self.rig)])):
                yield name

    def free_names(self, effects):
        return self.base_free + tuple(e.qualified(p) for e in effects for p in e.parameter_names if self.measured(p))

    def measured(self, param: str) -> bool:
        """False for an effect parameter of a channel that is not fitted (``gain_a2`` without a2): never fitted
        nor reported."""
        channel = param.rsplit("_", 1)[-1]
        return channel not in CHANNELS or channel in self.channels

    def fit(self, effects, starts) -> FitResult:
        problem = Problem(self.data, self.rig, self.free_names(effects), self.channels, effects)
        bounds = {n: (lo, hi) for n, lo, hi in zip(problem.names, problem.lower, problem.upper)}
        # a start taken from another fit may sit a rounding error outside a bound: bring it inside
        starts = [{k: float(np.clip(v, *bounds[k])) if k in bounds else v for k, v in s.items()} for s in starts]
        return identify(self.data, self.rig, self.free_names(effects), self.channels, effects, start=starts,
                        global_search=False, tol=1e-9, max_nfev=300, warn=False)

    def add(self, model: Model, name: str) -> Model:
        """Best fit of ``model`` plus effect ``name`` (screened starts, then least squares)."""
        key = frozenset(model.names + (name,))
        tried = (frozenset(model.names), name)  # another parent may lead to a better basin of the same set
        if tried in self.tried:
            return self.cache[key]
        self.tried.add(tried)
        new = at_rest(name, self.rig)
        effects = list(model.effects) + [new]
        problem = Problem(self.data, self.rig, self.free_names(effects), self.channels, effects)
        base = dict(model.fit.values)
        grid, n_refine = candidate_starts(new, model.fit, self.rig)
        thetas = np.array([[{**base, **{new.qualified(k): v for k, v in g.items()}}.get(n, np.nan)
                            for n in problem.names] for g in grid])
        thetas = np.clip(thetas, problem.lower, problem.upper)
        cost = problem.batch_cost(thetas)
        keep = _distinct_best(thetas, cost, problem.names, new, n_refine)
        starts = [dict(zip(problem.names, thetas[k])) for k in keep]
        fit = self.fit(effects, starts)
        fitted = [_with_values(e, fit.values) for e in effects]
        self.log.append((model.names + (name,), fit.bic))
        return self._keep(key, Model(model.names + (name,), fitted, fit))

    def remove(self, model: Model, name: str, nominal: Model) -> Model:
        """``model`` without effect ``name``, refitted from the current values."""
        keep = [(n, e) for n, e in zip(model.names, model.effects) if n != name]
        if not keep:
            return nominal
        key = frozenset(n for n, _ in keep)
        effects = [e for _, e in keep]
        start = {k: v for k, v in model.fit.values.items() if k in self.free_names(effects)}
        fit = self.fit(effects, [start])  # warm start from the larger model: often a better basin
        return self._keep(key, Model(tuple(n for n, _ in keep), [_with_values(e, fit.values) for e in effects], fit))

    def _keep(self, key, model: Model) -> Model:
        """Remember the best fit found so far for a set of effects."""
        old = self.cache.get(key)
        if old is None or model.bic < old.bic:
            self.cache[key] = model
        return self.cache[key]


def _with_values(effect, values):
    return effect.replace(**{p: values.get(effect.qualified(p), effect.params[p]) for p in effect.parameter_names})


def _distinct_best(thetas, cost, names, effect, k):
    """Indices of the k lowest-cost starts whose own effect parameters differ."""
    own = [i for i, n in enumerate(names) if n.startswith(effect.name + ".")]
    return distinct_best(cost, np.log(np.abs(thetas[:, own]) + 1e-30), k, 0.02)


def select(search: Search, nominal: Model, still_significant, max_effects: int = 3, beam: int = 3):
    """Beam search over effect sets, then backward elimination and swaps.

    A model may grow by one effect only while it still fails the calibrated
    mismatch test (``still_significant(fit)``) and only when the new effect
    lowers BIC by more than MIN_DELTA_BIC. The ``beam`` best models of each
    size are expanded, so a first effect that fits well alone but wrongly
    (a broad fake mode standing in for damping, say) cannot block the right
    pair. The answer is the model with the fewest effects among those reached
    within MIN_DELTA_BIC of the lowest BIC.
    """
    layer, reached = [nominal], [nominal]
    for _ in range(max_effects):
        grown: dict[frozenset, Model] = {}
        for parent in layer:
            if not still_significant(parent.fit):
                continue
            for c in search.options(parent):
                child = search.add(parent, c)
                if parent.bic - child.bic > MIN_DELTA_BIC:
                    key = frozenset(child.names)
                    if key not in grown or child.bic < grown[key].bic:
                        grown[key] = child
        if not grown:
            break
        layer = sorted(grown.values(), key=lambda m: m.bic)[:beam]
        reached += layer
    # parsimony: models within MIN_DELTA_BIC of the best explain the data as well; take the fewest effects
    lowest = min(m.bic for m in reached)
    best = min((m for m in reached if m.bic - lowest < MIN_DELTA_BIC), key=lambda m: (len(m.names), m.bic))
    if best.names:  # a swap, or a better basin found for a smaller set, can leave an effect without its place
        best = backward(search, _swaps(search, backward(search, best, nominal), nominal), nominal)
    return best


def backward(search, model, nominal):
    """Drop effects, one at a time, until each lowers BIC by more than MIN_DELTA_BIC against the model
    refitted without it."""
    changed = True
    while changed and model.names:
        changed = False
        for name in model.names:
            without = search.remove(model, name, nominal)
            if without.bic - model.bic <= MIN_DELTA_BIC:
                model, changed = without, True
                break
    return model


def _swaps(search, model, nominal):
    improved = True
    while improved:
        improved = False
        for name in model.names:
            rest = search.remove(model, name, nominal)
            for c in search.options(rest):
                if c in model.names:
                    continue
                alt = search.add(rest, c)
                if alt.bic < model.bic - 1e-6:
                    model, improved = alt, True
                    break
            if improved:
                break
    return model


def equivalents(search, model, nominal, limit: int = 3) -> dict:
    """For each effect of ``model``: other candidates explaining the data as well (|ΔBIC| < MIN_DELTA_BIC)."""
    out = {}
    for name in model.names:
        rest = search.remove(model, name, nominal)
        alts = []
        for c in search.options(rest):
            if c in model.names:
                continue
            alt = search.add(rest, c)
            if abs(alt.bic - model.bic) < MIN_DELTA_BIC:
                alts.append((alt.bic - model.bic, c))
        out[name] = [c for _, c in sorted(alts)[:limit]]
    return out

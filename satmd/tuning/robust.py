"""Parameter uncertainty for robust tuning: fixed draws (common random numbers) and quantiles.

The draws are made once (seeded), so the quantile objective is a
deterministic function of the design and Nelder–Mead sees no noise. Design
variables are not drawn: the user sets them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from ..errors import DataError
from ..physics.effects import Effect
from ..physics.model import resolve_parameter
from ..physics.rig import Rig


@dataclass(frozen=True)
class Draws:
    """Joint draws of uncertain model parameters: ``samples`` (S, P) for ``names``."""

    names: tuple
    samples: np.ndarray
    source: str  # where the uncertainty came from, in words

    @property
    def n(self) -> int:
        return self.samples.shape[0]

    def apply(self, rig: Rig, effects: Sequence[Effect]) -> tuple[Rig, list]:
        """The rig and effects as a batch of S (one row per draw)."""
        rig_changes, effects = {}, list(effects)
        for name, column in zip(self.names, self.samples.T):
            i, p = resolve_parameter(name, effects)
            if i < 0:
                rig_changes[p] = column
            else:
                effects[i] = effects[i].replace(**{p: column})
        return (rig.replace(**rig_changes) if rig_changes else rig), effects


def draws_from_covariance(names, mean, cov, exclude=(), n: int = 128, seed: int = 0,
                          source: str = "fit covariance") -> Draws:
    """Gaussian draws of the parameters not in ``exclude`` (their marginal distribution).

    Parameters
    ----------
    names, mean, cov : parameter names, values and covariance (physical units)
    exclude : names not drawn (the design variables)
    n : number of draws; seed : seed of the generator

    Returns
    -------
    Draws (values are kept > 0 for positive parameters by reflecting at 0)
    """
    cov = np.asarray(cov, float)
    keep = [i for i, name in enumerate(names) if name not in exclude]
    if not keep:
        raise DataError("robust tuning needs uncertain parameters besides the design variables "
                        f"(the model's free parameters are {', '.join(names)})")
    finite = [i for i in keep if np.isfinite(cov[i, i]) and cov[i, i] > 0]
    dropped = [names[i] for i in keep if i not in finite]
    if not finite:
        raise DataError("the fit gives no finite variance for "
                        f"{', '.join(names[i] for i in keep)}: robust tuning cannot use it")
    keep = finite
    mean = np.asarray(mean, float)[keep]
    cov = cov[np.ix_(keep, keep)]
    if not np.all(np.isfinite(cov)):
        raise DataError("the fit's covariance is not finite (a parameter is not identifiable): "
                        "robust tuning cannot use it")
    if dropped:
        source += f" ({', '.join(dropped)} held at their values: no finite variance)"
    rng = np.random.default_rng(seed)
    samples = rng.multivariate_normal(mean, cov, size=int(n), method="eigh")
    samples = np.where(mean > 0, np.abs(samples), samples)
    return Draws(tuple(names[i] for i in keep), samples, source)


def draws_from_std(std: dict, values: dict, n: int = 128, seed: int = 0) -> Draws:
    """Independent Gaussian draws.

    Parameters
    ----------
    std : {name: standard deviation}
    values : {name: mean}
    n, seed : number of draws, seed

    Returns
    -------
    Draws
    """
    names = tuple(std)
    mean = np.array([values[k] for k in names], float)
    cov = np.diag([float(std[k]) ** 2 for k in names])
    return draws_from_covariance(names, mean, cov, (), n, seed, source="given standard deviations")


def guaranteed_db(attenuation_db: np.ndarray, level: float, confidence: float = 0.9) -> float:
    """A conservative (1 − level) quantile of per-draw attenuations: the guaranteed attenuation.

    The k-th smallest of S draws lies below the true (1 − level) quantile with
    probability P(Binomial(S, 1 − level) ≥ k); the largest k with that
    probability ≥ ``confidence`` is used, so the figure holds for a fraction
    ``level`` of new draws with that confidence, not just on average.
    """
    from scipy.stats import binom

    a = np.sort(np.asarray(attenuation_db, float))
    s = a.size
    k = int(binom.ppf(1.0 - confidence, s, 1.0 - level))  # P(X >= k) >= confidence
    return float(a[max(k, 1) - 1])


def quantile_value(values, q: float) -> float:
    """The ``q`` quantile of ``values`` (linear interpolation)."""
    return float(np.quantile(np.asarray(values), q))


def robust_optimum(obj, space, rig: Rig, effects, draws: Draws, q: float, starts, current: dict, x_nominal):
    """Minimise the ``q`` quantile of the objective over fixed parameter draws.

    Parameters
    ----------
    obj : Objective
    space : DesignSpace of the design variables
    rig, effects : the nominal model
    draws : Draws of the uncertain parameters
    q : the quantile minimised
    starts : unit-cube points to start the local search from (the nominal optimum first)
    current : the current setting {name: value}
    x_nominal : the nominal optimum (design values), for comparison

    Returns
    -------
    (design values, summary dict for TuneResult.robust, function evaluations)
    """
    from .laws import OPEN_CIRCUIT_R
    from .optimiser import minimise

    d_rig, d_eff = draws.apply(rig, effects)

    def spread(values) -> np.ndarray:
        return obj(space.apply(d_rig, values), d_eff)

    def objective(u):
        return float(np.log(quantile_value(spread(space.values(u)), q)))

    best = minimise(None, objective, space.dim, extra_starts=starts)
    x = space.values(best.u)
    tuned, nominal = spread(x), spread(x_nominal)
    now = d_rig.replace(**current)
    at_current, at_open = obj(now, d_eff), obj(now.replace(R=OPEN_CIRCUIT_R), d_eff)
    summary = {
        "quantile": q, "n_draws": draws.n, "parameters": list(draws.names), "source": draws.source,
        "value_quantile": quantile_value(tuned, q),
        "nominal_optimum": {"design": space.as_dict(x_nominal), "value": float(obj(space.apply(rig, x_nominal),
                                                                                    effects)[0]),
                            "value_quantile": quantile_value(nominal, q)},
        "current_value_quantile": quantile_value(at_current, q),
        "guaranteed_attenuation_db": {"vs_current": guaranteed_db(20 * np.log10(at_current / tuned), q),
                                      "vs_open_circuit": guaranteed_db(20 * np.log10(at_open / tuned), q)},
    }
    return x, summary, best.nfev


def make_draws(uncertain, uncertainty, rig: Rig, effects, design, n: int, seed: int) -> Draws:
    """The draws of robust tuning: independent Gaussians from ``uncertainty``, else the fit's covariance.

    Parameters
    ----------
    uncertain : (names, values, covariance) of a fit, or None (a Rig)
    uncertainty : {parameter: standard deviation} or None; overrides ``uncertain``
    rig, effects : the nominal model (the means of ``uncertainty``'s parameters)
    design : the design variables (never drawn)
    n, seed : number of draws, seed

    Returns
    -------
    Draws
    """
    if uncertainty:
        values = {}
        for name in uncertainty:
            try:
                i, p = resolve_parameter(name, effects)
            except ValueError as exc:
                raise DataError(f"uncertainty: {exc}") from None
            if name in design:
                raise DataError(f"uncertainty given for design variable {name}")
            values[name] = float(getattr(rig, p)) if i < 0 else float(effects[i].params[p])
        return draws_from_std(uncertainty, values, n, seed)
    if uncertain is None:
        raise DataError("robust tuning needs parameter uncertainty: tune a FitResult (its covariance) "
                        "or pass uncertainty={name: std}")
    names, values, cov = uncertain
    return draws_from_covariance(names, values, cov, exclude=design, n=n, seed=seed)

"""Concealed-effect test cases: a seed picks a rig, an effect and a magnitude.

Used by the example, the tests and the benchmark to prove discovery on data
where the effect is concealed: the nominal model, refitted, still matches the
data to within a few times the noise, so an eye on the FRF plot sees nothing.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import SPEC_RANGES
from ..physics import Rig
from ..physics.effects import VOCABULARY_NAMES, Effect, effect
from ..simulation.frf import simulate

GRIDS = {"paper60": (40.0, 130.0, 60), "lin200": (30.0, 160.0, 200)}
NOISE = (0.01, 0.002)


@dataclass
class Scenario:
    data: object
    rig: Rig
    effects: list
    grid: str
    seed: int
    nominal_chi2_reduced: float = float("nan")
    detectable: bool = True  # the nominal model fails the χ² test (p < 1e-3) on these data

    @property
    def truth_names(self):
        return [e.name for e in self.effects]


def random_rig(rng) -> Rig:
    """Free parameters anywhere in the SPEC §9 ranges."""
    return Rig(**{name: rng.uniform(lo, hi) for name, (lo, hi) in SPEC_RANGES.items()})


def random_effect(name: str, rng, freq_hz):
    sign = rng.choice([-1.0, 1.0])
    if name == "sensor_gain":
        g1 = 1 + sign * rng.uniform(0.03, 0.08)
        g2 = g1 if rng.random() < 0.5 else 1 + rng.choice([-1.0, 1.0]) * rng.uniform(0.03, 0.08)
        return effect(name, gain_a1=g1, gain_a2=g2)
    if name == "time_delay":
        return effect(name, tau_s=rng.uniform(5e-5, 3e-4))
    if name == "structural_damping":
        return effect(name, eta=rng.uniform(0.01, 0.06))
    if name == "dielectric_loss":
        return effect(name, tan_delta=rng.uniform(0.04, 0.15))
    if name == "shunt_capacitance":
        return effect(name, Cs=rng.uniform(3e-6, 1.2e-5))
    if name == "extra_mode":
        lo, hi = freq_hz[0], freq_hz[-1]
        return effect(name, f_hz=rng.uniform(lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo)),
                      zeta=rng.uniform(0.003, 0.02), mass_ratio=rng.uniform(0.005, 0.02))
    p = name.split(":", 1)[1]
    nominal = float(getattr(Rig(), p))
    if p in ("c1", "cp"):
        factor = rng.uniform(2.0, 4.0) if sign > 0 else rng.uniform(0.1, 0.4)
    else:
        factor = 1 + sign * rng.uniform(0.08, 0.2) if p in ("e", "Cp") else 1 + sign * rng.uniform(0.03, 0.12)
    return effect(name, value=nominal * factor)


def concealed_case(seed: int, names=None, n_effects: int = 1, std_given: bool = True,
                   detectable: bool = True) -> Scenario:
    """A noisy dataset with ``n_effects`` random vocabulary effects (none if 0).

    With ``detectable`` the effects' magnitudes are scaled (by factors of 2)
    until the refitted nominal model is statistically wrong (χ²_red ≥ 1.5)
    yet still looks right to the eye (relative error ≤ 4 × the 1 % noise):
    concealed, but present in the data. Without it, magnitudes are as drawn.
    """
    rng = np.random.default_rng(seed)
    grid = str(rng.choice(list(GRIDS)))
    lo, hi, n = GRIDS[grid]
    freq = np.linspace(lo, hi, n)
    rig = random_rig(rng)
    pool = list(names or VOCABULARY_NAMES)
    picked: list[Effect] = []
    while len(picked) < n_effects:
        name = str(rng.choice(pool))
        kind = name.split(":")[0]
        if all(e.name.split(":")[0] != kind for e in picked):
            picked.append(random_effect(name, rng, freq))
    noise_seed = int(rng.integers(2**31))
    data = simulate(freq, rig, picked, noise=NOISE, seed=noise_seed)
    fits = _fits(data, picked)
    if detectable and picked:
        for _ in range(6):
            # each effect must show on top of the others (known), the whole still look fine to the eye
            nominal, without = fits
            weak = [f.chi2_reduced < 1.5 for f in without]
            if nominal.rel_error > 4 * NOISE[0]:
                picked = [scaled(e, 0.5) for e in picked]
            elif any(weak):
                picked = [scaled(e, 2.0) if w else e for e, w in zip(picked, weak)]
            else:
                break
            data = simulate(freq, rig, picked, noise=NOISE, seed=noise_seed)
            fits = _fits(data, picked)
    chi2_red, detectable = float("nan"), not picked
    if picked:
        from scipy import stats

        chi2_red = fits[0].chi2_reduced
        detectable = all(stats.chi2.sf(f.chi2, f.dof) < 1e-3 for f in fits[1])
    if not std_given:
        data = data.with_std({})
    return Scenario(data, rig, picked, grid, seed, chi2_red, detectable)


def _fits(data, effects):
    """The nominal fit, and for each effect the nominal fit with every other true effect included (with one
    effect, the nominal fit itself: fitted once)."""
    from ..identification import identify

    if not effects:
        return None, []
    nominal = identify(data, warn=False)
    return nominal, [nominal if len(effects) == 1 else _without(data, effects, i) for i in range(len(effects))]


def _without(data, effects, i):
    """Nominal fit with every true effect but the i-th included at its true value."""
    from ..identification import identify

    return identify(data, effects=[e for j, e in enumerate(effects) if j != i], warn=False)


REACH = 0.8  # share of the way from neutral to the edge of the search range a scaled effect may go


def scaled(eff, factor: float):
    """The effect with its departure from neutral multiplied by ``factor``, kept within `REACH` of the way to
    the edge of the effect's own search range (a magnitude discovery could not find is no test of it);
    a drawn value already further out stays where it is."""
    p = dict(eff.params)
    if eff.name == "sensor_gain":
        p = {k: 1 + factor * (v - 1) for k, v in p.items()}
    elif eff.name == "extra_mode":
        p["mass_ratio"] = p["mass_ratio"] * factor
    elif eff.name.startswith("parameter_offset:"):
        nominal = float(getattr(Rig(), eff.parameter))
        p["value"] = nominal * (1 + factor * (p["value"] / nominal - 1))
    else:
        p = {k: v * factor for k, v in p.items()}
    bounds = eff.bounds(Rig())
    for spec in eff.parameter_specs:
        neutral = float(getattr(Rig(), eff.parameter)) if eff.name.startswith("parameter_offset:") else spec.neutral
        if neutral is None or spec.name not in p:
            continue
        lo, hi = (neutral + REACH * (b - neutral) for b in bounds[spec.name])
        old = float(eff.params[spec.name])
        p[spec.name] = float(np.clip(p[spec.name], min(lo, old), max(hi, old)))
    return eff.replace(**p)


def judge(report, scenario: Scenario) -> bool:
    """The shared scorer's rule: same number of effects, each named or listed as equivalent,
    extra_mode within 5 % in frequency, and a good final fit when std was given."""
    truth = scenario.truth_names
    found = report.effects
    if not truth:
        return not report.significant_mismatch and not found
    if len(found) != len(truth):
        return False
    for e in scenario.effects:
        match = [r for r in found if r.name == e.name or e.name in r.equivalent]
        if not match:
            return False
        if e.name == "extra_mode" and match[0].name == "extra_mode":
            if abs(match[0].parameters["f_hz"] - e.params["f_hz"]) > 0.05 * e.params["f_hz"]:
                return False
    return report.noise != "given" or report.fit_after["chi2_reduced"] <= 1.5

"""The concealed-case generator never scales an effect out of the range discovery searches."""
import numpy as np
from hypothesis import given, settings, strategies as st

from satmd.discovery.scenarios import REACH, random_effect, scaled
from satmd.physics import Rig
from satmd.physics.effects import VOCABULARY_NAMES

FREQ = np.linspace(30.0, 160.0, 50)


def _neutral(eff, spec):
    return float(getattr(Rig(), eff.parameter)) if eff.name.startswith("parameter_offset:") else spec.neutral


@settings(max_examples=200, deadline=None)
@given(name=st.sampled_from(VOCABULARY_NAMES), seed=st.integers(0, 2**31), doublings=st.integers(1, 6))
def test_scaling_up_stays_within_reach_of_the_search_range(name, seed, doublings):
    eff = random_effect(name, np.random.default_rng(seed), FREQ)
    big = eff
    for _ in range(doublings):
        big = scaled(big, 2.0)
    bounds = eff.bounds(Rig())
    for spec in eff.parameter_specs:
        neutral = _neutral(eff, spec)
        if neutral is None:
            continue
        lo, hi = (neutral + REACH * (b - neutral) for b in bounds[spec.name])
        drawn, v = float(eff.params[spec.name]), float(big.params[spec.name])
        assert min(lo, drawn) - 1e-12 * abs(drawn) <= v <= max(hi, drawn) + 1e-12 * abs(drawn), (spec.name, drawn, v)
        # scaling up never shrinks the departure from neutral
        assert abs(v - neutral) >= abs(drawn - neutral) * (1 - 1e-12) or abs(v - neutral) >= abs(lo - neutral) * (1 - 1e-12)


def test_a_weak_dielectric_loss_doubled_three_times_stops_short_of_its_search_edge():
    from satmd.physics.effects import effect

    eff = scaled(scaled(scaled(effect("dielectric_loss", tan_delta=0.12), 2.0), 2.0), 2.0)
    assert eff.params["tan_delta"] == REACH * 0.5  # 0.96 unscaled; the search range ends at 0.5

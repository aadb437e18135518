"""What each effect declares about itself (parameters as data, search starts, words) is consistent."""
import numpy as np
import pytest

from satmd.physics import CHANNELS, PAPER_GRID_HZ, Rig, frf
from satmd.physics.effects import VOCABULARY_NAMES, at_rest, effect, registered_names

RIG = Rig()


@pytest.mark.parametrize("name", VOCABULARY_NAMES)
def test_at_rest_is_the_base_model(name):
    base = frf(PAPER_GRID_HZ, RIG)
    got = frf(PAPER_GRID_HZ, RIG, [at_rest(name, RIG)])
    for ch in CHANNELS:
        np.testing.assert_allclose(getattr(got, ch), getattr(base, ch), rtol=1e-14, atol=0)


@pytest.mark.parametrize("name", VOCABULARY_NAMES)
def test_declared_starts_lie_in_the_search_bounds(name):
    eff = at_rest(name, RIG)
    bounds = eff.bounds(RIG)
    starts = eff.starts(RIG)
    assert starts or eff.scan is not None  # every effect says where a fit starts
    for s in starts:
        assert set(s) == set(eff.parameter_names)
        for p, v in s.items():
            assert bounds[p][0] <= v <= bounds[p][1], (name, p, v)
    if eff.scan is not None:
        declared = {eff.scan.location, eff.scan.amplitude, *eff.scan.shapes}
        assert declared == set(eff.parameter_names)
        assert eff.scan.amplitude in eff.neutral


@pytest.mark.parametrize("name", VOCABULARY_NAMES)
def test_a_fitted_effect_explains_itself_in_one_line(name):
    eff = at_rest(name, RIG)
    bounds = eff.bounds(RIG)
    fitted = eff.replace(**{p: lo + 0.3 * (hi - lo) for p, (lo, hi) in bounds.items()})
    text = fitted.explain(RIG)
    assert text and "\n" not in text


def test_the_registry_spells_out_every_name():
    assert registered_names()[:len(VOCABULARY_NAMES)] == VOCABULARY_NAMES
    assert all(effect(n, **{p: v for p, v in at_rest(n, RIG).params.items()}).name == n for n in VOCABULARY_NAMES)

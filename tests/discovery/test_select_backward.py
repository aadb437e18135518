"""Backward elimination: every effect of the selected model earns its place, the last one found too."""
from types import SimpleNamespace

from satmd.conventions import MIN_DELTA_BIC
from satmd.discovery.select import Model, backward


class _Search:
    """Refits without an effect give the BIC in ``bic_without`` (by the set of names left)."""

    def __init__(self, bic_without):
        self.bic_without = bic_without

    def remove(self, model, name, nominal):
        rest = tuple(n for n in model.names if n != name)
        return nominal if not rest else Model(rest, [None] * len(rest), SimpleNamespace(bic=self.bic_without[rest]))


def test_the_last_effect_found_is_checked_too():
    nominal = Model((), [], SimpleNamespace(bic=1000.0))
    model = Model(("a", "b"), [None, None], SimpleNamespace(bic=500.0))
    # without a: far worse; without b (the last found): within MIN_DELTA_BIC, as a better basin can leave it
    search = _Search({("b",): 900.0, ("a",): 500.0 + MIN_DELTA_BIC / 2})
    assert backward(search, model, nominal).names == ("a",)


def test_effects_that_earn_their_place_stay():
    nominal = Model((), [], SimpleNamespace(bic=1000.0))
    model = Model(("a", "b"), [None, None], SimpleNamespace(bic=500.0))
    search = _Search({("b",): 900.0, ("a",): 500.0 + 3 * MIN_DELTA_BIC})
    assert backward(search, model, nominal).names == ("a", "b")

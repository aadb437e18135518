"""A new effect is one class: registered from this file alone, discovery considers it and finds it."""
import numpy as np
import pytest

from satmd import discover, simulate
from satmd.physics.effects import Effect, Parameter, register, registered_names, unregister


class PiezoLeak(Effect):
    """A toy effect outside the SPEC vocabulary: a leakage conductance G across the piezo,
    so its admittance iωCp becomes iωCp + G, i.e. Cp -> Cp - iG/ω."""

    name = "piezo_leak"
    parameter_specs = (Parameter("G", "S", default=0.0, neutral=0.0, hard=(0.0, 1.0), search=(0.0, 1e-2),
                                 starts=(1e-5, 1e-4, 1e-3)),)
    description = "a leakage conductance across the piezo"
    acts_on = "piezo"

    def capacitance(self, omega, rig, Cp):
        return Cp - 1j * self.params["G"] / omega

    def explain(self, rig):
        return f"the piezo leaks through {1 / self.params['G']:.3g} Ω"


@pytest.fixture
def piezo_leak():
    register(PiezoLeak)
    yield PiezoLeak
    unregister(PiezoLeak.name)


def test_registered_effect_is_a_candidate_and_is_found(piezo_leak):
    assert "piezo_leak" in registered_names()
    data = simulate(np.linspace(30, 160, 200), effects=[piezo_leak(G=5e-4)], noise=(0.01, 0.002), seed=3)
    rep = discover(data)
    assert rep.significant_mismatch and rep.effect_names == ["piezo_leak"]
    found = rep.effects[0]
    assert found.parameters["G"] == pytest.approx(5e-4, rel=0.2)
    # the explanation is the effect's own, with the numbers of the fit
    assert found.explanation.startswith(f"the piezo leaks through {1 / found.parameters['G']:.3g} Ω")
    assert rep.to_dict()["effects"][0]["name"] == "piezo_leak"


def test_unregistered_effect_is_gone(piezo_leak):
    unregister("piezo_leak")
    assert "piezo_leak" not in registered_names()
    register(piezo_leak)  # the fixture removes it again


def test_register_refuses_a_taken_name(piezo_leak):
    with pytest.raises(ValueError):
        register(piezo_leak)

"""The matched-filter scan's Jacobian by the chain rule through the model's intermediates equals frf's."""
from types import SimpleNamespace

import numpy as np
import pytest

from satmd import effect
from satmd.discovery.candidates import amplitude_jacobian, matched_filter
from satmd.physics import Rig, frf
from satmd.physics.effects import at_rest

FREQ = np.linspace(5.0, 300.0, 400)


def _fit(effects=()):
    return SimpleNamespace(freq_hz=FREQ, rig=Rig(m2=0.6, kp=1.3e5), effects=list(effects), channels=("a1", "a2"))


def _direct(fit, trial, amplitude):
    r = frf(FREQ, fit.rig, list(fit.effects) + [trial], wrt=[trial.qualified(amplitude)], outputs=fit.channels)
    return {c: r.jac[c][..., 0].reshape(-1, FREQ.size) for c in fit.channels}


@pytest.mark.parametrize("name, param", [
    ("time_delay", "tau_s"), ("sensor_gain", "gain_a1"), ("structural_damping", "eta"),
    ("dielectric_loss", "tan_delta"), ("shunt_capacitance", "Cs"), ("parameter_offset:k1", "value"),
    ("parameter_offset:Cp", "value")])
def test_chain_rule_equals_frf_jacobian(name, param):
    """At the effect's neutral value (where it leaves the model as it is), as the scan uses it."""
    fit = _fit([effect("sensor_gain", gain_a1=0.97, gain_a2=1.02), effect("time_delay", tau_s=1e-4)]
               if name not in ("sensor_gain", "time_delay") else [effect("extra_mode", f_hz=90.0, zeta=0.01,
                                                                           mass_ratio=0.01)])
    trial = at_rest(name, fit.rig)
    got, want = amplitude_jacobian(fit, trial, param), _direct(fit, trial, param)
    for c in fit.channels:
        assert np.allclose(got[c], want[c], rtol=1e-10, atol=1e-12 * np.abs(want[c]).max())


def test_scan_batch_equals_frf_and_finds_the_mode():
    truth = effect("extra_mode", f_hz=123.0, zeta=0.01, mass_ratio=0.002)
    new = at_rest("extra_mode", Rig())
    fit = _fit()
    trial = new.replace(f_hz=np.array([40.0, 123.0, 250.0])[:, None], zeta=np.array([0.002, 0.01, 0.05])[:, None])
    got, want = amplitude_jacobian(fit, trial, "mass_ratio"), _direct(fit, trial, "mass_ratio")
    for c in fit.channels:
        assert np.allclose(got[c], want[c], rtol=1e-10, atol=1e-12 * np.abs(want[c]).max())
    data = frf(FREQ, fit.rig, [truth], outputs=fit.channels)
    model = frf(FREQ, fit.rig, outputs=fit.channels)
    sigma = {c: np.full(FREQ.size, 1e-3) for c in fit.channels}
    fit.residuals = lambda: {c: model.channel(c) - data.channel(c) for c in fit.channels}
    fit.sigma = sigma
    best = matched_filter(new, fit)[0]
    assert abs(best["f_hz"] / 123.0 - 1) < 0.02  # a start, refined by least squares later

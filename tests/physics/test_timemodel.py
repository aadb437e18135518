"""The one time-model protocol (issue 36 item 4): every model a recorder drives answers `respond`."""
import numpy as np
import pytest

from satmd.physics import Rig, effect
from satmd.physics.nonlinear.excitation import random_force
from satmd.physics.oscillator import PolynomialOscillator
from satmd.physics.timemodel import LinearRig, NonlinearRig, TimeModel

FS = 2048.0


def _force(seconds=8.0, seed=0):
    return random_force(int(seconds * FS), FS, (20.0, 200.0), np.random.default_rng(seed))


def test_every_time_model_follows_the_protocol():
    models = [LinearRig(Rig()), NonlinearRig(Rig(), (effect("quadratic_damping", c2=2.0),)),
              PolynomialOscillator(k=(2 * np.pi * 50) ** 2, c=10.0, k3=1e6)]
    force = _force(2.0)
    for model in models:
        assert isinstance(model, TimeModel)
        out = model.respond(force, FS)
        assert "force" in out and all(np.shape(v) == force.shape and np.all(np.isfinite(v)) for v in out.values())


@pytest.mark.parametrize("elements", [(), (effect("cubic_absorber_spring", k3=0.0),)])
def test_the_convolution_and_the_integrator_agree_in_the_linear_limit(elements):
    """Two independent routes to the SPEC §2 response (impulse response by FFT; exact discretisation with a
    first-order hold, at 4x and 8x extrapolated with an element of no strength), one force: within 0.1 % RMS."""
    rig = Rig(m2=0.6, kp=1.2e5, R=40.0, L=0.09)
    linear = LinearRig(rig).respond(_force(), FS)
    other = NonlinearRig(rig, elements).respond(linear["force"], FS)  # the force as the convolution rolled it off
    for ch in ("acc1", "acc2"):
        rel = np.sqrt(np.mean((linear[ch] - other[ch]) ** 2) / np.mean(other[ch] ** 2))
        assert rel < 1e-3, (ch, rel)


def test_a_wrong_rig_is_told_apart():
    """The agreement above is not loose: a 1 % change of kp moves the response by far more than 0.1 %."""
    force = LinearRig(Rig()).respond(_force(), FS)["force"]
    a = NonlinearRig(Rig()).respond(force, FS)["acc2"]
    b = NonlinearRig(Rig(kp=Rig().kp * 1.01)).respond(force, FS)["acc2"]
    assert np.sqrt(np.mean((a - b) ** 2) / np.mean(a ** 2)) > 1e-2


def test_the_hold_error_is_extrapolated_away():
    """Richardson between 4x and 8x is far nearer the 64x integration than 8x alone (a hardening spring at
    2e9, 10 N RMS), where the fit judges (after 2 s, before the last 0.5 s: the interpolation's ends aside)."""
    from satmd.physics import integrate

    rig, el = Rig(), [effect("cubic_absorber_spring", k3=2e9)]
    force = 10.0 * _force(4.0)
    judged = slice(int(2 * FS), -int(0.5 * FS))
    fine = integrate(rig, force, FS, el, oversample=64).a2[judged]

    def err(k, extrapolate=False):
        return np.sqrt(np.mean((integrate(rig, force, FS, el, oversample=k, extrapolate=extrapolate).a2[judged]
                                - fine) ** 2) / np.mean(fine ** 2))

    assert err(4, True) < 0.1 * err(8) and err(8) < 0.4 * err(4)  # the hold's error falls as Δ²; extrapolated, far more

"""The SPEC §8b elements: declarations, registry, force laws, equivalent linearisation (closed forms
against quadrature and against simulation), and words."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.signal import csd, welch

from satmd.errors import DataError
from satmd.physics import Rig, frf
from satmd.physics.nonlinear import (
    NONLINEAR,
    NonlinearElement,
    element,
    equivalent_rig,
    gaussian_mean,
    integrate,
    nonlinear_names,
    register_nonlinear,
)
from satmd.physics.effects import VOCABULARY

SPEC_8B = {"cubic_absorber_spring": ("kp", "absorber"), "cubic_host_spring": ("k1", "host"),
           "absorber_friction": ("cp", "absorber"), "quadratic_damping": ("cp", "absorber"),
           "inductor_saturation": ("L", "shunt")}
AT_1N = {"cubic_absorber_spring": {"k3": 1.2e13}, "cubic_host_spring": {"k3": 3.5e13},
         "absorber_friction": {"Fc": 0.03, "v0": 1e-3}, "quadratic_damping": {"c2": 276.0},
         "inductor_saturation": {"isat": 0.02}}


def test_registry_and_declarations():
    assert set(nonlinear_names()) == set(SPEC_8B)
    for name, (target, acts) in SPEC_8B.items():
        el = element(name, **AT_1N[name])
        assert isinstance(el, NonlinearElement) and el.linear_parameter == target and el.acts == acts
        assert len(el.reads) == 1 and el.strength in el.parameter_names
        assert all(p.unit for p in el.parameter_specs)
        assert name not in VOCABULARY  # never fitted as a linear effect
        assert el.to_dict()["name"] == name
        assert len(el.explain(Rig())) > 40
    with pytest.raises(DataError, match="unknown nonlinear element"):
        element("cubic_spring")
    with pytest.raises(DataError):
        element("quadratic_damping", c2=-1.0)
    with pytest.raises(DataError):
        register_nonlinear(NONLINEAR["quadratic_damping"])  # taken


def test_force_laws_of_spec_8b():
    y = np.linspace(-2e-3, 2e-3, 9)
    assert np.allclose(element("cubic_absorber_spring", k3=2e9).force({"d": y}, Rig()), 2e9 * y ** 3)
    assert np.allclose(element("cubic_host_spring", k3=-1e9).force({"u1": y}, Rig()), -1e9 * y ** 3)
    assert np.allclose(element("absorber_friction", Fc=2.0, v0=1e-3).force({"v": y}, Rig()), 2 * np.tanh(y / 1e-3))
    assert np.allclose(element("quadratic_damping", c2=50.0).force({"v": y}, Rig()), 50 * np.abs(y) * y)
    # saturation: with λ = L0 isat arctan(i / isat), the integrator's ĩ = λ / L0 maps back to i
    isat, i = 0.02, np.linspace(-0.05, 0.05, 11)
    small = isat * np.arctan(i / isat)
    assert np.allclose(small + element("inductor_saturation", isat=isat).force({"i": small}, Rig()), i)


@settings(max_examples=25, deadline=None)
@given(name=st.sampled_from(sorted(SPEC_8B)), x=st.floats(-3.0, 3.0))
def test_slope_is_the_derivative_of_the_force(name, x):
    el = element(name, **AT_1N[name])
    sig = el.reads[0]
    scale = {"d": 1e-4, "u1": 1e-4, "v": 1e-2, "i": 0.01}[sig]  # |ĩ| < isat π/2, inside the flux limit
    h = 1e-6 * scale
    num = (el.force({sig: x * scale + h}, Rig()) - el.force({sig: x * scale - h}, Rig())) / (2 * h)
    typical = abs(el.force({sig: scale}, Rig())) / scale  # a secant slope: the size round-off is measured against
    assert np.isclose(el.slope({sig: x * scale}, Rig()), num, rtol=1e-5, atol=1e-6 * typical)


@settings(max_examples=25, deadline=None)
@given(name=st.sampled_from(sorted(SPEC_8B)), level=st.floats(0.2, 5.0))
def test_equivalent_value_is_the_gaussian_linearisation(name, level):
    # k_eq = E[f(x) x] / E[x²] (statistical linearisation), by quadrature of the force law itself
    el, rig = element(name, **AT_1N[name]), Rig()
    sig = el.reads[0]
    sigma = level * {"d": 1.6e-5, "u1": 1.2e-5, "v": 6.8e-3, "i": 7.4e-3}[sig]
    if sig == "i":  # the law is on the true current: L_eq = E[λ(i) i] / E[i²], λ = L0 isat arctan(i / isat)
        a = el.params["isat"]
        expect = rig.L * gaussian_mean(lambda x: a * np.arctan(x / a) * x, sigma, a) / sigma ** 2
    else:
        width = el.params.get("v0", 0.1 * sigma)  # adaptive quadrature: friction's tanh, |v|³ at 0
        expect = getattr(rig, el.linear_parameter) + gaussian_mean(lambda x: el.force({sig: x}, rig) * x,
                                                                   sigma, width) / sigma ** 2
    eq = el.equivalent_linear(rig, {sig: sigma})
    assert np.isclose(eq.value, expect, rtol=1e-6)
    assert eq.direction == {"cubic_absorber_spring": "up", "cubic_host_spring": "up", "quadratic_damping": "up",
                            "absorber_friction": "up", "inductor_saturation": "down"}[name]


def test_levels_move_the_equivalent_parameter_the_spec_way():
    rig = Rig()
    for name, way in (("cubic_absorber_spring", 1), ("cubic_host_spring", 1), ("absorber_friction", -1),
                      ("quadratic_damping", 1), ("inductor_saturation", -1)):
        el = element(name, **AT_1N[name])
        lo, _, _ = equivalent_rig(rig, [el], force_rms=1.0)
        hi, _, _ = equivalent_rig(rig, [el], force_rms=3.0)
        p = el.linear_parameter
        assert way * (float(getattr(hi, p)) - float(getattr(lo, p))) > 0, name


def _h1(F, a, fs):
    f, pff = welch(F, fs, nperseg=int(4 * fs))
    _, pfa = csd(F, a, fs, nperseg=int(4 * fs))
    return f, pfa / pff


def test_equivalent_linearisation_matches_simulation():
    """At ~5-10 % strength, the equivalent rig's FRF is much closer to the simulated H1 than the linear rig's."""
    fs, seconds = 1024.0, 40.0
    n = int(fs * seconds)
    rng = np.random.default_rng(11)
    x = np.fft.rfft(rng.standard_normal(4 * n))
    f = np.fft.rfftfreq(4 * n, 1 / fs)
    x[(f < 20) | (f > 200)] = 0
    F = np.fft.irfft(x, 4 * n)[:n]
    F /= F.std()
    rig = Rig()
    for name, params in AT_1N.items():
        el = element(name, **params)
        r = integrate(rig, F, fs, [el], outputs=("a2",))
        freq, h = _h1(F[int(fs):], r.a2[int(fs):], fs)
        band = (freq > 35) & (freq < 150)
        eq, _, _ = equivalent_rig(rig, [el], force=F, fs_hz=fs)
        err_eq = np.linalg.norm(frf(freq[band], eq, outputs=("a2",)).a2 - h[band])
        err_lin = np.linalg.norm(frf(freq[band], rig, outputs=("a2",)).a2 - h[band])
        assert err_eq < 0.4 * err_lin, (name, err_eq, err_lin)


def test_explanations_say_which_way():
    rig = Rig()
    assert "hardens" in element("cubic_absorber_spring", k3=2e9).explain(rig)
    assert "softens" in element("cubic_absorber_spring", k3=-2e9).explain(rig)
    assert "falls with level" in element("absorber_friction", Fc=1.0).explain(rig)
    assert "rise with level" in element("quadratic_damping", c2=10.0).explain(rig)
    assert "L fall" in element("inductor_saturation", isat=0.1).explain(rig)
    eq = element("cubic_absorber_spring", k3=1e13).equivalent_linear(rig, {"d": 2e-5})
    assert eq.to_dict()["direction"] == "up" and math.isclose(eq.value, 111e3 + 3e13 * 4e-10)
    assert "kp" in eq.report()

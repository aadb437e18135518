"""A nonlinear element added from outside the package is one class and a registration (issue 36, "one element").

The class below (a gap spring: a contact spring that engages beyond a clearance) is written the way a user
would write one: its parameters, what it reads and moves, and its force law once. satmd then simulates it,
detects it, names it (over the cubic absorber spring, which moves kp the same way), fits it in the time
domain and tunes the shunt for it, with nothing else edited.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from satmd import discover, simulate
from satmd.identification.nonlinear.fit import fit_nonlinear
from satmd.physics import Rig
from satmd.physics.effects.base import Parameter
from satmd.physics.nonlinear import NonlinearElement, kernel, register_nonlinear, unregister_nonlinear
from satmd.tuning.nonlinear import tune_nonlinear

pytestmark = pytest.mark.skipif(not kernel.available, reason="numba not installed (pip install numba)")

TRUTH = Rig(m2=0.55, kp=1.2e5, R=30.0, L=0.07)
KG, GAP = 6e4, 1.2e-4  # the contact spring: half kp, engaging at ~0.8 RMS of the stroke at the top level


def gap_law(p0, p1, y):
    """p0 (y - clip(y, -p1, p1)): a spring of stiffness p0 beyond a clearance p1, and its slope."""
    inside = np.minimum(np.maximum(y, -p1), p1)
    return p0 * (y - inside), p0 * (np.abs(y) > p1)


class GapSpring(NonlinearElement):
    name = "test_gap_spring"
    parameter_specs = (
        Parameter("kg", "N/m", default=0.0, neutral=0.0, hard=(0.0, math.inf), search=(0.0, 1e8), starts=(1e4, 1e5)),
        Parameter("gap", "m", default=1e-4, hard=(1e-9, math.inf), search=(1e-6, 1e-2), starts=(1e-4,)),
    )
    description = "a contact spring kg beyond a clearance gap in the absorber's stroke"
    acts, reads, linear_parameter, strength, moves = "absorber", ("d",), "kp", "kg", "up"
    law = staticmethod(gap_law)
    regressor = "d:cube"  # the distortion test's regressor that stands for it

    @property
    def law_width(self):  # the slope steps at ±gap: quadrature with break points there
        return float(np.min(self.params["gap"]))

    def kernel_parameters(self):
        return (self.params["kg"], self.params["gap"])


@pytest.fixture(scope="module")
def recordings():
    register_nonlinear(GapSpring)
    el = GapSpring(kg=KG, gap=GAP)
    recs = [simulate(rig=TRUTH, time=True, nonlinear=[el], level=lv, duration_s=12.0, fs_hz=1024.0, noise=0.01,
                     seed=i) for i, lv in enumerate((1.0, 3.0, 6.0, 10.0))]
    yield recs
    unregister_nonlinear(GapSpring.name)


def test_new_element_law_written_once_serves_both_integrators(recordings):
    from satmd.physics import integrate

    force = np.asarray(recordings[-1]["force"])[:4096]
    el = GapSpring(kg=KG, gap=GAP)
    compiled = integrate(TRUTH, force, 1024.0, [el], backend="numba")
    plain = integrate(TRUTH, force, 1024.0, [el], backend="numpy")
    assert np.max(np.abs(compiled.a2 - plain.a2)) < 1e-6 * np.max(np.abs(plain.a2))
    eq = el.equivalent_linear(TRUTH, {"d": 1.5e-4})  # numerical by default: kp + kg P(|d| > gap)
    assert eq.value == pytest.approx(TRUTH.kp + KG * math.erfc(GAP / (math.sqrt(2) * 1.5e-4)), rel=1e-6)
    from satmd.discovery.nonlinear.findings import regressor_hint

    assert "test_gap_spring" in regressor_hint("d:cube")  # the distortion test's hint names it too


def test_new_element_detected_named_fitted_and_tuned(recordings):
    found = discover(recordings).nonlinear.findings[0]
    assert found["name"] == "test_gap_spring", found  # the trend with level, not the first kp-up element
    assert "cubic_absorber_spring" not in found["equivalent"]
    lo, hi = found["ci95"]["kg"]
    assert lo <= KG <= hi and hi - lo < 0.3 * KG

    fit = fit_nonlinear(recordings, "test_gap_spring", seconds=None, start=TRUTH)
    assert abs(fit.values["kg"] / KG - 1) < 0.05 and abs(fit.values["gap"] / GAP - 1) < 0.05

    tuned = tune_nonlinear(fit.rig, [fit.element], levels=[1.0, 10.0], duration_s=8.0)
    assert np.isfinite(tuned.worst_db) and tuned.worst_db <= max(tuned.linear_peaks_db) + 1e-9

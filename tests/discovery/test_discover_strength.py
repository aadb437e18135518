"""The coefficient `discover` reports for a named element is the time-domain fit's, and its interval covers
(issue 36 item 7: the equivalent-linearisation strength came with an interval from that fit's noise alone)."""
from __future__ import annotations

import pytest

from satmd import discover, simulate
from satmd.physics import Rig, nonlinear_element
from satmd.physics.nonlinear import kernel

pytestmark = pytest.mark.skipif(not kernel.available, reason="numba not installed (pip install numba)")


def test_named_element_strength_covers_the_truth():
    truth = Rig(m2=0.55, kp=1.2e5, R=30.0, L=0.07)
    el = nonlinear_element("cubic_absorber_spring", k3=2e11)
    recs = [simulate(rig=truth, time=True, nonlinear=[el], level=lv, duration_s=16.0, fs_hz=1024.0, noise=0.01,
                     seed=i) for i, lv in enumerate((1.0, 10.0))]
    found = discover(recs).nonlinear.findings[0]
    assert found["name"] == "cubic_absorber_spring"
    lo, hi = found["ci95"]["k3"]
    assert lo <= 2e11 <= hi and hi - lo < 0.05 * 2e11
    assert abs(found["parameters"]["k3"] / 2e11 - 1) < 0.01
    assert "k3 = 2e+11" in found["explanation"]

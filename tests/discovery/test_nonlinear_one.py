"""One recording (issue 26): the per-regressor distortion test finds weak damping nonlinearities and holds its level."""
from __future__ import annotations

import numpy as np
import pytest

from satmd import simulate
from satmd.discovery.nonlinear.distortion import distortion_test
from satmd.discovery.nonlinear.findings import analyse_recordings
from satmd.discovery.nonlinear.stats import distortion_regressors, linearity_test, separate_linearity_test
from satmd.physics import Rig
from satmd.physics.nonlinear import element, response_rms


def _c2_for(change: float) -> float:
    """c2 whose equivalent linear damping at level 1 is ``change`` x cp (statistical linearisation)."""
    sv = response_rms(Rig(), band_hz=(20.0, 200.0), force_rms=1.0)["v"]
    return change * Rig().cp / (2 * np.sqrt(2 / np.pi) * sv)


def test_velocity_squared_damping_at_ten_percent_is_found_and_hinted():
    rec = simulate(time=True, nonlinear=[element("quadratic_damping", c2=_c2_for(0.10))], level=1.0,
                   duration_s=30, fs_hz=2048, noise=0.02, seed=2)
    t = distortion_test(rec)
    assert t.significant and t.p_value < 1e-8, t.report()
    assert t.details["regressors"][0] == "v:absv", t.details["per_regressor"]
    rep = analyse_recordings([rec])
    assert rep.detected and "velocity-squared" in rep.findings[0]["explanation"]
    assert rep.findings[0]["name"] == "nonlinear_unexplained"  # one level cannot name the element


def test_the_same_recording_without_the_element_is_not_flagged():
    rec = simulate(time=True, level=1.0, duration_s=30, fs_hz=2048, noise=0.02, seed=2)
    t = distortion_test(rec)
    assert not t.significant, t.report()
    assert set(t.details["per_regressor"]) == {"u1:cube", "d:cube", "v:cube", "v:absv", "v:sign"}


def _resonant_record(rng, n, strength):
    """A one-mode resonator driven by band-limited noise, with a |y'|y' damping force through the same path."""
    from scipy.signal import lfilter

    X = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n)
    X[(f < 0.05) | (f > 0.3)] = 0
    x = np.fft.irfft(X, n)
    w, r = 2 * np.pi * 0.12, np.exp(-0.02 * 2 * np.pi * 0.12)
    a = [1.0, -2 * r * np.cos(w), r * r]
    y = lfilter([1.0], a, x)
    dy = np.gradient(y)
    y = y - strength * lfilter([1.0], a, np.abs(dy) * dy / np.std(dy))
    return x, y + 0.02 * np.std(y) * rng.standard_normal(n)


@pytest.mark.parametrize("seed", range(6))
def test_separate_test_holds_its_level_on_linear_records(seed):
    rng = np.random.default_rng(seed)
    x, y = _resonant_record(rng, 1 << 15, 0.0)
    dy = np.gradient(y)
    regs = distortion_regressors({"y": y, "dy": dy}, {"y": ("cube",), "dy": ("cube", "absv", "sign")})
    t = separate_linearity_test(x, {"y": y}, 1.0, regs, band_hz=(0.06, 0.29), window_hz=0.004, alpha=0.01)
    assert t.p_value > 1e-3, t.report()


def test_separate_test_is_more_powerful_than_the_joint_test_for_one_shape():
    rng = np.random.default_rng(7)
    x, y = _resonant_record(rng, 1 << 15, 0.03)
    dy = np.gradient(y)
    regs = distortion_regressors({"y": y, "dy": dy}, {"y": ("cube",), "dy": ("cube", "absv", "sign")})
    joint = linearity_test(x, {"y": y}, 1.0, regs, band_hz=(0.06, 0.29))
    sep = separate_linearity_test(x, {"y": y}, 1.0, regs, band_hz=(0.06, 0.29), window_hz=0.004)
    assert sep.significant and sep.p_value < joint.p_value, (sep.report(), joint.report())

"""Practical significance: an effect within the estimator's own bias bound is a measurement matter."""
import numpy as np
import pytest

from satmd import discover, effect
from satmd.errors import DataError
from satmd.io import FRFData
from satmd.physics import Rig
from satmd.simulation.frf import simulate

F = np.linspace(30.0, 160.0, 200)


def _biased(bound):
    """A null rig whose estimate reads 0.3 % low in both channels (a force-noise-like bias), tiny noise."""
    d = simulate(F, Rig(), [effect("sensor_gain", gain_a1=0.997, gain_a2=0.997)], noise=(0.0005, 0.0001), seed=2)
    return FRFData(d.freq_hz, d.channels, d.std, bias_bound=np.full(F.size, bound))


def test_a_gain_inside_the_bias_bound_is_a_measurement_finding_not_physics():
    rep = discover(_biased(0.005), candidates=["sensor_gain", "time_delay", "structural_damping"])
    assert rep.significant_mismatch and rep.effects == []
    notes = [m for m in rep.measurement if m["name"] == "within_estimator_bias"]
    assert len(notes) == 1 and notes[0]["explanation"].startswith("sensor_gain")
    assert rep.fit_after["chi2_reduced"] < 1.5  # the fit keeps it: nothing left for `unexplained`
    judged = {j.name: j for j in rep.judged}
    assert judged["sensor_gain"].status == "measurement"
    assert judged["sensor_gain"].reasons[0].kind == "within_estimator_bias"
    assert judged["sensor_gain"].finding.parameters  # what it would have said is kept
    assert "within_estimator_bias" in rep.report()


def test_the_same_gain_beyond_the_bias_bound_is_named():
    rep = discover(_biased(0.001), candidates=["sensor_gain", "time_delay", "structural_damping"])
    assert rep.effect_names == ["sensor_gain"]
    assert not [m for m in rep.measurement if m["name"] == "within_estimator_bias"]


def test_bias_bound_is_checked_and_follows_the_band():
    d = _biased(0.005)
    assert d.band(50, 100).bias_bound.shape == d.band(50, 100).freq_hz.shape
    with pytest.raises(DataError, match="bias_bound"):
        FRFData(d.freq_hz, d.channels, d.std, bias_bound=np.ones(3))
    with pytest.raises(DataError, match="bias_bound"):
        FRFData(d.freq_hz, d.channels, d.std, bias_bound=-np.ones(F.size))


class _Prediction(dict):
    def __init__(self, f, channels):
        super().__init__(channels)
        self.freq_hz, self.channels = f, tuple(channels)


def _fit(h, std, k):
    """A fitted model's face as `evidence_beyond_bias` reads it: prediction, std, χ² and BIC with k parameters."""
    from types import SimpleNamespace

    n = 4 * F.size
    return SimpleNamespace(prediction=lambda: _Prediction(F, {"a1": h, "a2": h}),
                           data=SimpleNamespace(std={"a1": std, "a2": std}), chi2=float(n), bic=n + k * np.log(n))


@pytest.mark.parametrize("rel_std, named", [(1e-3, False), (1e-5, True)])
def test_only_the_signature_beyond_the_bias_is_evidence(rel_std, named):
    """A change within the bound at every point but three, where it exceeds it by a fifth: the excess is evidence
    at a tiny noise, none at a noise comparable to the bound (the old max-share rule named it at both)."""
    from satmd.conventions import MIN_DELTA_BIC
    from satmd.discovery.budget import evidence_beyond_bias

    bound = np.full(F.size, 1e-3)
    without = np.ones(F.size, complex)
    change = np.full(F.size, 0.5e-3)
    change[[50, 100, 150]] = 1.2e-3
    with_ = without * (1 + change)
    ev = evidence_beyond_bias(_fit(with_, rel_std, 6), _fit(without, rel_std, 4), bound)
    assert (ev > MIN_DELTA_BIC) == named
    assert evidence_beyond_bias(_fit(with_, rel_std, 6), _fit(without, rel_std, 4), None) == float("inf")

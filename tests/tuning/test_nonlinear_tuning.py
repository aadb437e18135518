"""Tuning across drive levels on a nonlinear rig (issue 27 item 4)."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.errors import DataError
from satmd.physics import Rig, nonlinear_element
from satmd.tuning.nonlinear import equivalent_peaks, simulated_peaks, tune_nonlinear

from satmd.physics.nonlinear import kernel

# time-domain fits and direct-simulation tuning run hundreds of simulations: compiled integrator only
pytestmark = pytest.mark.skipif(not kernel.available, reason="numba not installed (pip install numba)")

SIM = dict(duration_s=20.0, fs_hz=1024.0, seed=3)


def test_linear_rig_simulated_peak_matches_the_frf_peak():
    # direct simulation's H1 peak against the exact FRF peak (the estimator's resolution and averaging)
    eq = equivalent_peaks(Rig(), [], 40.0, 0.2, [1.0], (20.0, 200.0))
    sim = simulated_peaks(Rig(), [], [40.0], [0.2], [1.0], (20.0, 200.0), **SIM)
    assert abs(20 * np.log10(sim[0, 0] / eq[0])) < 0.3


def test_hardening_rig_tuned_across_levels_beats_the_linear_tuning():
    el = nonlinear_element("cubic_absorber_spring", k3=2e11)
    res = tune_nonlinear(Rig(), [el], [1.0, 10.0], **SIM)
    assert res.worst_db == pytest.approx(max(res.peaks_db))
    assert res.cost_of_linear_db > 0.2  # the low-level tuning pays at the high level
    assert res.linear_peaks_db[1] > res.linear_peaks_db[0]  # ... and there, not at the low level
    assert 30 < res.linear_design["R"] < 70 and 0.15 < res.linear_design["L"] < 0.3  # SPEC §10: 46.9 Ω, 0.214 H
    d = res.to_dict()
    assert set(d["design"]) == {"R", "L"} and "costs" in res.report()


def test_bad_levels():
    with pytest.raises(DataError, match="level"):
        tune_nonlinear(Rig(), [], [])
    with pytest.raises(DataError, match="output"):
        tune_nonlinear(Rig(), [], [1.0], output="q")

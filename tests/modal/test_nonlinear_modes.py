"""satmd.discovery.nonlinear.modes on levels of a simulated structure: the resonance the joint moves, told."""
from __future__ import annotations

import json

import numpy as np

from satmd.discovery.nonlinear.modes import NOT_SATMD, level_modes, modal_finding
from satmd.io.frfdata import FRFData

from .test_follow_modes import simulated_levels


def test_the_finding_names_the_resonance_the_slipping_joint_moves_and_puts_its_band_there():
    freq, frfs, stds, levels, target = simulated_levels("friction_chain4")
    datas = [FRFData(freq, h, s) for h, s in zip(frfs, stds)]
    finding, bands = modal_finding(datas, list(levels), "N RMS")
    doc = json.loads(json.dumps(finding.to_dict(), allow_nan=False))  # every number finite
    assert doc["name"] == "nonlinear_unexplained" and NOT_SATMD in doc["explanation"]
    (mode,) = [m for m in doc["modes"] if abs(m["f_hz"][0] / target - 1) < 0.02]
    assert (mode["trend"], mode["damping_trend"]) == ("softening", "rising")
    assert f"the {mode['f_hz'][0]:.3g} Hz resonance softens" in doc["explanation"]
    assert any(lo <= f <= hi for lo, hi in bands for f in mode["f_hz"])


def test_too_few_frequencies_give_no_modes():
    freq = np.linspace(10.0, 20.0, 5)
    h = {"a1": np.ones(5, complex)}
    assert level_modes(freq, [h, h], [None, None], [1.0, 2.0]) == []

"""Retuning a drifting rig: warm-started identification and retuning at every step."""
import json

import numpy as np
import pytest

from satmd import Rig, retune, simulate
from satmd.tuning import RetuneResult


def test_retune_tracks_kp_and_beats_the_fixed_setting(tmp_path):
    series = [simulate(rig=Rig(kp=kp), noise=0.005, seed=i, meta={"label": f"kp {kp:.0f}"})
              for i, kp in enumerate((111e3, 95e3))]
    res = retune(series, n_search=256, n_starts=2)
    assert isinstance(res, RetuneResult) and res.labels == ("kp 111000", "kp 95000")
    assert res.parameters[1]["kp"] == pytest.approx(95e3, rel=0.01)
    assert res.retuning_gain_db[0] == pytest.approx(0.0, abs=1e-9)
    assert res.retuning_gain_db[1] > 0.3  # the first step's setting no longer fits
    assert np.all(res.value_retuned <= res.value_fixed * (1 + 1e-9))
    assert res.fixed_design == res.designs[0]
    assert "Retuning over time" in res.report()
    json.dumps(res.to_dict(), allow_nan=False)
    assert res.plot(tmp_path / "drift.png").exists()

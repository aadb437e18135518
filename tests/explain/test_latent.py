import numpy as np
import pytest

from satmd.explain import latent_map
from satmd.explain.latent import angle_deg


def test_latent_map_with_stand_in(standin, labelled):
    lm = latent_map(standin, labelled["a1a2_raw"], labels=(labelled["R"], labelled["L"]),
                    anchors=[(22.0, 0.064), (60.0, 0.3)], n_sweep=5)
    n = len(labelled["R"])
    assert lm.latent.shape == (n, 64) and lm.pcs.shape == (n, 2)
    assert 0 < lm.explained.sum() <= 1
    assert lm.probe_r2["R"] > 0.5 and lm.probe_r2["L"] > 0.5  # the stand-in is trained on labels
    assert len(lm.sweeps) == 2
    for s in lm.sweeps:
        assert 0.0 <= s["angle_deg"] <= 90.0
        assert s["pcs_R"].shape == (5, 2)
    d = lm.to_dict()
    assert set(d) == {"explained_variance_ratio", "probe_r2", "sweeps"}


def test_angle_between_directions():
    assert angle_deg(np.array([1.0, 0]), np.array([0, 2.0])) == pytest.approx(90.0)
    assert angle_deg(np.array([1.0, 1]), np.array([-2.0, -2])) == pytest.approx(0.0, abs=1e-4)


def test_labels_are_required(standin, labelled):
    from satmd.errors import DataError

    with pytest.raises(DataError):
        latent_map(standin, labelled["a1a2_raw"])

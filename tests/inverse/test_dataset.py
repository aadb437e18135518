import numpy as np
import pytest

from satmd.inverse import BOUNDS, BOX_RANGE, PAPER_PAIRS, make_dataset, pairs_dataset
from satmd.inverse.dataset import complex_to_features, denormalise, features_to_complex, normalise
from satmd.physics import PAPER_GRID_HZ, Rig, frf


def test_paper_preset_jitter_and_split():
    ds = make_dataset("paper", samples_per_pair=7, val_fraction=0.2, seed=0)
    assert len(ds) == 30 * 7
    centre = PAPER_PAIRS[ds.group]
    assert np.all(np.abs(ds.R - centre[:, 0]) <= 2.0 + 1e-12)
    assert np.all(np.abs(ds.L - centre[:, 1]) <= 0.010 + 1e-12)
    # split by reference pair: no pair on both sides, ends stay in training
    assert not set(ds.train.group) & set(ds.val.group)
    assert len(set(ds.val.group)) == 6
    assert {0, 29} <= set(ds.train.group)
    assert ds.a1.shape == (len(ds), 60) and np.iscomplexobj(ds.a1)


def test_labels_match_the_forward_model():
    ds = make_dataset("paper", samples_per_pair=2, seed=4)
    r = frf(PAPER_GRID_HZ, Rig(R=ds.R[5], L=ds.L[5]))
    np.testing.assert_allclose(ds.a1[5], r.a1, rtol=1e-12)
    np.testing.assert_allclose(ds.a2[5], r.a2, rtol=1e-12)


def test_box_preset_ranges_and_split():
    ds = make_dataset("box", n_samples=500, seed=2)
    assert len(ds) == 500
    assert BOX_RANGE["R"][0] <= ds.R.min() and ds.R.max() <= BOX_RANGE["R"][1]
    assert BOX_RANGE["L"][0] <= ds.L.min() and ds.L.max() <= BOX_RANGE["L"][1]
    assert not set(ds.train.group) & set(ds.val.group)
    # R and L independent: no strong correlation, unlike the paper's line
    assert abs(np.corrcoef(ds.R, ds.L)[0, 1]) < 0.2


def test_seeded():
    a, b = make_dataset("paper", samples_per_pair=3, seed=9), make_dataset("paper", samples_per_pair=3, seed=9)
    np.testing.assert_array_equal(a.R, b.R)
    np.testing.assert_array_equal(a.is_val, b.is_val)
    c = make_dataset("paper", samples_per_pair=3, seed=10)
    assert not np.array_equal(a.R, c.R)


def test_feature_order_matches_torch_twin():
    pytest.importorskip("torch")
    from satmd.physics.torch import features, frf as tfrf

    ds = pairs_dataset([(22.0, 0.064)])
    ref = features(tfrf(PAPER_GRID_HZ, Rig(R=22.0, L=0.064))).numpy()
    np.testing.assert_allclose(ds.features()[0], ref, rtol=1e-10)
    back = features_to_complex(ds.features())
    np.testing.assert_allclose(back[:, 0], ds.a1)
    np.testing.assert_allclose(back[:, 1], ds.a2)
    assert complex_to_features(back).shape == (1, 240)


def test_normalisation_roundtrip():
    v = np.array([[22.0, 0.064], [103.0, 0.5]])
    np.testing.assert_allclose(denormalise(normalise(v, BOUNDS), BOUNDS), v)
    np.testing.assert_allclose(normalise(v)[1], [1.0, 1.0])


def test_bad_preset():
    from satmd.errors import SatmdError

    with pytest.raises(SatmdError, match="unknown preset"):
        make_dataset("grid")

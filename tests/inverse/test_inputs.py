"""Lab data onto the net's grid, and the forward check that flags data the prediction does not explain."""
import warnings

import numpy as np
import pytest

pytest.importorskip("torch")

from satmd import Rig, simulate
from satmd.errors import DataError
from satmd.inverse import InverseModel
from satmd.inverse.inputs import CHECK_LIMIT, forward_check, prepare, to_grid
from satmd.io import DataWarning
from satmd.physics import PAPER_GRID_HZ, frf


def _frf(freq, **rig):
    r = frf(freq, Rig(**rig), outputs=("a1", "a2"))
    return np.stack([r.a1, r.a2])


def test_dense_data_are_interpolated_onto_the_grid():
    dense = np.linspace(20.0, 200.0, 2001)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # full coverage, finer than the grid: no warning
        a, std, notes = to_grid(dense, _frf(dense, R=30.0, L=0.15), None, PAPER_GRID_HZ)
    assert not notes and std is None
    truth = _frf(PAPER_GRID_HZ, R=30.0, L=0.15)
    assert np.max(np.abs(a - truth)) / np.max(np.abs(truth)) < 1e-4


def test_a_narrow_band_is_filled_from_the_model_with_a_warning():
    band = np.linspace(55.0, 100.0, 400)
    a, _, notes = to_grid(band, _frf(band, R=22.0, L=0.064), None, PAPER_GRID_HZ, Rig())
    assert len(notes) == 1 and "cover 55..100 Hz" in notes[0] and "filled from the forward model" in notes[0]
    truth = _frf(PAPER_GRID_HZ, R=22.0, L=0.064)
    np.testing.assert_allclose(a, truth, rtol=1e-4, atol=1e-6 * np.abs(truth).max())


def test_coarse_data_warn_and_no_overlap_is_refused():
    coarse = np.linspace(40.0, 130.0, 20)
    _, _, notes = to_grid(coarse, _frf(coarse), None, PAPER_GRID_HZ)
    assert any("coarser than the model's grid" in n for n in notes)
    far = np.linspace(300.0, 400.0, 50)
    with pytest.raises(DataError, match="hardly overlap"):
        to_grid(far, _frf(far), None, PAPER_GRID_HZ)


def test_std_columns_follow_and_the_check_uses_measured_points():
    data = simulate(freq_hz=np.linspace(35.0, 140.0, 300), rig=Rig(R=40.0, L=0.2), noise=0.01, seed=2)
    inputs = prepare(data, PAPER_GRID_HZ, Rig())
    assert inputs.a.shape == (1, 2, 60) and inputs.std.shape == (1, 2, 60)
    f, a, s = inputs.raw[0]
    assert f.min() >= 40.0 and f.max() <= 130.0 and a.shape == s.shape == (2, f.size)
    good = forward_check(inputs, np.array([40.0]), np.array([0.2]), Rig(), 1e-3, 0.0)
    assert good["explained"][0] and 0.5 < good["residual_ratio"][0] < 1.5  # the noise, as expected
    bad = forward_check(inputs, np.array([20.0]), np.array([0.2]), Rig(), 1e-3, 0.0)
    assert not bad["explained"][0] and bad["residual_ratio"][0] > CHECK_LIMIT


def test_out_of_distribution_rig_is_flagged(tiny_physics):
    """The issue's case: m2 0.7, kp 1.5e5 (true R 22) used to give R 3.4 ± 1.1 Ω silently."""
    import copy

    model = copy.copy(tiny_physics)  # a few epochs only: give it the accuracy of a trained net
    model.fit_info_ = {**tiny_physics.fit_info_, "residual_ref": 0.01}
    off = simulate(rig=Rig(m2=0.7, kp=1.5e5, R=22.0, L=0.064), noise=0.01, seed=0)
    with pytest.warns(DataWarning, match="does not explain the data"):
        p = model.predict(off)
    assert not p["explained"][0] and p["residual_ratio"][0] > 10


def test_in_distribution_is_explained():
    m = InverseModel("optimization").fit()
    data = simulate(rig=Rig(R=30.0, L=0.15), noise=0.01, seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataWarning)
        p = m.predict(data)
    assert p["explained"][0] and p["residual_ratio"][0] < 2
    one = m.predict_one(data)
    assert isinstance(one["explained"], bool) and isinstance(one["R"], float)


def test_predict_accepts_lab_grids(tiny_physics):
    on = simulate(rig=Rig(R=30.0, L=0.15))
    off = simulate(freq_hz=np.linspace(30.0, 150.0, 1200), rig=Rig(R=30.0, L=0.15))
    a, b = tiny_physics.predict(on), tiny_physics.predict(off)
    np.testing.assert_allclose(b["R"], a["R"], rtol=1e-3)
    np.testing.assert_allclose(b["L"], a["L"], rtol=1e-3)

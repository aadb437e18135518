"""Issue 29: one training (cross-fitted members), the shunt Jacobian, and models saved before still load."""
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from satmd import Rig
from satmd.errors import DataError
from satmd.inverse import BLIND_PAIRS, InverseModel, make_dataset, pairs_dataset
from satmd.inverse.dataset import crossfit_folds
from satmd.inverse.objective import gauss_newton_step, gauss_newton_step_fd

V1_META = Path(__file__).parent / "data" / "model_v1.json"  # written by satmd before issue 29 (format 1)
# format 2 as written before the Möbius step (commit 8ce9393's parent: jacobian="shunt"), and what that version
# predicted with the weights `_saved_folder` writes
V2_META = Path(__file__).parent / "data" / "model_v2_shunt.json"
V2_PREDICT = Path(__file__).parent / "data" / "model_v2_shunt_predict.json"


def test_each_validation_pair_is_held_out_from_one_member(tiny_data):
    folds = crossfit_folds(tiny_data, 3, seed=4)
    assert np.all(folds[~tiny_data.is_val] == -1)
    val_groups = np.unique(tiny_data.group[tiny_data.is_val])
    for g in val_groups:  # a pair's samples share one fold
        assert np.unique(folds[tiny_data.group == g]).size == 1
    per_fold = [np.unique(tiny_data.group[folds == k]).size for k in range(3)]
    assert sum(per_fold) == val_groups.size and max(per_fold) - min(per_fold) <= 1
    np.testing.assert_array_equal(folds, crossfit_folds(tiny_data, 3, seed=4))


def test_members_draw_only_their_own_samples(tiny_data):
    from satmd.inverse.training import Scaler, _Batches

    folds = crossfit_folds(tiny_data, 2, seed=0)
    members = np.stack([folds != k for k in range(2)])
    tr = _Batches(tiny_data, Scaler.fit(tiny_data.features()), InverseModel.bounds, torch.device("cpu"),
                  torch.complex64, members)
    order = tr.epoch_order(torch.Generator().manual_seed(0)).numpy()
    assert order.shape == (2, members.sum(axis=1).max())
    for k in range(2):
        assert set(order[k]) == set(np.flatnonzero(members[k]))  # all of its samples, none of the others


def test_crossfit_trains_once_and_calibrates_out_of_fold(tiny_physics):
    info = tiny_physics.fit_info_
    assert info["calibration"] == "crossfit" and info["refit"] is False and info["n_folds"] == 3
    assert "refit_loss" not in tiny_physics.history_  # no second training
    assert info["n_val"] == 6 * 6 and 0.9 <= info["val_coverage_2sd"] <= 1.0
    assert np.all(tiny_physics.std_scale_ > 0)


def test_holdout_is_the_method_before(tiny_data):
    kw = dict(epochs=2, warm_start_epochs=1, n_members=2, seed=5, verbose=False, mc_samples=4)
    old = InverseModel("physics", calibration="holdout", jacobian="fd", **kw).fit(tiny_data)
    assert old.fit_info_["calibration"] == "holdout" and old.fit_info_["refit"] is True
    assert "refit_loss" in old.history_
    one = InverseModel("supervised", **{**kw, "n_members": 1}).fit(tiny_data)
    assert one.fit_info_["calibration"] == "holdout" and "one member" in one.fit_info_["calibration_note"]


def test_shunt_jacobian_step_matches_finite_differences():
    ds = pairs_dataset(BLIND_PAIRS, per_pair=3, seed=2)
    y = torch.as_tensor(ds.labels_normalised(), dtype=torch.float64)
    target = torch.as_tensor(np.stack([ds.a1, ds.a2], axis=1))
    s_n = torch.as_tensor(np.abs(np.stack([ds.a1, ds.a2], axis=1)).max(axis=(1, 2)))
    start = y + torch.as_tensor(np.random.default_rng(0).normal(0, 0.01, y.shape))
    a, la = gauss_newton_step(start, target, s_n, torch.as_tensor(ds.freq_hz), Rig())
    b, lb = gauss_newton_step_fd(start, target, s_n, torch.as_tensor(ds.freq_hz), Rig())
    torch.testing.assert_close(la, lb, rtol=1e-12, atol=0)
    torch.testing.assert_close(a, b, rtol=0, atol=1e-4 * float(b.abs().max()))


def _saved_folder(tmp_path, source=V1_META):
    """The model.json ``source`` that satmd wrote before (format 1 by default), with seeded weights of its
    network's shape."""
    from satmd.inverse.nets import EnsembleNet

    meta = json.loads(source.read_text())
    folder = tmp_path / source.stem
    folder.mkdir()
    shutil.copy(source, folder / "model.json")
    net = EnsembleNet(meta["network"]["n_members"], meta["network"]["sizes"], torch.Generator().manual_seed(0))
    torch.save(net.state_dict(), folder / "weights.pt")
    return folder


@pytest.mark.filterwarnings("ignore:R_std")  # random weights: the std spans the box
def test_format_1_models_still_load(tmp_path):
    m = InverseModel.load(_saved_folder(tmp_path))
    assert json.loads(V1_META.read_text())["schema"] == "satmd-inverse/1"
    assert m.calibration == "holdout" and m.jacobian == "fd"  # how format-1 models were trained
    p = m.predict(pairs_dataset(BLIND_PAIRS[:2]), check=False)
    assert np.all(np.isfinite(p["R"])) and p["R"].shape == (2,)
    m.save(tmp_path / "again")  # saved again, in the current format
    meta = json.loads((tmp_path / "again" / "model.json").read_text())
    assert meta["schema"] == "satmd-inverse/2" and meta["params"]["calibration"] == "holdout"
    assert InverseModel.load(tmp_path / "again").jacobian == "fd"


@pytest.mark.filterwarnings("ignore:R_std", "ignore:L_std")  # random weights: the std spans the box
def test_format_2_models_saved_before_the_moebius_step_load_and_predict_as_before(tmp_path):
    meta = json.loads(V2_META.read_text())
    assert meta["schema"] == "satmd-inverse/2" and meta["params"]["jacobian"] == "shunt"
    m = InverseModel.load(_saved_folder(tmp_path, V2_META))
    assert m.jacobian == "shunt" and m.calibration == "crossfit"  # its own settings, not today's defaults
    p = m.predict(pairs_dataset(BLIND_PAIRS[:2]), check=False)
    before = json.loads(V2_PREDICT.read_text())
    assert sorted(before) == ["L", "L_std", "R", "R_std"]
    for k, v in before.items():
        np.testing.assert_allclose(p[k], v, rtol=1e-6, atol=0)


def test_a_newer_format_is_refused_with_the_reason(tmp_path):
    folder = _saved_folder(tmp_path)
    meta = json.loads(V1_META.read_text())
    meta["schema"] = "satmd-inverse/7"
    (folder / "model.json").write_text(json.dumps(meta))
    with pytest.raises(DataError, match=r"newer satmd \(format 7\).*reads formats 1-2: upgrade") as exc:
        InverseModel.load(folder)
    assert "\n" not in str(exc.value)
    meta["schema"] = "something-else/1"
    (folder / "model.json").write_text(json.dumps(meta))
    with pytest.raises(DataError, match="expected one of 'satmd-inverse/1', 'satmd-inverse/2'"):
        InverseModel.load(folder)


def test_crossfit_needs_no_more_than_the_data(tiny_data):
    # a dataset without a validation part: nothing to calibrate on, one training on everything
    no_val = make_dataset("paper", samples_per_pair=2, val_fraction=0.0, seed=1)
    m = InverseModel("supervised", epochs=1, n_members=2, verbose=False, mc_samples=2).fit(no_val)
    assert m.fit_info_["n_val"] == 0 and np.all(m.std_scale_ == 1)


def test_cross_fitted_model_records_its_held_out_pairs(tiny_physics, tiny_data):
    held = tiny_physics.fit_info_["held_out"]
    assert len(held) == 6 and {h[0] for h in held} == {0, 1, 2}
    for k, r0, r1, l0, l1 in held:
        assert r0 < r1 and l0 < l1

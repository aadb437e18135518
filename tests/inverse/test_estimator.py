"""InverseModel as a scikit-learn estimator: parameters, validation in fit, clone, save/load refusals."""
import inspect
import json

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from satmd import Rig
from satmd.errors import DataError, SatmdError
from satmd.inverse import BLIND_PAIRS, InverseModel, pairs_dataset


def test_init_stores_its_arguments_and_nothing_else():
    names = [p for p in inspect.signature(InverseModel.__init__).parameters if p != "self"]
    m = InverseModel("supervised", noise=0.01, epochs=3)
    assert sorted(vars(m)) == sorted(names)
    assert m.get_params() == {n: getattr(m, n) for n in names}
    assert not m.is_fitted
    # no validation in __init__: a bad value waits for fit
    InverseModel(kind="magic", noise=-1)


def test_get_set_params_round_trip():
    m = InverseModel()
    params = m.get_params()
    m2 = InverseModel().set_params(**{**params, "epochs": 7, "kind": "hybrid"})
    assert m2.epochs == 7 and m2.kind == "hybrid"
    assert m2.set_params(**params).get_params() == params
    with pytest.raises(SatmdError, match="no parameter 'epoch'"):
        m.set_params(epoch=3)


def test_sklearn_clone():
    base = pytest.importorskip("sklearn.base")
    m = InverseModel("physics", "box", 0.01, epochs=5, rig=Rig(m2=0.6), freq_hz=np.linspace(40, 130, 30))
    c = base.clone(m)
    assert c is not m and type(c) is InverseModel
    for k, v in m.get_params().items():
        if isinstance(v, np.ndarray):
            np.testing.assert_array_equal(getattr(c, k), v)
        else:
            assert getattr(c, k) == v
    assert not c.is_fitted


@pytest.mark.parametrize("name, value, match", [
    ("kind", "magic", "unknown kind 'magic'"),
    ("preset", "grid", "unknown preset"),
    ("noise", 1.0, "noise must be"),
    ("noise", float("nan"), "noise must be"),
    ("epochs", 0, "epochs must be"),
    ("epochs", 2.5, "epochs must be"),
    ("batch_size", True, "batch_size must be"),
    ("lr", -1e-3, "lr must be"),
    ("n_members", 0, "n_members must be"),
    ("twin_dtype", "float16", "unknown twin_dtype"),
    ("val_fraction", 1.0, "val_fraction must be"),
    ("seed", -1, "seed must be"),
    ("rig", {"m2": 1}, "rig must be"),
    ("freq_hz", [130.0, 40.0], "freq_hz must be"),
])
def test_fit_validates_against_one_table(name, value, match):
    with pytest.raises(SatmdError, match=match):
        InverseModel(**{name: value}).fit()


def test_device_refused_before_any_work():
    with pytest.raises(SatmdError, match="use cpu, cuda or cuda:N"):
        InverseModel(device="bogus").fit()
    if not torch.cuda.is_available():
        with pytest.raises(SatmdError, match="no CUDA"):
            InverseModel(device="cuda").fit()


def test_to_dict_from_dict(tiny_physics):
    meta = tiny_physics.to_dict()
    json.dumps(meta)  # JSON-ready
    state = tiny_physics.ensemble_.state_dict()
    m = InverseModel.from_dict(meta, state)
    test = pairs_dataset(BLIND_PAIRS[:2])
    np.testing.assert_array_equal(m.predict(test)["R"], tiny_physics.predict(test)["R"])
    with pytest.raises(DataError, match="needs its weights"):
        InverseModel.from_dict(meta)


@pytest.fixture()
def saved(tiny_physics, tmp_path):
    return tiny_physics.save(tmp_path / "m")


def _one_line(exc):
    assert "\n" not in str(exc.value)
    return str(exc.value)


def test_tampered_kind_is_refused(saved):
    for kind in ("optimization", "magic", None):
        meta = json.loads((saved / "model.json").read_text())
        meta["kind"] = kind
        meta.pop("sha256", None)  # a careful tamperer removes the checksum too
        (saved / "model.json").write_text(json.dumps(meta))
        with pytest.raises(DataError) as exc:
            InverseModel.load(saved)
        assert _one_line(exc).startswith(str(saved / "model.json"))


def test_edited_file_fails_its_checksum(saved):
    meta = json.loads((saved / "model.json").read_text())
    meta["params"]["noise"] = 0.5
    (saved / "model.json").write_text(json.dumps(meta))
    with pytest.raises(DataError, match="checksum") as exc:
        InverseModel.load(saved)
    _one_line(exc)


def test_truncated_weights_are_refused(saved):
    w = saved / "weights.pt"
    w.write_bytes(w.read_bytes()[: w.stat().st_size // 2])
    with pytest.raises(DataError) as exc:
        InverseModel.load(saved)
    assert _one_line(exc).startswith(str(w)) and "truncated" in str(exc.value)


def test_old_models_with_none_params_load(saved):
    meta = json.loads((saved / "model.json").read_text())
    meta["params"]["epochs"] = None  # as written before the defaults moved into the signature
    meta.pop("sha256")
    (saved / "model.json").write_text(json.dumps(meta))
    assert InverseModel.load(saved).epochs == 90


def test_fitted_model_follows_the_explain_contract(tiny_physics):
    from satmd.explain import ExplainableModel

    assert isinstance(tiny_physics, ExplainableModel)
    assert np.asarray(tiny_physics.freq_hz).shape == (60,) and tiny_physics.bounds["R"] == (0.0, 103.0)


def test_damaged_bounds_are_refused(saved):
    meta = json.loads((saved / "model.json").read_text())
    meta.pop("sha256")
    for bounds in ({"R": 1, "L": [0, 0.5]}, {"R": [0, 50], "L": [0, 0.5]}, {"R": ["a", "b"], "L": [0, 0.5]}):
        (saved / "model.json").write_text(json.dumps({**meta, "bounds": bounds}))
        with pytest.raises(DataError) as exc:
            InverseModel.load(saved)
        assert _one_line(exc).startswith(str(saved / "model.json"))

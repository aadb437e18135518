"""A one-member ensemble has no spread: no std (NaN, with the reason), never 0 or 1e10 (issue 38 item 2)."""
import json
import warnings

import numpy as np
import pytest

pytest.importorskip("torch")

from satmd import Rig, save_frf, simulate
from satmd.cli import main
from satmd.inverse import InverseModel, evaluate
from satmd.io import DataWarning


@pytest.fixture(scope="module")
def one(tiny_data):
    return InverseModel("supervised", epochs=2, n_members=1, batch_size=64, seed=0, verbose=False,
                        mc_samples=4).fit(tiny_data)


@pytest.fixture(scope="module")
def noisy_frf(tmp_path_factory):
    path = tmp_path_factory.mktemp("one") / "d.csv"
    save_frf(simulate(rig=Rig(R=30.0, L=0.15), noise=0.01, seed=0), path)
    return path


def test_predict_gives_no_std_and_says_why(one, noisy_frf):
    from satmd.io import load_frf

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        p = one.predict(load_frf(noisy_frf))
    assert np.isfinite(p["R"]).all() and np.isfinite(p["L"]).all()  # the point prediction stays
    assert np.isnan(p["R_std"]).all() and np.isnan(p["L_std"]).all()
    assert not p["explained"].any()  # nothing says how far to trust R, L
    notes = [str(w.message) for w in caught if issubclass(w.category, DataWarning)]
    assert len(notes) == 1 and "no std: a one-member ensemble" in notes[0]


def test_evaluate_has_no_coverage_and_divides_by_no_zero(one):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = evaluate(one)
    assert all(np.isnan(res["R_std"])) and np.isnan(res["coverage"]) and np.isnan(res["coverage_R"])
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)]  # no nanmean of nothing, no 0/0


def test_a_two_member_ensemble_keeps_its_std(tiny_physics, noisy_frf):
    from satmd.io import load_frf

    p = tiny_physics.predict(load_frf(noisy_frf))
    assert np.all(p["R_std"] > 0) and np.all(p["R_std"] < 1e3)


def test_cli_predict_and_evaluate_say_no_std(one, noisy_frf, tmp_path, capsys):
    one.save(tmp_path / "m")
    capsys.readouterr()
    assert main(["inverse", "predict", str(tmp_path / "m"), str(noisy_frf), "--json"]) == 0
    cap = capsys.readouterr()
    p = json.loads(cap.out)
    assert p["R_std"] is None and p["L_std"] is None and p["explained"] is False
    assert any(w.startswith("no std: a one-member ensemble") for w in p["warnings"])
    assert "not finite" not in cap.err and len(cap.err.strip().splitlines()) == 1  # the reason, once
    assert main(["inverse", "predict", str(tmp_path / "m"), str(noisy_frf)]) == 0
    out = capsys.readouterr().out
    assert "Ω (no std)" in out and "±" not in out
    assert main(["inverse", "evaluate", str(tmp_path / "m"), "--json"]) == 0
    cap = capsys.readouterr()
    doc = json.loads(cap.out)
    assert doc["coverage"] is None and all(r["R_std"] is None and r["L_std"] is None for r in doc["rows"])
    assert "no std" in cap.err and "not finite" not in cap.err

import json

import numpy as np
import pytest

pytest.importorskip("torch")

from satmd import Rig, save_frf, simulate
from satmd.cli import main


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    out = tmp_path_factory.mktemp("inv") / "model"
    rc = main(["inverse", "train", "--kind", "supervised", "--epochs", "2", "--samples-per-pair", "4",
               "--members", "2", "--seed", "1", "--quiet", "--out", str(out)])
    assert rc == 0
    return out


def test_train_writes_weights_and_metadata(trained, capsys):
    assert (trained / "model.json").is_file() and (trained / "weights.pt").is_file()
    meta = json.loads((trained / "model.json").read_text())
    assert meta["kind"] == "supervised" and meta["preset"] == "paper"


def test_predict_json(trained, tmp_path, capsys):
    f = tmp_path / "d.csv"
    save_frf(simulate(rig=Rig(R=30.0, L=0.15), noise=0.01, seed=0), f)
    capsys.readouterr()
    assert main(["inverse", "predict", str(trained), str(f), "--json"]) == 0
    p = json.loads(capsys.readouterr().out)
    assert set(p) == {"R", "L", "R_std", "L_std", "residual", "residual_expected", "residual_ratio", "explained",
                      "warnings"}
    assert all(np.isfinite(p[k]) for k in ("R", "L", "R_std", "L_std", "residual", "residual_ratio"))
    assert isinstance(p["explained"], bool) and isinstance(p["warnings"], list)
    assert main(["inverse", "predict", str(trained), str(f)]) == 0
    out = capsys.readouterr().out
    assert "R =" in out and "forward check: residual" in out


def test_predict_flags_an_unexplained_rig(trained, tmp_path, capsys):
    """SPEC §5's rig is fixed; data from another rig (m2 0.7, kp 1.5e5) must not pass silently."""
    f = tmp_path / "offm.csv"
    save_frf(simulate(rig=Rig(m2=0.7, kp=1.5e5, R=22.0, L=0.064), noise=0.01, seed=0), f)
    # least squares: the best R, L of the paper's rig; still no explanation of this rig's data
    model = tmp_path / "opt"
    assert main(["inverse", "train", "--kind", "optimization", "--quiet", "--out", str(model)]) == 0
    capsys.readouterr()
    assert main(["inverse", "predict", str(model), str(f), "--json"]) == 0
    cap = capsys.readouterr()
    p = json.loads(cap.out)
    assert p["explained"] is False and p["residual_ratio"] > 3
    assert any("does not explain the data" in w for w in p["warnings"])
    assert "satmd inverse predict: warning:" in cap.err and len(cap.err.strip().splitlines()) == len(p["warnings"])


def test_predict_takes_lab_grids_and_band(trained, tmp_path, capsys):
    f = tmp_path / "lab.csv"
    save_frf(simulate(freq_hz=np.linspace(20, 200, 721), rig=Rig(R=30.0, L=0.15), noise=0.005, seed=1), f)
    capsys.readouterr()
    assert main(["inverse", "predict", str(trained), str(f), "--json"]) == 0
    p = json.loads(capsys.readouterr().out)
    assert np.isfinite(p["R"]) and not any("cover" in w for w in p["warnings"])
    assert main(["inverse", "predict", str(trained), str(f), "--band", "50:110", "--json"]) == 0
    cap = capsys.readouterr()
    p = json.loads(cap.out)
    assert np.isfinite(p["R"]) and any("not the model's 40..130 Hz" in w for w in p["warnings"])
    assert "filled from the forward model" in cap.err


def test_predict_takes_a_recording(trained, tmp_path, capsys):
    from satmd.io import save_recording
    from satmd.simulation import simulate_recording

    rec = tmp_path / "rec.npz"
    save_recording(simulate_recording(20.0, rig=Rig(R=30.0, L=0.15), seed=0), rec)
    capsys.readouterr()
    assert main(["inverse", "predict", str(trained), str(rec), "--json"]) == 0
    p = json.loads(capsys.readouterr().out)
    assert np.isfinite(p["R"]) and np.isfinite(p["residual"])


def test_evaluate_json(trained, capsys):
    capsys.readouterr()
    assert main(["inverse", "evaluate", str(trained), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert len(res["rows"]) == 6 and res["rows"][0]["R"] == 8.0
    assert {"mae_R", "mae_L", "coverage"} <= set(res)
    assert main(["inverse", "evaluate", str(trained)]) == 0
    assert "MAE R" in capsys.readouterr().out


def test_errors_are_one_line(tmp_path, capsys):
    assert main(["inverse", "evaluate", str(tmp_path / "nothing")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("satmd inverse: error:") and "\n" not in err
    assert main(["inverse", "train", "--noise", "-1", "--out", str(tmp_path / "x")]) == 2
    assert "--noise" in capsys.readouterr().err
    f = tmp_path / "short.csv"
    save_frf(simulate(freq_hz=np.linspace(40, 130, 20)), f)
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "model.json").write_text("{not json")
    assert main(["inverse", "predict", str(tmp_path / "m"), str(f)]) == 2
    assert "invalid JSON" in capsys.readouterr().err

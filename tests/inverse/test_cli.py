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
    assert set(p) == {"R", "L", "R_std", "L_std"}
    assert all(np.isfinite(v) for v in p.values())
    assert main(["inverse", "predict", str(trained), str(f)]) == 0
    assert "R =" in capsys.readouterr().out


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

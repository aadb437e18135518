"""`satmd discover ... --save-model` and `satmd predict` (issue 47, SPEC §11) on the independent chain."""
from __future__ import annotations

import json

import numpy as np
import pytest

from satmd.io import save_recording
from tests.structure.chain import simulate_chain

from ._cli import refused, run


@pytest.fixture(scope="module")
def levels(tmp_path_factory):
    d = tmp_path_factory.mktemp("structure")
    recs = simulate_chain(joint=(2, 3), law=lambda dd, v: 3e9 * dd ** 3, levels=(1.0, 3.0, 8.0), seed=1, period=512)
    for r, name in zip(recs, ("L1", "L3", "L8")):
        save_recording(r, d / f"{name}.csv")
    return d


def test_discover_saves_the_model_and_predict_judges_a_level_it_never_saw(capsys, levels, tmp_path, monkeypatch):
    """The whole path: located, fitted, saved, drawn (the sensors, the evidence and the fit's panel), each level's
    force read once however many stages (locate, fit, simulate) follow; then a level it never saw predicted."""
    from matplotlib.image import imread

    from tests.signal.test_memo import count_detections

    model, figure = tmp_path / "structure.json", tmp_path / "discover.png"
    calls = count_detections(monkeypatch)
    rc, out, err = run(capsys, "discover", levels / "L1.csv", levels / "L8.csv", "--save-model", model, "--json",
                       "--plot", figure)
    assert rc == 0, err
    assert len(calls) == 2
    height, width = imread(figure).shape[:2]
    assert width > 3.5 * height  # three panels side by side (two without a fitted model)
    assert "locating the joint" in err and "output-error fit of the" in err  # minutes of work, told stage by stage
    joint = json.loads(out)["nonlinear"]["findings"][0]
    assert joint["name"] == "joint" and joint["between"] == ["acc3", "acc4"]
    assert joint["fit"]["metric"] == "nrmse" and len(joint["fit"]["nonlinear"]) == 2
    assert max(joint["fit"]["nonlinear"][1]) < max(joint["fit"]["linear"][1])
    assert "k3" in joint["parameters"]
    rc, out, err = run(capsys, "predict", model, levels / "L3.csv", "--json", "--plot", tmp_path / "L3.png")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["schema"] == "satmd-prediction/1"
    (p,) = doc["recordings"]
    assert p["channels"] == [f"acc{i}" for i in range(1, 6)] and p["extrapolated"] is False
    assert max(p["nrmse"]) < 0.016 and np.isfinite(p["linear_nrmse"]).all()
    assert (tmp_path / "L3.png").stat().st_size > 0
    rc, out, err = run(capsys, "predict", model, levels / "L3.csv")
    assert rc == 0 and "NRMSE acc1" in out and "note" not in err
    lines = (levels / "L3.csv").read_text().splitlines()  # a sensor more than the model's: said, not refused
    more = tmp_path / "more.csv"
    more.write_text("\n".join([lines[0], lines[1] + ",acc9", *(r + "," + r.split(",")[2] for r in lines[2:])]) + "\n")
    rc, out, err = run(capsys, "predict", model, more)
    assert rc == 0 and "more.csv: acc9 not in the model" in err and "acc5 0.0" in out and "acc9" not in out


def test_predict_refuses_what_it_cannot_use(capsys, levels, tmp_path):
    not_model = tmp_path / "not_model.json"
    not_model.write_text('{"schema": "satmd-report/1"}')
    refused(capsys, "predict", not_model, levels / "L3.csv", says=("not a structure model",))
    refused(capsys, "predict", levels / "missing.json", levels / "L3.csv", says=("missing.json",))


def test_a_refusal_names_the_level_at_fault_not_the_first(capsys, levels, tmp_path):
    """Of several levels, the one whose force is constant, or holds a NaN, is named; the first level is not."""
    lines = (levels / "L8.csv").read_text().splitlines()
    head, rows = lines[:2], [row.split(",") for row in lines[2:]]
    still = tmp_path / "still.csv"
    still.write_text("\n".join([*head, *(",".join([r[0], "0", *r[2:]]) for r in rows)]) + "\n")
    line = refused(capsys, "discover", levels / "L1.csv", still, says=("still.csv: the force is constant",))
    assert "L1.csv" not in line
    rows[40][3] = "nan"
    holed = tmp_path / "holed.csv"
    holed.write_text("\n".join([*head, *(",".join(r) for r in rows)]) + "\n")
    line = refused(capsys, "discover", levels / "L1.csv", holed, says=("holed.csv, line 43",))
    assert "L1.csv" not in line


def test_save_model_needs_a_structure(capsys, levels, tmp_path):
    """One recording of one level: no structure model to save; said in one line, nothing written."""
    out = tmp_path / "m.json"
    refused(capsys, "discover", levels / "L1.csv", "--save-model", out, says=("--save-model",), alone=False)
    assert not out.exists()


def test_locate_only_places_the_joint_in_seconds_and_refuses_what_needs_a_model(capsys, levels, tmp_path):
    rc, out, err = run(capsys, "discover", levels / "L1.csv", levels / "L8.csv", "--locate-only", "--json")
    assert rc == 0, err
    assert "locating the joint" in err and "output-error fit" not in err
    joint = json.loads(out)["nonlinear"]["findings"][0]
    assert joint["between"] == ["acc3", "acc4"] and "fit" not in joint
    out_model = tmp_path / "m.json"
    refused(capsys, "discover", levels / "L1.csv", levels / "L8.csv", "--locate-only", "--save-model", out_model,
            says=("--locate-only",), alone=False)
    refused(capsys, "discover", levels / "L1.csv", "--locate-only", says=("--locate-only",), alone=False)
    assert not out_model.exists()


def test_a_structure_with_no_joint_saves_its_linear_model(capsys, tmp_path):
    """SPEC §11: no joint, no joint finding, and the linear model predicts every level within the noise; its
    model is saved as asked, not refused (a ground vibration test of a linear structure is a result too)."""
    recs = simulate_chain(joint=(2, 3), law=lambda dd, v: 0.0 * dd, levels=(1.0, 3.0, 8.0), seed=2, period=512)
    for r, name in zip(recs, ("L1", "L3", "L8")):
        save_recording(r, tmp_path / f"{name}.csv")
    model = tmp_path / "linear.json"
    rc, out, err = run(capsys, "discover", tmp_path / "L1.csv", tmp_path / "L8.csv", "--save-model", model, "--json")
    assert rc == 0, err
    assert not any(f["name"] == "joint" for f in (json.loads(out).get("nonlinear") or {}).get("findings", []))
    rc, out, err = run(capsys, "predict", model, tmp_path / "L3.csv", "--json")
    assert rc == 0, err
    (p,) = json.loads(out)["recordings"]
    assert max(p["nrmse"]) < 0.03 and p["nrmse"] == p["linear_nrmse"]  # 1 % noise on every channel

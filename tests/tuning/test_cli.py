"""`satmd tune` on files, a model rig and a drifting series; bad input is one line, exit 2."""
import json

import pytest

from satmd import Rig, save_frf, simulate
from satmd.cli import main

SPEC_KEYS = ["objective", "output", "band_hz", "design", "value", "current", "attenuation_db", "model", "robust"]


@pytest.fixture(scope="module")
def frf_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("tune") / "rig.csv"
    save_frf(simulate(noise=0.01, seed=4), path)
    return path


def test_json_from_data(frf_file, capsys, tmp_path):
    fig = tmp_path / "tune.png"
    assert main(["tune", str(frf_file), "--json", "--plot", str(fig)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert list(out) == SPEC_KEYS
    assert out["objective"] == "hinf" and out["output"] == "u1" and out["band_hz"] == [20.0, 200.0]
    assert out["design"]["R"] == pytest.approx(47, rel=0.05)
    assert out["attenuation_db"]["vs_current"] == pytest.approx(8.7, abs=0.2)
    assert fig.stat().st_size > 1000


def test_text_report_for_a_model_rig(capsys):
    assert main(["tune", "--rig", "m2=0.6,kp=1.2e5", "--objective", "h2", "--output", "a1", "--band", "30:150",
                 "--bounds", "R=1:500,L=0.01:2"]) == 0
    out = capsys.readouterr().out
    assert "RMS (H2) of |A1| over 30–150 Hz" in out and "m2 = 0.6" in out


def test_robust_model_rig_with_given_uncertainty(capsys):
    assert main(["tune", "--rig", "--robust", "0.9", "--uncertainty", "kp=5e3", "--draws", "16", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["robust"]["quantile"] == 0.9 and out["robust"]["parameters"] == ["kp"]


def test_series_retunes_each_step(tmp_path, capsys):
    folder = tmp_path / "drift"
    folder.mkdir()
    for i, kp in enumerate((111e3, 100e3, 90e3)):
        save_frf(simulate(rig=Rig(kp=kp), noise=0.005, seed=i), folder / f"step{i}.csv")
    fig = tmp_path / "drift.png"
    assert main(["tune", str(folder), "--json", "--plot", str(fig)]) == 0
    out = json.loads(capsys.readouterr().out)
    steps = out["steps"]
    assert [s["label"] for s in steps] == ["step0", "step1", "step2"]
    assert steps[0]["retuning_gain_db"] == pytest.approx(0.0, abs=1e-6)
    assert steps[2]["retuning_gain_db"] > 0.05  # kp drifted 20 %: retuning pays
    assert steps[2]["parameters"]["kp"] == pytest.approx(90e3, rel=0.01)
    assert fig.exists()


@pytest.mark.parametrize("argv, match", [
    (["tune"], "give DATA"),
    (["tune", "missing.csv"], "no such file"),
    (["tune", "--rig", "R=-1"], "--rig"),
    (["tune", "--rig", "--band", "200:20"], "band"),
    (["tune", "--rig", "--objective", "h2", "--design", "R,F0"], "design"),
    (["tune", "--rig", "--plot", "no/such/dir/fig.png"], "does not exist"),
    (["tune", "--rig", "--plot", "fig.txt"], "cannot write"),
    (["tune", "--rig", "--robust"], "uncertainty"),
    (["tune", "--rig", "--robust", "1.5"], "quantile"),
    (["tune", "--rig", "--bounds", "R=5"], "NAME=LO:HI"),
])
def test_bad_input_is_one_line_exit_2(argv, match, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("satmd tune: error:") and match in err and "\n" not in err


def test_bad_data_file_is_refused_before_work(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("# satmd-frf v1\nfreq_hz,a1_re\n1,2\n")
    assert main(["tune", str(bad), "--plot", str(tmp_path / "x.png")]) == 2
    assert "satmd tune: error:" in capsys.readouterr().err
    assert not (tmp_path / "x.png").exists()

"""`satmd identify`: JSON output, plots, one-line errors."""
from __future__ import annotations

import json

import pytest

from satmd import PAPER_GRID_HZ, Rig, save_frf, simulate
from satmd.cli import main


@pytest.fixture(scope="module")
def frf_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("identify") / "rig.csv"
    save_frf(simulate(PAPER_GRID_HZ, Rig(R=40.0, L=0.2), noise=0.01, seed=1), path)
    return path


def test_identify_json(frf_file, capsys):
    assert main(["identify", str(frf_file), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("parameters", "std", "correlation", "chi2_reduced", "rel_error", "fit_percent"):
        assert key in out
    assert set(out["parameters"]) == {"m2", "kp", "R", "L"}
    assert out["parameters"]["R"] == pytest.approx(40.0, rel=0.05)
    assert out["parameters"]["L"] == pytest.approx(0.2, rel=0.05)
    assert 0.5 < out["chi2_reduced"] < 1.5
    assert out["noise"] == "given"


def test_identify_text_report(frf_file, capsys):
    assert main(["identify", str(frf_file), "--free", "R,L", "--local", "--init", "R=30,L=0.15"]) == 0
    out = capsys.readouterr().out
    assert "[[Variables]]" in out and "R " in out and "L " in out


def test_identify_plot_writes_png(frf_file, tmp_path, capsys):
    png = tmp_path / "fit.png"
    assert main(["identify", str(frf_file), "--json", "--plot", str(png)]) == 0
    json.loads(capsys.readouterr().out)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("content", [
    "# satmd-frf v1\nfreq_hz,a1_re,a1_im\n40.0,1.0,nan\n",
    "# satmd-frf v1\nfreq_hz,a1_re,a1_im\n41.0,1.0,0.0\n40.0,1.0,0.0\n",
    "not a csv at all\n",
], ids=["nan", "decreasing-frequency", "garbage"])
def test_identify_bad_file_exit_2_one_line(tmp_path, capsys, content):
    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    assert main(["identify", str(bad), "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("satmd identify: error:")
    assert "bad.csv" in lines[0]


def test_identify_missing_file(tmp_path, capsys):
    assert main(["identify", str(tmp_path / "nope.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nope.csv" in err[0]


def test_identify_bad_free_parameter(frf_file, capsys):
    assert main(["identify", str(frf_file), "--free", "m2,bogus"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bogus" in err[0]

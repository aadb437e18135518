"""satmd tune --levels / --nonlinear: tuning a nonlinear rig across drive levels from the command line."""
from __future__ import annotations

import json

import pytest

from satmd.physics.nonlinear import kernel

from ._cli import refused, run


@pytest.mark.parametrize("argv, says", [
    (["--rig", "--levels", "1,4"], ["--levels", "--nonlinear"]),
    (["--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11"], ["--levels"]),
    (["--rig", "--nonlinear", "bogus:k3=1", "--levels", "1"], ["bogus", "known"]),
    (["--rig", "--nonlinear", "cubic_absorber_spring", "--levels", "1"], ["cubic_absorber_spring", "k3="]),
    (["--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11", "--levels", "1,-4"], ["--levels", "> 0"]),
    (["--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11", "--levels", "1,x"], ["--levels"]),
    (["--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11", "--levels", ","], ["--levels"]),
    (["--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11", "--levels", "1", "--objective", "h2"], ["h2"]),
    (["--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11", "--levels", "1", "--design", "R"], ["R,L"]),
    (["--rig", "--nonlinear", "cubic_absorber_spring:bad=2", "--levels", "1"], ["--nonlinear"]),
])
def test_bad_input_exits_2_with_one_line(capsys, argv, says):
    refused(capsys, "tune", *argv, says=says)


def test_data_needs_the_element_and_recordings(capsys, tmp_path):
    from satmd import simulate
    from satmd.io import save_recording

    rec = simulate(time=True, duration_s=2.0, fs_hz=1024.0, level=1.0, seed=0)
    path = save_recording(rec, tmp_path / "low.csv")
    refused(capsys, "tune", path, "--levels", "1,4", says=["--nonlinear"])
    refused(capsys, "tune", path, "--levels", "1", "--nonlinear", "cubic_absorber_spring:k3=1", says=["name only"])


@pytest.mark.skipif(not kernel.available, reason="numba not installed")
def test_model_rig_tuned_over_levels(capsys):
    rc, out, err = run(capsys, "tune", "--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11",
                       "--levels", "1,10", "--json")
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["levels"] == [1.0, 10.0] and len(doc["peaks_db"]) == 2
    assert doc["worst_db"] == max(doc["peaks_db"])
    assert doc["cost_of_linear_db"] >= -0.05  # the level-aware design is no worse than the low-level one
    assert 0.1 < doc["design"]["R"] < 1000 and 1e-3 < doc["design"]["L"] < 5

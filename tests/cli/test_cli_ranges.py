"""Refusals name the cause as the user gave it: the option as typed, its usable range, the file (issue 38 item 3)."""
from __future__ import annotations

import numpy as np
import pytest

from satmd import Rig, save_frf, simulate

from ._cli import refused, run


@pytest.fixture(scope="module")
def paper(tmp_path_factory):
    path = tmp_path_factory.mktemp("ranges") / "p.csv"
    save_frf(simulate(rig=Rig(), noise=0.01, seed=1), path)
    return path


@pytest.mark.parametrize("option, value, limit", [("--m2", "1e300", "518000"), ("--kp", "1e308", "1.11e+11"),
                                                  ("--L", "1e-300", "6.4e-08")])
def test_simulate_rig_values_beyond_the_usable_range(capsys, tmp_path, option, value, limit):
    refused(capsys, "simulate", option, value, "-o", tmp_path / "s.csv", says=(option, limit, "SI units"))
    assert not (tmp_path / "s.csv").exists()


def test_a_zero_shunt_is_still_a_shunt(capsys, tmp_path):
    assert run(capsys, "simulate", "--R", "0", "-o", tmp_path / "s.csv")[0] == 0


@pytest.mark.parametrize("argv, says", [
    (["--burn-in", "1e9"], ("--burn-in", "at most")),
    (["--fs", "1e-300"], ("--fs", "--force-band")),
    (["--excitation", "multisine", "--periods", "1000000000"], ("--periods", "--duration")),
    (["--excitation", "multisine", "--periods", "0"], ("--periods 0",)),
    (["--nonlinear", "cubic_absorber_spring:k3=1e300"], ("--nonlinear", "k3", "usable")),
])
def test_simulate_time_options_name_themselves(capsys, tmp_path, argv, says):
    line = refused(capsys, "simulate", "--time", "--duration", "2", *argv, "-o", tmp_path / "r.csv", says=says)
    assert "NaN" not in line


def test_burn_in_is_not_blamed_on_fs_and_duration(capsys, tmp_path):
    line = refused(capsys, "simulate", "--time", "--burn-in", "1e9", "-o", tmp_path / "r.csv", says=("--burn-in",))
    assert not line.split(": error: ")[1].startswith("--fs")


def test_tune_names_data_band_as_typed(capsys, paper):
    line = refused(capsys, "tune", paper, "--data-band", "120:40", says=("--data-band '120:40'", "LO must be below HI"))
    assert "--band '" not in line


def test_tune_names_the_file_the_model_cannot_describe(capsys, tmp_path):
    f = np.linspace(40.0, 130.0, 60)
    w = 2 * np.pi * f
    a1 = -w ** 2 / (4e6 - w ** 2 + 30j * w)  # a 1-DOF accelerance: no SATMD rig gives it
    path = tmp_path / "one_dof.csv"
    rows = [f"{x:.17g},{z.real:.17g},{z.imag:.17g}" for x, z in zip(f, a1)]
    path.write_text("freq_hz,a1_re,a1_im\n" + "\n".join(rows) + "\n")
    refused(capsys, "tune", path, "--no-discover", says=("one_dof.csv", "--force"), alone=False)


@pytest.mark.parametrize("argv, says", [
    (["identify", "{paper}", "--init", "m2=1e300"], ("--init m2=", "bounds")),
    (["identify", "{paper}", "--reg", "1e300"], ("--reg",)),
    (["inverse", "train", "--epochs", "1000000000", "--out", "{tmp}/m"], ("--epochs", "10000")),
    (["inverse", "train", "--samples-per-pair", "1000000000", "--out", "{tmp}/m"], ("--samples-per-pair",)),
    (["inverse", "train", "--threads", "1000000", "--out", "{tmp}/m"], ("--threads", "256")),
    (["inverse", "train", "--warm-start", "90", "--out", "{tmp}/m"], ("--warm-start 90", "--epochs 90")),
    (["inverse", "train", "--kind", "supervised", "--warm-start", "5", "--out", "{tmp}/m"], ("--warm-start",)),
    (["explain", "{tmp}", "--threads", "1000000"], ("--threads", "256")),
    (["tune", "--rig", "--levels", "1e300", "--nonlinear", "cubic_absorber_spring:k3=2e11"], ("--levels", "1e+12")),
    (["tune", "--rig", "--levels", "1", "--nonlinear", "cubic_absorber_spring:k3=1e300"], ("--nonlinear", "k3")),
    (["tune", "--rig", "m2=1e300"], ("--rig m2=", "5.18e-07..518000")),
])
def test_out_of_range_options_are_refused_by_name(capsys, tmp_path, paper, argv, says):
    argv = [a.replace("{paper}", str(paper)).replace("{tmp}", str(tmp_path)) for a in argv]
    refused(capsys, *argv, says=says)
    assert not (tmp_path / "m").exists()


def test_several_files_never_end_in_a_type_error(capsys, tmp_path, paper):
    """`discover_many` / `identify_many` refuse wrong types with a TypeError (Python's way); the commands load
    every file themselves, so a bad one is a refusal naming it."""
    for argv in (["discover", paper, tmp_path / "x.csv"], ["tune", paper, tmp_path / "x.csv"]):
        line = refused(capsys, *argv, says=("x.csv",))
        assert "TypeError" not in line

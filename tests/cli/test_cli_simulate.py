"""`satmd simulate`: files equal satmd.simulation.frf.simulate(...) exactly; bad input
is one line on stderr, exit status 2, and no file written or destroyed."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from satmd.cli import main
from satmd.io import load_frf
from satmd.physics import OFFSET_PARAMETERS, PAPER_GRID_HZ, Rig, effect
from satmd.simulation.frf import simulate

ALL = ("a1", "a2", "u1", "u2", "q")

# (command-line spec, effect name, parameters)
EFFECTS = [
    ("sensor_gain:gain_a1=1.05,gain_a2=0.95", "sensor_gain", dict(gain_a1=1.05, gain_a2=0.95)),
    ("time_delay:tau_s=1e-4", "time_delay", dict(tau_s=1e-4)),
    ("structural_damping:eta=0.02", "structural_damping", dict(eta=0.02)),
    ("dielectric_loss:tan_delta=0.03", "dielectric_loss", dict(tan_delta=0.03)),
    ("shunt_capacitance:Cs=2e-6", "shunt_capacitance", dict(Cs=2e-6)),
    ("extra_mode:f_hz=66,zeta=0.01,mass_ratio=0.01", "extra_mode", dict(f_hz=66.0, zeta=0.01, mass_ratio=0.01)),
    ("extra_mode:f_hz=90,mass_ratio=0.02", "extra_mode", dict(f_hz=90.0, mass_ratio=0.02)),  # default zeta
] + [(f"parameter_offset:{p}:value={1.2 * getattr(Rig(), p)!r}", f"parameter_offset:{p}",
      dict(value=1.2 * getattr(Rig(), p))) for p in OFFSET_PARAMETERS]


def _same(a, b):
    np.testing.assert_array_equal(a.freq_hz, b.freq_hz)
    assert list(a.channels) == list(b.channels)
    for c in a.channels:
        np.testing.assert_array_equal(a.channels[c], b.channels[c])
    assert set(a.std) == set(b.std)
    for c in a.std:
        np.testing.assert_array_equal(a.std[c], b.std[c])


def _run(capsys, *argv):
    code = main(["simulate", *argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("spec, name, params", EFFECTS, ids=[e[0] for e in EFFECTS])
def test_each_effect_written_file_equals_simulate(tmp_path, capsys, spec, name, params):
    out = tmp_path / "sim.csv"
    code, stdout, err = _run(capsys, "--effect", spec, "--channels", ",".join(ALL), "-o", str(out))
    assert code == 0 and err == ""
    assert str(out) in stdout
    want = simulate(PAPER_GRID_HZ, Rig(), [effect(name, **params)], ALL)
    _same(load_frf(out), want)
    # and the effect made a difference (the comparison could fail)
    nominal = simulate(PAPER_GRID_HZ, Rig(), [], ALL)
    assert np.max(np.abs(want["a1"] - nominal["a1"])) > 1e-6 * np.max(np.abs(nominal["a1"]))


def test_rig_options_grid_and_several_effects(tmp_path, capsys):
    out = tmp_path / "sim.csv"
    code, _, err = _run(capsys, "--m2", "0.6", "--kp", "1.5e5", "--R", "35", "--L", "0.2", "--freq", "20:300:41",
                        "--effect", "extra_mode:f_hz=66,zeta=0.01,mass_ratio=0.01",
                        "--effect", "time_delay:tau_s=-5e-5", "--channels", "a2,q", "-o", str(out))
    assert code == 0, err
    want = simulate(np.linspace(20, 300, 41), Rig(m2=0.6, kp=1.5e5, R=35.0, L=0.2),
                    [effect("extra_mode", f_hz=66.0, zeta=0.01, mass_ratio=0.01), effect("time_delay", tau_s=-5e-5)],
                    ("a2", "q"))
    got = load_frf(out)
    _same(got, want)
    assert got.names == ("a2", "q") and not got.std


def test_default_is_the_paper_rig_on_the_paper_grid(tmp_path, capsys):
    out = tmp_path / "sim.csv"
    assert _run(capsys, "-o", str(out))[0] == 0
    got = load_frf(out)
    _same(got, simulate())
    assert got.names == ("a1", "a2") and len(got) == 60


def test_noise_with_seed_is_reproducible_and_adds_std(tmp_path, capsys):
    a, b, c = tmp_path / "a.csv", tmp_path / "b.csv", tmp_path / "c.csv"
    args = ["--noise", "0.01:0.001", "--effect", "structural_damping:eta=0.01"]
    assert _run(capsys, *args, "--seed", "7", "-o", str(a))[0] == 0
    assert _run(capsys, *args, "--seed", "7", "-o", str(b))[0] == 0
    assert _run(capsys, *args, "--seed", "8", "-o", str(c))[0] == 0
    assert a.read_bytes() == b.read_bytes()
    da, dc = load_frf(a), load_frf(c)
    assert da.has_std and set(da.std) == {"a1", "a2"}
    header = next(line for line in a.read_text().splitlines() if not line.startswith("#"))
    assert header.split(",") == ["freq_hz", "a1_re", "a1_im", "a2_re", "a2_im", "a1_std", "a2_std"]
    want = simulate(PAPER_GRID_HZ, Rig(), [effect("structural_damping", eta=0.01)], noise=(0.01, 0.001), seed=7)
    _same(da, want)
    assert not np.array_equal(da["a1"], dc["a1"])
    np.testing.assert_array_equal(da.std["a1"], dc.std["a1"])
    clean = simulate(PAPER_GRID_HZ, Rig(), [effect("structural_damping", eta=0.01)])
    # std = 0.01|A| + 0.001 max|A|, and the noise is of that size
    s = 0.01 * np.abs(clean["a1"]) + 0.001 * np.max(np.abs(clean["a1"]))
    np.testing.assert_allclose(da.std["a1"], s, rtol=1e-15)
    z = np.concatenate([(da["a1"] - clean["a1"]).real / s, (da["a1"] - clean["a1"]).imag / s])
    assert 0.5 < np.std(z) < 1.5
    # REL alone
    d = tmp_path / "d.csv"
    assert _run(capsys, "--noise", "0.02", "--seed", "1", "-o", str(d))[0] == 0
    np.testing.assert_allclose(load_frf(d).std["a2"], 0.02 * np.abs(simulate()["a2"]), rtol=1e-15)


BAD = [
    ("--effect", "no_such_effect:x=1"),
    ("--effect", "extra_mode"),  # f_hz required
    ("--effect", "extra_mode:f_hz=abc"),
    ("--effect", "extra_mode:f_hz=nan"),
    ("--effect", "extra_mode:f_hz=66,bogus=1"),
    ("--effect", "time_delay:tau_s=5"),  # out of range
    ("--effect", "structural_damping:eta=-0.1"),
    ("--effect", "sensor_gain:gain_a1"),
    ("--effect", "parameter_offset:m2:value=0.5"),
    ("--effect", "parameter_offset:k1:value=-1"),
    ("--freq", "130:40:60"),
    ("--freq", "40:130"),
    ("--freq", "0:130:60"),
    ("--freq", "a:b:c"),
    ("--freq", "40:130:1"),
    ("--freq", "40:130:6.5"),
    ("--freq", "40:inf:60"),
    ("--noise", "abc"),
    ("--noise", "-0.01"),
    ("--noise", "0"),
    ("--noise", "0.01:-1"),
    ("--noise", "0.01:x"),
    ("--noise", "nan"),
    ("--channels", "a1,a3"),
    ("--m2", "-0.5"),
    ("--R", "nan"),
]


@pytest.mark.parametrize("option, value", BAD, ids=[f"{o}={v}" for o, v in BAD])
def test_bad_input_exit_2_one_line_no_file(tmp_path, capsys, option, value):
    out = tmp_path / "out.csv"
    code, stdout, err = _run(capsys, option, value, "-o", str(out))
    assert code == 2
    lines = err.strip("\n").split("\n")
    assert len(lines) == 1 and lines[0].startswith("satmd simulate: error:"), err
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []  # no temporary file either


@pytest.mark.parametrize("option, value", [("--effect", "extra_mode:f_hz=-1"), ("--freq", "1:2"),
                                           ("--noise", "-1")])
def test_failure_keeps_an_existing_output_file(tmp_path, capsys, option, value):
    out = tmp_path / "precious.csv"
    out.write_text("do not destroy\n")
    code, _, err = _run(capsys, option, value, "-o", str(out))
    assert code == 2 and err.count("\n") == 1
    assert out.read_text() == "do not destroy\n"


def test_output_into_a_missing_folder_fails_cleanly(tmp_path, capsys):
    out = tmp_path / "missing" / "out.csv"
    code, _, err = _run(capsys, "-o", str(out))
    assert code == 2 and err.count("\n") == 1
    assert not out.parent.exists()


def _satmd_command():
    exe = Path(sys.executable).parent / "satmd"
    if exe.exists():
        return [str(exe)]
    found = shutil.which("satmd")
    if found:
        return [found]
    return [sys.executable, "-c", "import sys; from satmd.cli import main; sys.exit(main())"]


def test_subprocess_exit_status_and_single_stderr_line(tmp_path):
    out = tmp_path / "out.csv"
    out.write_text("keep me\n")
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    proc = subprocess.run(_satmd_command() + ["simulate", "--effect", "extra_mode:f_hz=66,zeta=-1", "-o", str(out)],
                          capture_output=True, text=True, timeout=120, env=env)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("satmd simulate: error:"), proc.stderr
    assert "zeta" in proc.stderr
    assert proc.stdout == ""
    assert out.read_text() == "keep me\n"
    good = tmp_path / "good.csv"
    proc = subprocess.run(_satmd_command() + ["simulate", "--freq", "40:130:5", "-o", str(good)],
                          capture_output=True, text=True, timeout=120, env=env)
    assert proc.returncode == 0, proc.stderr
    _same(load_frf(good), simulate(np.linspace(40, 130, 5)))

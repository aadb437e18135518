"""Hostile command lines (issue 28): one representative per family, each refused naming the option or file.

The full set (1500+ cases, signals included) is `benchmarks/fuzz.py`.
"""
from __future__ import annotations

import numpy as np
import pytest

from satmd.cli import main

from ._cli import refused, run


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    import contextlib
    import io

    d = tmp_path_factory.mktemp("hostile")
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["simulate", "--freq", "40:130:20", "--noise", "0.01", "--seed", "1", "-o", str(d / "f.csv")]) == 0
        assert main(["simulate", "--freq", "40:130:20", "-o", str(d / "f.uff")]) == 0
        assert main(["simulate", "--time", "--duration", "2", "--fs", "400", "--force-band", "20:150", "--seed", "2",
                     "-o", str(d / "r.csv")]) == 0
    return d


def test_duplicate_channels_are_refused(capsys, files):
    refused(capsys, "identify", files / "f.csv", "--channels", "a1,a1", says=("--channels", "twice"))
    refused(capsys, "simulate", "--channels", "a1,a1", "-o", files / "x.csv", says=("--channels",))


@pytest.mark.parametrize("spec", ["a1=#99", "a1=#1,a2=#1", "a1=1:3,a2=1:+Z"])
def test_maps_are_checked_on_uff_files(capsys, files, spec):
    refused(capsys, "identify", files / "f.uff", "--map", spec, says=("--map", "f.uff"))


def test_one_column_cannot_be_two_channels(capsys, files, tmp_path):
    from satmd.io import load_recording, save_recording

    save_recording(load_recording(files / "r.csv"), tmp_path / "r.wav")
    refused(capsys, "estimate-frf", tmp_path / "r.wav", "-o", tmp_path / "o.csv", "--map", "force=#1,a1=#1,a2=#2",
            says=("--map", "#1"))


@pytest.mark.parametrize("argv, flag", [
    (["simulate", "--time", "--freq", "40:130:60"], "--freq"),  # the default value, given: still refused
    (["simulate", "--fs", "1000"], "--fs"),
    (["estimate-frf", "{r}", "--estimator", "H1", "--width", "0.5"], "--width"),
    (["estimate-frf", "{r}", "--estimator", "lpm", "--nperseg", "64"], "--nperseg"),
])
def test_options_that_do_not_apply_are_refused(capsys, files, argv, flag):
    argv = [a.replace("{r}", str(files / "r.csv")) for a in argv]
    refused(capsys, *argv, "-o", files / "never.csv", says=(flag,))
    assert not (files / "never.csv").exists()


def test_reproduce_refuses_an_unknown_section(capsys, tmp_path):
    refused(capsys, "reproduce", "--only", "bogus", "--out", tmp_path / "rep", says=("--only", "bogus", "forward"))
    assert not (tmp_path / "rep").exists()


@pytest.mark.parametrize("opt, says", [
    ("--current R=-1", ("--current", ">= 0")), ("--robust --uncertainty kp=-5", ("--uncertainty",)),
    ("--rig m1=1e300", ("--rig", "m1")), ("--bounds R=1e-300:1e300", ("--bounds",)),
    ("--robust --uncertainty kp=1e300", ("--uncertainty",)), ("--band 1e-300:1", ("--band", "GB")),
    ("--robust --uncertainty kp=5e3 --draws 1000000000", ("--draws",)),
])
def test_tune_values_out_of_range_are_refused_up_front(capsys, opt, says):
    refused(capsys, "tune", "--rig", *opt.split(), "--json", says=says)


def test_work_beyond_memory_is_refused_with_the_estimate(capsys, tmp_path):
    refused(capsys, "simulate", "--time", "--fs", "1e6", "--duration", "1", "-o", tmp_path / "r.csv",
            says=("--fs", "--duration", "GB"))
    refused(capsys, "simulate", "--noise", "1e300", "-o", tmp_path / "s.csv", says=("--noise",))


def test_messages_blame_the_right_option(capsys, files, tmp_path):
    refused(capsys, "simulate", "--time", "--force-band", "200:20", "-o", tmp_path / "r.csv", says=("--force-band",))
    txt = tmp_path / "v.txt"
    txt.write_text("1+1j\n2+2j\n3+3j\n")
    refused(capsys, "info", txt, "--freq-axis", "nan:1", says=("--freq-axis", "nan"))


def test_control_characters_in_file_names_are_escaped(capsys, tmp_path):
    bad = tmp_path / "\x1b[31mred.csv"
    bad.write_text("garbage\n")
    line = refused(capsys, "identify", bad)
    assert "\\x1b" in line


def test_unrelated_channels_are_reported(capsys, files, tmp_path):
    rows = [ln for ln in (files / "r.csv").read_text().split("\n") if ln and not ln.startswith("#")]
    a = np.array([[float(x) for x in r.split(",")] for r in rows[1:]])
    a[:, 2:] = np.random.default_rng(0).standard_normal((a.shape[0], 2))
    p = tmp_path / "n.csv"
    p.write_text("time_s,force,acc1,acc2\n" + "\n".join(",".join(repr(float(x)) for x in r) for r in a) + "\n")
    rc, out, err = run(capsys, "estimate-frf", p, "-o", tmp_path / "o.csv", "--estimator", "H1")
    assert rc == 0 and "low coherence" in err


def test_refusals_from_the_fit_name_the_file(capsys, tmp_path):
    p = tmp_path / "two.csv"
    assert run(capsys, "simulate", "--freq", "40:130:2", "-o", p)[0] == 0
    refused(capsys, "identify", p, says=(str(p),))


def test_interrupted_reproduce_leaves_the_old_report(capsys, tmp_path, monkeypatch):
    from satmd import report

    out = tmp_path / "rep"
    (out / "figures").mkdir(parents=True)
    (out / "index.md").write_text("old")
    (out / "figures" / "old.png").write_bytes(b"old")

    def interrupted(ctx, only, log):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        ctx.figure(plt.figure(), "new.png")  # a figure is written, then Ctrl-C
        raise KeyboardInterrupt

    monkeypatch.setattr(report, "_build", interrupted)
    assert run(capsys, "reproduce", "--only", "forward", "--out", out)[0] == 130
    assert (out / "index.md").read_text() == "old"
    assert sorted(p.name for p in out.rglob("*")) == ["figures", "index.md", "old.png"]

"""The faults of issue 16 (items 9-14) one by one: outputs checked first and written atomically,
refusals instead of tracebacks, conflicting options, messages in the CLI's words, strict JSON, progress."""
from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import numpy as np
import pytest

import satmd
from satmd.cli import main, os_message
from satmd.cli._common import dumps_json
from satmd.errors import FormatError
from satmd.io.atomic import all_or_none, atomic_write

from ._cli import refused, run


@pytest.fixture(scope="module")
def rec(tmp_path_factory):
    path = tmp_path_factory.mktemp("rob") / "rec.csv"
    assert main(["simulate", "--time", "--duration", "4", "--fs", "400", "--force-band", "20:150", "--noise", "0.01",
                 "--seed", "1", "-o", str(path)]) == 0
    return path


def _files(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


# --- item 9: outputs ----------------------------------------------------------------------------
def test_bad_plot_path_is_refused_before_the_data_file_is_touched(capsys, tmp_path, rec):
    g = tmp_path / "g.csv"
    g.write_text("precious\n")
    line = refused(capsys, "simulate", "-o", g, "--plot", tmp_path / "bad.xyz", says=("--plot", ".xyz"))
    assert "supported formats" not in line  # not matplotlib's own message
    refused(capsys, "estimate-frf", rec, "-o", g, "--plot", tmp_path / "bad.xyz", says=("--plot",))
    refused(capsys, "identify", rec, "--plot", tmp_path / "nodir" / "f.png", says=("--plot", "does not exist"))
    assert g.read_text() == "precious\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g.csv"]


def test_an_output_that_is_an_input_or_a_folder_is_refused(capsys, tmp_path, rec):
    before = rec.read_bytes()
    refused(capsys, "estimate-frf", rec, "-o", rec, says=("-o", "input"))
    assert rec.read_bytes() == before
    folder = tmp_path / "existing_dir.csv"
    folder.mkdir()
    refused(capsys, "simulate", "-o", folder, says=("-o", "folder"))
    refused(capsys, "simulate", "-o", tmp_path / "a.csv", "--plot", tmp_path / "a.csv", says=("--plot",))
    assert [p.name for p in tmp_path.iterdir()] == ["existing_dir.csv"] and not list(folder.iterdir())


def test_outputs_appear_together_or_not_at_all(capsys, tmp_path, monkeypatch):
    import satmd.plots

    def broken(*args, **kw):
        raise satmd.errors.SatmdError("the figure failed")

    monkeypatch.setattr(satmd.plots, "plot_frfdata", broken)
    out = tmp_path / "g.csv"
    refused(capsys, "simulate", "-o", out, "--plot", tmp_path / "g.png", says=("figure failed",))
    assert list(tmp_path.iterdir()) == []  # the data file waited for the figure


def test_atomic_write_leaves_the_old_file_or_the_new_one(tmp_path):
    p = tmp_path / "x.txt"
    p.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_write(p, "w") as fh:
            fh.write("half")
            raise RuntimeError("disk full")
    assert p.read_text() == "old" and _files(tmp_path) == {"x.txt": b"old"}
    with atomic_write(p, "w") as fh:
        fh.write("new")
    assert p.read_text() == "new" and len(list(tmp_path.iterdir())) == 1
    with pytest.raises(FormatError, match="directory"):
        with atomic_write(tmp_path, "w"):
            pass


def test_all_or_none_commits_every_file_or_none(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    with pytest.raises(KeyError):
        with all_or_none():
            with atomic_write(a) as fh:
                fh.write(b"1")
            assert not a.exists()  # not before the block ends
            raise KeyError("later failure")
    assert list(tmp_path.iterdir()) == []
    with all_or_none():
        for p in (a, b):
            with atomic_write(p) as fh:
                fh.write(b"2")
    assert _files(tmp_path) == {"a": b"2", "b": b"2"}


def test_every_writer_goes_through_atomic_write():
    """No satmd module writes a file except through atomic_write (io/atomic.py)."""
    root = Path(satmd.__file__).parent
    direct = re.compile(r"\.write_(text|bytes)\(|savefig\((?!fh)|np\.savez\((?!fh)|savemat\((?!fh)|"
                        r"torch\.save\((?!state, fh)|wavfile\.write\((?!buf)")
    # not a user's file: numba's cache stamp (below io in the layering; a torn stamp only compiles again, as
    # numba's own cache files, written beside it, would)
    cache_only = {"_compiled.py"}
    found = [f"{p.relative_to(root)}:{i}" for p in root.rglob("*.py") if str(p.relative_to(root)) not in cache_only
             for i, line in enumerate(p.read_text().splitlines(), 1)
             if direct.search(line) and not line.lstrip().startswith("#")]
    assert found == [], "write through satmd.io.atomic.atomic_write (figures: satmd.plots.save)"


# --- item 10: no tracebacks -----------------------------------------------------------------------
@pytest.fixture(scope="module")
def model_dir(tmp_path_factory):
    pytest.importorskip("torch")
    path = tmp_path_factory.mktemp("model") / "m"
    assert main(["inverse", "train", "--kind", "supervised", "--epochs", "1", "--samples-per-pair", "1",
                 "--members", "1", "--quiet", "--out", str(path)]) == 0
    return path


def _copy(src: Path, dst: Path) -> Path:
    dst.mkdir()
    for f in src.iterdir():
        (dst / f.name).write_bytes(f.read_bytes())
    return dst


def test_damaged_or_edited_models_are_refused(capsys, tmp_path, model_dir):
    paper = tmp_path / "p.csv"
    assert run(capsys, "simulate", "-o", paper)[0] == 0
    m = _copy(model_dir, tmp_path / "trunc")
    w = (m / "weights.pt").read_bytes()
    (m / "weights.pt").write_bytes(w[: len(w) // 2])
    refused(capsys, "inverse", "predict", m, paper, says=("weights.pt", "damaged or truncated"))
    m = _copy(model_dir, tmp_path / "kind")
    meta = json.loads((m / "model.json").read_text())
    (m / "model.json").write_text(json.dumps({**meta, "kind": "physics"}))
    refused(capsys, "inverse", "evaluate", m, says=("model.json",))
    # even edited consistently, and without the checksum, the training record gives it away
    del meta["sha256"]
    edited = {**meta, "kind": "physics", "params": {**meta["params"], "kind": "physics"},
              "fit_info": {**meta["fit_info"], "kind": "physics"}}
    (m / "model.json").write_text(json.dumps(edited))
    refused(capsys, "inverse", "evaluate", m, says=("kind",))
    m = _copy(model_dir, tmp_path / "nan")
    import torch

    state = torch.load(m / "weights.pt", weights_only=True)
    next(iter(state.values())).view(-1)[0] = float("nan")
    torch.save(state, m / "weights.pt")
    refused(capsys, "inverse", "predict", m, paper, says=("NaN",))


@pytest.mark.parametrize("device, says", [("bogus", "cpu, cuda"), ("cuda:x", "cpu, cuda"), ("gpu", "cpu, cuda")])
def test_bad_devices_are_refused_before_training(capsys, tmp_path, device, says):
    refused(capsys, "inverse", "train", "--device", device, "--out", tmp_path / "m", says=("--device", says))
    assert not (tmp_path / "m").exists()


def test_cuda_without_cuda_is_refused(capsys, tmp_path):
    torch = pytest.importorskip("torch")
    if torch.cuda.is_available():
        pytest.skip("this machine has CUDA")
    refused(capsys, "inverse", "train", "--device", "cuda", "--out", tmp_path / "m", says=("--device cuda", "CUDA"))


def test_huge_work_is_refused_up_front(capsys, tmp_path):
    refused(capsys, "simulate", "--time", "--duration", "1e7", "-o", tmp_path / "r.csv", says=("--duration", "samples"))
    refused(capsys, "simulate", "--freq", "40:130:1000000000", "-o", tmp_path / "f.csv", says=("--freq", "points"))
    assert list(tmp_path.iterdir()) == []


def test_a_real_bug_keeps_its_traceback(monkeypatch):
    import satmd.cli.info as info

    def bug(*args, **kw):
        raise KeyError("a bug")

    monkeypatch.setattr(info, "describe", bug)
    with pytest.raises(KeyError):
        main(["info", __file__])
    monkeypatch.setattr(info, "describe", lambda *a, **k: float("x"))  # a plain ValueError is a bug too
    with pytest.raises(ValueError):
        main(["info", __file__])


# --- items 11-12: refusals instead of silence ---------------------------------------------------------
@pytest.mark.parametrize("alpha", ["0", "1", "2", "nan", "inf", "-0.1"])
def test_discover_alpha_must_be_a_level(capsys, tmp_path, alpha):
    refused(capsys, "discover", tmp_path / "any.csv", "--alpha", alpha, says=("--alpha",))


def test_json_never_holds_nan(capsys):
    text = dumps_json({"a": float("nan"), "b": [1.0, float("inf")], "c": np.float64(2.0), "d": np.array([np.nan])},
                      "identify")
    assert json.loads(text, parse_constant=lambda c: pytest.fail(c)) == {"a": None, "b": [1.0, None], "c": 2.0,
                                                                        "d": [None]}
    err = capsys.readouterr().err
    assert err.startswith("satmd identify: note: not finite, written as null: a, b[1], d[0]")


@pytest.mark.parametrize("argv, says", [
    (["simulate", "--time", "--freq", "40:130:10"], ("--freq", "without --time")),
    (["simulate", "--time", "--channels", "u1"], ("--channels", "without --time")),
    (["simulate", "--duration", "5"], ("--duration", "only with --time")),
    (["simulate", "--fs", "2000", "--force-band", "10:50"], ("--fs, --force-band",)),
    (["inverse", "train", "--preset", "paper", "--samples", "10"], ("--samples", "paper")),
    (["inverse", "train", "--preset", "box", "--samples-per-pair", "10"], ("--samples-per-pair", "box")),
])
def test_conflicting_options_are_refused(capsys, tmp_path, argv, says):
    out = ["--out", tmp_path / "m"] if argv[0] == "inverse" else ["-o", tmp_path / "x.csv"]
    refused(capsys, *argv, *out, says=says)
    assert list(tmp_path.iterdir()) == []


# --- item 13: messages in the CLI's words --------------------------------------------------------------
def test_messages_name_their_subject(capsys, tmp_path, rec):
    refused(capsys, "simulate", "--seed", "-1", "--noise", "0.01", "-o", tmp_path / "x.csv", says=("--seed",))
    f = tmp_path / "z.csv"
    assert run(capsys, "simulate", "--noise", "0.01", "--seed", "1", "-o", f)[0] == 0
    lines = f.read_text().splitlines()
    lines[-1] = ",".join(lines[-1].split(",")[:-1] + ["0"])
    f.write_text("\n".join(lines) + "\n")
    refused(capsys, "identify", f, says=("z.csv", "a2_std", "row 60"))
    short = tmp_path / "short.npz"
    np.savez(short, fs_hz=100.0, force=np.ones(5), acc1=np.ones(5), acc2=np.ones(5))
    line = refused(capsys, "estimate-frf", short, "-o", tmp_path / "e.csv", "--estimator", "H1", says=("5 samples",))
    assert "8..5" not in line
    t = tmp_path / "t.csv"
    oo = tmp_path / "oo.npz"
    r = satmd.io.load_recording(rec)
    np.savez(oo, fs_hz=r.fs_hz, acc1=r["acc1"], acc2=r["acc2"])
    assert run(capsys, "estimate-frf", oo, "-o", t)[0] == 0
    refused(capsys, "identify", t, says=("t.csv", "transmissibility"))


def test_os_errors_are_said_in_words():
    exc = PermissionError(13, "Permission denied", "out.csv")
    assert os_message(exc) == "out.csv: permission denied"
    assert os_message(OSError(28, "No space left on device")) == "no space left on device"


def test_usage_errors_are_one_line(capsys):
    line = refused(capsys, "simulate", "--R", "nan", "-o", "x.csv", says=("--R", "finite"))
    assert line.startswith("satmd simulate: error: argument --R")
    assert main(["--version"]) == 0


def test_library_messages_do_not_name_cli_flags():
    """Flags belong to the CLI (satmd/cli adds them); the library names its parameters."""
    root = Path(satmd.__file__).parent
    found = []
    for p in root.rglob("*.py"):
        if "cli" in p.relative_to(root).parts:
            continue
        tree = ast.parse(p.read_text())
        for node in ast.walk(tree):
            is_call = isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", "")) in (
                "warn", "FormatError", "DataError", "SatmdError")
            if isinstance(node, ast.Raise) or is_call:
                for sub in ast.walk(node):
                    if isinstance(sub, ast.Constant) and isinstance(sub.value, str) and re.search(r"(^|\W)--[a-z]",
                                                                                                  sub.value):
                        found.append(f"{p.relative_to(root)}:{sub.lineno}: {sub.value.strip()[:60]}")
    assert sorted(set(found)) == []


# --- item 14: progress -----------------------------------------------------------------------------------------
def test_progress_lines_without_a_terminal(capsys):
    from satmd._progress import LineProgress, progress

    bar = progress(3, "train physics", "epoch")
    assert isinstance(bar, LineProgress)  # stderr is not a terminal under pytest
    bar.every = 0.0
    for _ in range(3):
        bar.set_postfix({"loss": "0.1"})
        bar.update(1)
    err = capsys.readouterr().err.splitlines()
    assert err[-1].startswith("train physics: 3/3 epoch (") and "loss=0.1" in err[-1]
    assert progress(3, "x", enabled=False) is None


def test_a_failed_write_names_the_output_not_its_temporary_file(tmp_path, monkeypatch):
    import os

    p = tmp_path / "out.csv"

    def full(*args, **kw):
        raise OSError(28, "No space left on device", args[0])

    monkeypatch.setattr(os, "replace", full)
    with pytest.raises(OSError) as info:
        with atomic_write(p, "w") as fh:
            fh.write("x")
    assert os_message(info.value) == f"{p}: no space left on device"
    assert list(tmp_path.iterdir()) == []


def test_explain_shows_progress_and_writes_everything_together(capsys, tmp_path, model_dir):
    out = tmp_path / "ex"
    rc, stdout, err = run(capsys, "explain", model_dir, "--quick", "--no-distill", "--out", out)
    assert rc == 0, err
    steps = [ln for ln in err.splitlines() if ln.startswith("satmd explain: [")]
    assert len(steps) >= 3 and "figure(s) drawn" in steps[-1]
    assert (out / "summary.md").is_file() and (out / "explain.json").is_file()
    json.loads((out / "explain.json").read_text(), parse_constant=lambda c: pytest.fail(c))
    assert not [p for p in out.rglob("*") if ".tmp" in p.name]


def test_progress_can_be_silenced(capsys):
    from satmd.cli._common import Progress

    Progress("explain", quiet=True).step("QUIET", force=True)
    Progress("explain").step("LOUD", force=True)
    err = capsys.readouterr().err
    assert "QUIET" not in err and err.startswith("satmd explain: [") and err.rstrip().endswith("LOUD")

"""Hostile inputs to the readers, writers and public API (issue 28): one representative per family.

The full set (1500+ cases, every command) is `benchmarks/fuzz.py`; these are
the fast checks that each root fix holds: the estimator metadata schema, the
bounded reader, the memory cap, signal-safe temporary files, the saved-model
checks, the API type checks and '\\n'-only line splitting.
"""
from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from satmd import FRFData
from satmd.errors import DataError, FormatError
from satmd.io import DataWarning, Recording, load_frf, load_recording, save_frf, save_recording
from satmd.io.atomic import all_or_none, atomic_write, temp_name
from satmd.io.limits import check_memory, check_samples


def _frf():
    f = np.linspace(40.0, 130.0, 12)
    a = np.exp(1j * f / 10.0)
    return FRFData(f, {"a1": a, "a2": 2 * a}, {"a1": 0.01 * np.abs(a), "a2": 0.02 * np.abs(a)})


def _csv(tmp_path, comment=None, name="f.csv") -> Path:
    p = tmp_path / name
    save_frf(_frf(), p)
    if comment is not None:
        lines = p.read_text().split("\n")
        p.write_text("\n".join(lines[:1] + [comment] + lines[1:]))
    return p


def _rec(n=2000, fs=1000.0):
    t = np.arange(n) / fs
    rng = np.random.default_rng(0)
    f = rng.standard_normal(n)
    return Recording(fs, {"force": f, "acc1": np.convolve(f, [1, 0.5], "same"), "acc2": np.convolve(f, [0.3, 1], "same")
                          + 0 * t})


# --- estimator metadata: one schema check ----------------------------------------------------
@pytest.mark.parametrize("key, value", [("kernel_rms_hz", "wide"), ("kernel_rms_hz", 1e300), ("kernel_rms_hz", -3),
                                        ("measurement", 5), ("noise_dof", "many"), ("noise_dof", 0),
                                        ("method", 7), ("band_hz", [200, 20])])
def test_estimator_metadata_is_checked_key_by_key(tmp_path, key, value):
    p = _csv(tmp_path, f"# satmd estimator: {json.dumps({key: value})}")
    with pytest.raises(FormatError) as info:
        load_frf(p)
    assert str(p) in str(info.value) and key in str(info.value) and "line 2" in str(info.value)


def test_estimator_metadata_nested_too_deep_is_refused(tmp_path):
    p = _csv(tmp_path, "# satmd estimator: " + "[" * 5000 + "]" * 5000)
    with pytest.raises(FormatError, match="JSON"):
        load_frf(p)
    with pytest.raises(DataError, match="deeper"):
        FRFData(_frf().freq_hz, _frf().channels, estimator={"x": [[[[[[[[[[1]]]]]]]]]]})


def test_valid_estimator_metadata_round_trips(tmp_path):
    est = {"method": "welch-H1", "kernel_rms_hz": 0.5, "noise_dof": 30.0, "future": [1]}
    p = tmp_path / "e.csv"
    save_frf(FRFData(_frf().freq_hz, _frf().channels, estimator=est), p)
    assert load_frf(p).estimator == est


# --- '\n'-only line splitting --------------------------------------------------------------------
@pytest.mark.parametrize("sep", ["\u2028", "\x85", "\x0c", "\x1c"])
def test_separators_in_comments_do_not_break_a_valid_file(tmp_path, sep):
    p = _csv(tmp_path, f"# note: a{sep}b")
    np.testing.assert_array_equal(load_frf(p)["a1"], _frf()["a1"])
    lines = p.read_text().split("\n")
    lines[5] = lines[5].replace(lines[5].split(",")[1], "x", 1)
    p.write_text("\n".join(lines))
    with pytest.raises(FormatError, match="line 6"):  # line numbers count '\n' only
        load_frf(p)


# --- the bounded reader ---------------------------------------------------------------------------
def test_fifo_device_and_huge_files_are_refused_unread(tmp_path):
    fifo = tmp_path / "p.csv"
    os.mkfifo(fifo)
    with pytest.raises(FormatError, match="FIFO"):
        load_frf(fifo)  # would block forever if opened
    with pytest.raises(FormatError, match="FIFO"):
        load_recording(fifo)
    dev = tmp_path / "z.csv"
    dev.symlink_to("/dev/zero")
    with pytest.raises(FormatError, match="device"):
        load_frf(dev)
    sparse = tmp_path / "s.wav"
    with open(sparse, "wb") as fh:
        fh.truncate(16 * 2 ** 30)
    with pytest.raises(FormatError, match="GB"):
        load_recording(sparse)


def _wav(frames, declared=None):
    data = np.zeros((frames, 3), "<i2").tobytes()
    fmt = struct.pack("<HHIIHH", 1, 3, 1000, 6000, 6, 16)
    size = len(data) if declared is None else declared
    body = b"WAVE" + b"fmt " + struct.pack("<I", 16) + fmt + b"data" + struct.pack("<I", size) + data
    return b"RIFF" + struct.pack("<I", len(body)) + body


def test_wav_header_claiming_more_than_the_file_holds_is_refused(tmp_path):
    p = tmp_path / "w.wav"
    p.write_bytes(_wav(2000, declared=100_000_000))
    with pytest.raises(FormatError, match="truncated"):
        load_recording(p)


def test_sample_cap_and_memory_estimate():
    with pytest.raises(DataError, match="samples per channel"):
        check_samples("--duration", 2 ** 30, 3)
    with pytest.raises(DataError, match="GB of memory"):
        check_memory("--fs 1e6", 1e11)


def test_mat_dimensions_whose_product_overflows(tmp_path):
    p = tmp_path / "r.mat"
    save_recording(_rec(), p)
    raw = bytearray(p.read_bytes())
    j = raw.rfind(struct.pack("<II", 5, 8), 0, raw.find(b"force"))
    raw[j + 8:j + 16] = struct.pack("<ii", 2 ** 31 - 1, 2 ** 31 - 1)
    p.write_bytes(bytes(raw))
    with pytest.raises(FormatError, match="r.mat"):
        load_recording(p)


# --- recordings that mislead ----------------------------------------------------------------------
def test_time_in_milliseconds_is_refused_by_the_reader(tmp_path):
    p = tmp_path / "t.csv"
    rows = "\n".join(f"{k},{np.sin(k / 3)},{np.cos(k / 3)},{np.sin(k / 5)}" for k in range(400))
    p.write_text("time_s,force,acc1,acc2\n" + rows + "\n")
    with pytest.raises(FormatError, match="milliseconds"):
        load_recording(p)


def test_glitches_are_refused_or_reported(tmp_path):
    rec = _rec()
    force = rec["force"].copy()
    force[100] = 3e38  # float32's largest: a glitch, never a force
    with pytest.raises(DataError, match="reaches 3e"):
        Recording(rec.fs_hz, {**rec.channels, "force": force})
    force[100] = 1e12
    p = tmp_path / "g.csv"
    save_recording(Recording(rec.fs_hz, {**rec.channels, "force": force}), p)
    with pytest.warns(DataWarning, match="glitch"):
        load_recording(p)


# --- API types ------------------------------------------------------------------------------------------
def test_api_names_the_argument_of_the_wrong_type():
    from satmd import identify
    from satmd.discovery import discover_many
    from satmd.signal import estimate_frf

    with pytest.raises(TypeError, match="data must be FRFData"):
        identify([1, 2, 3])
    with pytest.raises(TypeError, match=r"datas\[1\]"):
        discover_many([_frf(), "x"])
    with pytest.raises(TypeError, match="recording must be Recording"):
        estimate_frf("rec.csv")


# --- atomic files ---------------------------------------------------------------------------------------
def test_long_output_names_fit_the_temporary_name(tmp_path):
    p = tmp_path / ("x" * 246 + ".csv")
    assert len(temp_name(p).name.encode()) <= 255
    save_frf(_frf(), p)
    assert load_frf(p).names == ("a1", "a2") and [q.name for q in tmp_path.iterdir()] == [p.name]


def test_sigterm_inside_a_write_removes_the_temporary_file(tmp_path):
    code = (f"import os, signal, time\nfrom satmd.io.atomic import atomic_write\n"
            f"with atomic_write({str(tmp_path / 'o.csv')!r}, 'w') as fh:\n"
            f"    fh.write('half')\n    os.kill(os.getpid(), signal.SIGTERM)\n    time.sleep(5)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=60,
                       env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])})
    assert p.returncode == 128 + 15, p.stderr
    assert list(tmp_path.iterdir()) == []


def test_all_or_none_keeps_the_old_outputs_on_interrupt(tmp_path):
    a, b = tmp_path / "a.txt", tmp_path / "b.txt"
    a.write_text("old a")
    with pytest.raises(KeyboardInterrupt):
        with all_or_none():
            with atomic_write(a, "w") as fh:
                fh.write("new a")
            with atomic_write(b, "w") as fh:
                fh.write("new b")
                raise KeyboardInterrupt
    assert a.read_text() == "old a" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


# --- saved models ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def opt_model(tmp_path_factory):
    pytest.importorskip("torch")
    from satmd.inverse import InverseModel

    path = tmp_path_factory.mktemp("opt") / "m"
    InverseModel(kind="optimization", verbose=False, samples_per_pair=1).fit().save(path)
    return path


def _tampered(src, tmp_path, edit):
    import hashlib
    import shutil

    dst = tmp_path / "m"
    shutil.copytree(src, dst)
    meta = edit(json.loads((dst / "model.json").read_text()))
    if isinstance(meta, dict):
        meta["sha256"] = hashlib.sha256(json.dumps({k: v for k, v in meta.items() if k != "sha256"},
                                                   sort_keys=True).encode()).hexdigest()
        (dst / "model.json").write_text(json.dumps(meta))
    else:
        (dst / "model.json").write_text(meta)
    return dst


@pytest.mark.parametrize("edit, says", [
    (lambda m: {**m, "std_scale": [-1.0, 1.0]}, "std_scale"),
    (lambda m: {**m, "params": {**m["params"], "mc_samples": 10 ** 9}}, "mc_samples"),
    (lambda m: "[" * 5000 + "]" * 5000, "nested"),
    (lambda m: {**m, "history": json.loads("[" * 20 + "1" + "]" * 20)}, "deeper"),
])
def test_tampered_models_are_refused(opt_model, tmp_path, edit, says):
    from satmd.inverse import InverseModel

    with pytest.raises(DataError, match=says):
        InverseModel.load(_tampered(opt_model, tmp_path, edit))


def test_std_is_finite_and_a_model_without_spread_is_not_trusted():
    from satmd.inverse.inputs import trust_check

    out = {"R_std": np.array([np.nan, 1.0]), "L_std": np.array([0.01, 0.01]), "explained": np.array([True, True])}
    with warnings.catch_warnings():
        note = trust_check(out, {"R": (0.0, 103.0), "L": (0.0, 0.5)})
    assert np.all(np.isfinite(out["R_std"])) and list(out["explained"]) == [False, True] and "R_std" in note
    # a model without spread (one member, or a calibration factor of 1.8e11) gives no std, never 0 or 1e10
    out = {"R": np.array([40.0]), "L": np.array([0.1]), "R_std": np.array([1.0]), "L_std": np.array([0.01]),
           "explained": np.array([True])}
    assert "calibration" in trust_check(out, {"R": (0.0, 103.0), "L": (0.0, 0.5)}, "calibration factor 1.8e+11")
    assert not out["explained"][0] and np.isnan(out["R_std"][0])

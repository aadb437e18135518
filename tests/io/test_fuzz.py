"""Fuzz every loader with malformed files: a satmd error or a warning, never anything else.

Each test draws small inputs (valid seed files mutated by truncation, byte
flips, insertions, deleted or duplicated lines, NaN, or plain garbage) and
feeds them to one loader. 7 loaders x 160 examples + `satmd info` = over
1000 malformed inputs per run.
"""
from __future__ import annotations

import io
import os
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from satmd import FRFData
from satmd.errors import SatmdError
from satmd.io import DataWarning, Recording, load_frf, load_recording, save_frf, save_recording

# SATMD_FUZZ_EXAMPLES=5000 runs a longer, randomised hunt; the default is fixed and fast.
EXAMPLES = int(os.environ.get("SATMD_FUZZ_EXAMPLES", 160))
DERANDOMIZE = "SATMD_FUZZ_EXAMPLES" not in os.environ
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=DERANDOMIZE,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def _frf():
    f = np.linspace(40.0, 130.0, 7)
    a = np.exp(1j * f / 10.0)
    return FRFData(f, {"a1": a, "a2": 2 * a}, {"a1": 0.01 * np.abs(a), "a2": 0.02 * np.abs(a)})


def _rec(force=True):
    t = np.arange(24) / 100.0
    ch = {"acc1": np.sin(7 * t), "acc2": np.cos(5 * t)}
    if force:
        ch = {"force": np.sin(3 * t + 0.3), **ch}
    return Recording(100.0, ch)


def _seed_bytes(kind: str, suffix: str) -> bytes:
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / f"seed{suffix}"
        if kind == "frf":
            save_frf(_frf(), p, **({"binary": False} if suffix == ".unv" else {}))
        elif kind == "txt":
            p.write_text("\n".join(str(complex(k, -k)) for k in range(1, 9)) + "\n")
        elif kind == "wav16":
            from scipy.io import wavfile

            wavfile.write(p, 100, (np.column_stack(list(_rec().channels.values())) * 30000).astype(np.int16))
        else:
            save_recording(_rec(), p)
        return p.read_bytes()


SEEDS = {
    "frf.csv": _seed_bytes("frf", ".csv"),
    "frf.uff": _seed_bytes("frf", ".uff"),
    "frf.unv": _seed_bytes("frf", ".unv"),  # ASCII UFF
    "frf.npz": _seed_bytes("frf", ".npz"),
    "frf.mat": _seed_bytes("frf", ".mat"),
    "frf.txt": _seed_bytes("txt", ".txt"),
    "rec.csv": _seed_bytes("rec", ".csv"),
    "rec.uff": _seed_bytes("rec", ".uff"),
    "rec.wav": _seed_bytes("rec", ".wav"),
    "rec16.wav": _seed_bytes("wav16", ".wav"),
    "rec.npz": _seed_bytes("rec", ".npz"),
}


@st.composite
def malformed(draw, seed: bytes):
    """A damaged copy of ``seed`` (or garbage)."""
    how = draw(st.sampled_from(["truncate", "flip", "insert", "lines", "nan", "garbage", "empty", "splice"]))
    data = bytearray(seed)
    if how == "truncate":
        return bytes(data[: draw(st.integers(0, max(0, len(data) - 1)))])
    if how == "flip":
        for _ in range(draw(st.integers(1, 6))):
            i = draw(st.integers(0, len(data) - 1))
            data[i] = draw(st.integers(0, 255))
        return bytes(data)
    if how == "insert":
        i = draw(st.integers(0, len(data)))
        return bytes(data[:i]) + draw(st.binary(min_size=1, max_size=24)) + bytes(data[i:])
    if how == "lines":
        lines = bytes(data).split(b"\n")
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["drop", "dup", "swap", "short"]))
        if op == "drop":
            del lines[i]
        elif op == "dup":
            lines.insert(i, lines[i])
        elif op == "swap" and i + 1 < len(lines):
            lines[i], lines[i + 1] = lines[i + 1], lines[i]
        else:
            lines[i] = lines[i][: len(lines[i]) // 2]
        return b"\n".join(lines)
    if how == "nan":
        text = bytes(data)
        for token in (b"1", b"0.", b"E+", b"e-"):
            j = text.find(token, draw(st.integers(0, max(0, len(text) - 1))))
            if j >= 0:
                return text[:j] + draw(st.sampled_from([b"nan", b"inf", b"-", b"NaN", b" ", b","])) + text[j + 1:]
        return text
    if how == "garbage":
        return draw(st.binary(min_size=1, max_size=200))
    if how == "empty":
        return draw(st.sampled_from([b"", b"\n", b"   \n\n", b"    -1\n", b"    -1\n    58\n    -1\n"]))
    i = draw(st.integers(0, len(data)))  # splice another format's bytes in
    other = draw(st.sampled_from(sorted(SEEDS)))
    return bytes(data[:i]) + SEEDS[other][: draw(st.integers(1, 400))]


def _check(load, suffix: str, content: bytes):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / f"fuzz{suffix}"
        p.write_bytes(content)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # anything but our own warnings is a failure
            warnings.simplefilter("ignore", DataWarning)
            try:
                load(p)
            except SatmdError as exc:
                message = str(exc)
                assert "\n" not in message and message.startswith(str(p)), message
            except Exception as exc:  # pragma: no cover - this is what the test hunts for
                pytest.fail(f"{type(exc).__name__} escaped for {content[:80]!r}: {exc}")


CASES = [  # (seed, suffix, loader)
    ("frf.uff", ".uff", load_frf),
    ("frf.unv", ".unv", load_frf),
    ("frf.npz", ".npz", load_frf),
    ("frf.mat", ".mat", load_frf),
    ("rec.csv", ".csv", load_recording),
    ("rec.uff", ".uff", load_recording),
    ("rec16.wav", ".wav", load_recording),
]


@pytest.mark.parametrize("seed,suffix,load", CASES, ids=[f"{s}->{l.__name__}" for s, _, l in CASES])
def test_loaders_survive_malformed_files(seed, suffix, load):
    @FUZZ
    @given(content=malformed(SEEDS[seed]))
    def run(content):
        _check(load, suffix, content)

    run()


@settings(max_examples=max(60, EXAMPLES // 3), deadline=None, derandomize=DERANDOMIZE,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_small_loaders_survive_malformed_files(data):
    """The CSV FRF reader, the .txt reader, float WAV and .npz recordings."""
    seed, suffix, load = data.draw(st.sampled_from([
        ("frf.csv", ".csv", load_frf),
        ("frf.txt", ".txt", lambda p: load_frf(p, freq_axis="0:1")),
        ("rec.wav", ".wav", load_recording),
        ("rec.npz", ".npz", load_recording),
    ]))
    _check(load, suffix, data.draw(malformed(SEEDS[seed])))


@settings(max_examples=max(40, EXAMPLES // 4), deadline=None, derandomize=DERANDOMIZE,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_info_survives_malformed_files(data):
    """`satmd info` prints or fails with one line (exit 2), never a traceback."""
    from satmd.cli import main

    name = data.draw(st.sampled_from(sorted(SEEDS)))
    content = data.draw(malformed(SEEDS[name]))
    suffix = os.path.splitext(name)[1]
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / f"fuzz{suffix}"
        p.write_bytes(content)
        err = io.StringIO()
        from contextlib import redirect_stderr, redirect_stdout

        with redirect_stdout(io.StringIO()), redirect_stderr(err):
            rc = main(["info", str(p)])
        assert rc in (0, 2)
        assert "Traceback" not in err.getvalue()
        if rc == 2:
            assert err.getvalue().startswith("satmd info: error: ")


def test_seeds_are_valid():
    """The unmutated seeds load, so the fuzz starts from real files."""
    with tempfile.TemporaryDirectory() as d:
        for name, content in SEEDS.items():
            p = Path(d) / name
            p.write_bytes(content)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", DataWarning)  # the .txt seed starts at 0 Hz
                if name.startswith("frf"):
                    load_frf(p, **({"freq_axis": "0:1"} if name.endswith(".txt") else {}))
                else:
                    load_recording(p)

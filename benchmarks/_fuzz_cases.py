"""Hostile inputs for `benchmarks/fuzz.py`: every family of issue 28 plus random damage, deterministic (seeded).

A case is a plain dict (picklable):

``id``, ``family``; ``kind`` "api" (an operation of `OPS` run in a worker
process), "cli" (``satmd.cli.main(argv)`` in a worker), "proc" (``python -m
satmd`` in a subprocess, a signal sent after ``delay`` s when ``signal`` is
set); ``files`` {name: bytes | ("fifo",) | ("sparse", size) | ("link", target)
| ("copy", base name)} made in a fresh folder first; ``expect`` "refuse",
"answer", "either" or "warn" (an answer must come with a warning naming one
of ``names``); ``names`` the words a refusal must contain (the file or the
option at fault).

`{base}` in arguments is the folder of valid material (`make_base`), `{work}`
the case's own folder.
"""
from __future__ import annotations

import io
import json
import random
import struct
import zipfile

import numpy as np

SEED = 28_2026
EST_KEYS = {
    "method": ["lpm", "welch-H1"], "reference": ["x"], "record_s": [4.0], "band_hz": [[20, 150]],
    "window_hz": [0.3], "bins_per_window": [7], "degree": [2], "points": [100], "noise_dof": [40.0],
    "force_noise_floor_detected": [False], "max_force_noise_bias": [0.0], "window": ["hann"], "nperseg": [256],
    "kernel_rms_hz": [0.5], "overlap": [0.5], "segments": [16], "resolution_hz": [1.5],
    "measurement": [[{"name": "a", "explanation": "b", "remedy": "c"}]],
}
BAD_VALUES = ["wide", "", None, True, -3, -1e-300, 0, 1e300, [1, 2], {"a": 1}, [[[[[[[[[[[1]]]]]]]]]]], 2.5, 10 ** 30]
WRONG = [[1, 2, 3], "x", None, 3, {"a1": 1}, np.arange(5.0), b"bytes"]  # not data, for the API type checks
SEPARATORS = ["\u2028", "\u2029", "\x85", "\x0c", "\x0b", "\x1c", "\x1d", "\x1e", "\r"]
TOKENS_NONFINITE = ["nan", "inf", "-inf", "1e999", "NaN", "Infinity"]


def case(family, kind, expect, names=(), **kw):
    return {"family": family, "kind": kind, "expect": expect, "names": list(names), **kw}


# --- valid material ---------------------------------------------------------------------------
def make_base(folder):
    """Valid files and models the cases start from (made once, never modified)."""
    import contextlib

    from satmd.cli import main
    from satmd.io import load_recording, save_frf, save_recording

    quiet = io.StringIO()
    with contextlib.redirect_stdout(quiet), contextlib.redirect_stderr(quiet):
        assert main(["simulate", "--freq", "40:130:30", "--noise", "0.01", "--seed", "1", "-o", f"{folder}/frf.csv"]) == 0
        assert main(["simulate", "--noise", "0.01", "--seed", "1", "-o", f"{folder}/paper.csv"]) == 0
        assert main(["simulate", "--time", "--duration", "4", "--fs", "400", "--force-band", "20:150", "--seed", "2",
                     "--noise", "0.01", "-o", f"{folder}/rec.csv"]) == 0
        rec = load_recording(f"{folder}/rec.csv")
        for suffix in (".wav", ".uff", ".npz", ".mat"):
            save_recording(rec, f"{folder}/rec{suffix}")
        from satmd.io import load_frf

        frf = load_frf(f"{folder}/frf.csv")
        for suffix in (".uff", ".npz", ".mat"):
            save_frf(frf, f"{folder}/frf{suffix}")
        with open(f"{folder}/frf.txt", "w") as fh:
            fh.write("\n".join(str(complex(v)) for v in frf["a1"]) + "\n")
        assert main(["inverse", "train", "--kind", "supervised", "--epochs", "2", "--samples-per-pair", "1",
                     "--members", "1", "--quiet", "--out", f"{folder}/net"]) == 0
        assert main(["inverse", "train", "--kind", "optimization", "--quiet", "--out", f"{folder}/opt"]) == 0
        # issue 38: one-member ensembles of every net kind, and a two-member one, each trained for two epochs
        for name, kind, members in (("phys1", "physics", "1"), ("hyb1", "hybrid", "1"), ("net2", "supervised", "2")):
            warm = ["--warm-start", "1"] if kind != "supervised" else []
            assert main(["inverse", "train", "--kind", kind, "--epochs", "2", *warm, "--samples-per-pair", "1",
                         "--members", members, "--quiet", "--out", f"{folder}/{name}"]) == 0
    make_structure_base(folder)


def make_structure_base(folder):
    """Two levels of a 4-mass chain with a cubic joint (`tests/structure/chain.py`) and its saved model."""
    import contextlib
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))
    from satmd.cli import main
    from satmd.io import Recording, save_recording
    from tests.structure.chain import simulate_chain

    low, high = simulate_chain(n=4, joint=(1, 2), law=lambda d, v: 3e9 * d ** 3, levels=(1.0, 8.0), periods=4, seed=3)
    save_recording(low, f"{folder}/s1.csv")
    save_recording(high, f"{folder}/s8.csv")
    fewer = Recording(high.fs_hz, {c: high[c] for c in ("force", "acc1", "acc2", "acc4")}, meta={})
    save_recording(fewer, f"{folder}/s8_no_acc3.csv")
    more = Recording(high.fs_hz, {**{c: high[c] for c in high.channels}, "acc5": high["acc4"]}, meta={})
    save_recording(more, f"{folder}/s8_acc5.csv")
    still = Recording(high.fs_hz, {**{c: high[c] for c in high.channels}, "force": 0.0 * high["force"]}, meta={})
    save_recording(still, f"{folder}/s8_still.csv")
    cut = Recording(high.fs_hz, {c: high[c][:300] for c in high.channels}, meta={})
    save_recording(cut, f"{folder}/s8_cut.csv")
    quiet = io.StringIO()
    with contextlib.redirect_stdout(quiet), contextlib.redirect_stderr(quiet):
        assert main(["discover", f"{folder}/s1.csv", f"{folder}/s8.csv", "--save-model", f"{folder}/structure.json"]) == 0


def structure_cases(base) -> list[dict]:
    """Issue 47: a structure's levels and its saved model, each hostile input refused naming the file and channel."""
    cases = []
    add = cases.append
    add(case("structure levels", "cli", "refuse", ["s8_no_acc3.csv", "acc3"],
             argv=["discover", "{base}/s1.csv", "{base}/s8_no_acc3.csv"]))
    add(case("structure levels", "cli", "refuse", ["s8_acc5.csv", "acc5"],
             argv=["discover", "{base}/s1.csv", "{base}/s8_acc5.csv"]))
    add(case("structure levels", "cli", "refuse", ["s8_still.csv", "constant"],  # the level at fault, not the first
             argv=["discover", "{base}/s1.csv", "{base}/s8_still.csv"]))
    add(case("structure levels", "cli", "refuse", ["s8_cut.csv", "300 samples"],
             argv=["discover", "{base}/s1.csv", "{base}/s8_cut.csv", "--save-model", "{work}/m.json"]))
    add(case("structure levels", "cli", "refuse", ["--driving-point", "acc9"],
             argv=["discover", "{base}/s1.csv", "{base}/s8.csv", "--save-model", "{work}/m.json",
                   "--driving-point", "acc9"]))
    add(case("structure levels", "cli", "refuse", ["s8_no_acc3.csv", "acc3"],
             argv=["predict", "{base}/structure.json", "{base}/s8_no_acc3.csv"]))
    add(case("structure levels", "cli", "answer", argv=["predict", "{base}/structure.json", "{base}/s8.csv", "--json"]))
    model = json.loads(open(f"{base}/structure.json", encoding="utf-8").read())
    for label, edit in (("no linear part", lambda d: d.pop("linear")), ("other schema", lambda d: d.update(schema="x")),
                        ("poles not numbers", lambda d: d["linear"].update(poles="many")),
                        ("a joint without a law", lambda d: d["joint"].pop("law")),
                        ("a fitted band upside down", lambda d: d.update(band_hz=[60.0, 3.0])),
                        ("a joint's reach below zero", lambda d: d.update(reach=-1.0))):
        bad = json.loads(json.dumps(model))
        edit(bad)
        add(case("structure levels", "cli", "refuse", ["bad.json"], argv=["predict", "{work}/bad.json", "{base}/s8.csv"],
                 files={"bad.json": json.dumps(bad).encode()}, label=label))
    # a lab's realizations (the F-16's odd multisines: Acceleration channel × realization × time)
    rng = np.random.default_rng(5)
    real = _npz(Force=rng.normal(size=(3, 2048)), Acceleration=rng.normal(size=(2, 3, 2048)), Fs=np.float64(256.0))
    odd = _npz(Force=rng.normal(size=(3, 2048)), Acceleration=rng.normal(size=(2, 5, 2048)), Fs=np.float64(256.0))
    add(case("structure levels", "cli", "refuse", ["odd.npz", "Acceleration", "2×5×2048", "3×2048"],
             argv=["discover", "{work}/odd.npz"], files={"odd.npz": odd}, label="realizations the force has not"))
    add(case("structure levels", "cli", "refuse", ["real.npz", "Acceleration[1,9]", "1..2, 1..3"],
             argv=["discover", "{work}/real.npz", "--map", "force=Force[1],a1=Acceleration[1,9],a2=Acceleration[2,1]"],
             files={"real.npz": real}, label="a realization that is not there"))
    # a structure's FRFs of every channel and its modes (`estimate-frf --channels`, `satmd modes`)
    add(case("structure FRFs", "cli", "answer", argv=["estimate-frf", "{base}/s8.csv", "--channels", "all", "-o",
                                                      "{work}/frfs.uff"]))
    add(case("structure FRFs", "cli", "answer", argv=["modes", "{base}/s8.csv", "--json"]))
    add(case("structure FRFs", "cli", "refuse", ["acc9"],
             argv=["estimate-frf", "{base}/s8.csv", "--channels", "acc2,acc9", "-o", "{work}/frfs.csv"]))
    add(case("structure FRFs", "cli", "refuse", ["acc9"], argv=["modes", "{base}/s8.csv", "--driving-point", "acc9"]))
    add(case("structure FRFs", "cli", "refuse", ["s8_still.csv"], argv=["modes", "{base}/s8_still.csv"]))
    head = "# satmd-frfs v1: the FRF of every response channel over the force\nfreq_hz,acc1_re,acc1_im,acc1_std,acc1_coh\n"
    for label, body in (("a value not a number", "1,2,3,x,1\n"), ("a row cut short", "1,2,3\n"),
                        ("a frequency that falls", "2,1,1,0.1,1\n1,1,1,0.1,1\n"), ("NaN", "1,nan,1,0.1,1\n"),
                        ("no rows", "")):
        for cmd in (["modes", "{work}/f.csv"], ["info", "{work}/f.csv"], ["identify", "{work}/f.csv"]):
            add(case("structure FRFs", "cli", "refuse", ["f.csv"], argv=cmd, files={"f.csv": (head + body).encode()},
                     label=label))
    return cases


def _csv_with_comment(base_text: str, comment: str) -> bytes:
    lines = base_text.split("\n")
    return ("\n".join(lines[:1] + [comment] + lines[1:])).encode()


def mutations(seed: bytes, rng: random.Random, n: int) -> list[bytes]:
    """Random damage: truncation, byte flips, insertions, dropped/duplicated lines, garbage."""
    out = []
    for _ in range(n):
        how = rng.choice(["truncate", "flip", "insert", "lines", "garbage"])
        data = bytearray(seed)
        if how == "truncate":
            data = data[:rng.randrange(len(data))]
        elif how == "flip":
            for _ in range(rng.randint(1, 6)):
                data[rng.randrange(len(data))] = rng.randrange(256)
        elif how == "insert":
            i = rng.randrange(len(data))
            data = data[:i] + bytes(rng.randrange(256) for _ in range(rng.randint(1, 16))) + data[i:]
        elif how == "lines":
            parts = bytes(data).split(b"\n")
            i = rng.randrange(len(parts))
            if rng.random() < 0.5:
                del parts[i]
            else:
                parts.insert(i, parts[i])
            data = bytearray(b"\n".join(parts))
        else:
            data = bytearray(rng.randrange(256) for _ in range(rng.randint(1, 200)))
        out.append(bytes(data))
    return out


def _wav(n_frames: int, channels: int = 3, declared: int | None = None, riff: int | None = None,
         block: int | None = None) -> bytes:
    """A 16-bit PCM WAV whose header may lie about its sizes."""
    rng = np.random.default_rng(n_frames)
    data = (rng.standard_normal((n_frames, channels)) * 3000).astype("<i2").tobytes()
    block = channels * 2 if block is None else block
    fmt = struct.pack("<HHIIHH", 1, channels, 1000, 1000 * block, block, 16)
    size = len(data) if declared is None else declared
    body = b"WAVE" + b"fmt " + struct.pack("<I", 16) + fmt + b"data" + struct.pack("<I", size) + data
    return b"RIFF" + struct.pack("<I", len(body) if riff is None else riff) + body


def _mat_with_dims(base_mat: bytes, dims) -> bytes:
    """The .mat recording with the dimensions of its 'force' variable replaced (e.g. a product that overflows)."""
    raw = bytearray(base_mat)
    i = raw.find(b"force")
    j = raw.rfind(struct.pack("<II", 5, 8), 0, i)  # miINT32 dims element, 8 bytes (2 dims)
    if j < 0:
        return bytes(raw)
    raw[j + 8:j + 16] = struct.pack("<ii", *dims)
    return bytes(raw)


def _npz(**arrays) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


# --- the families -------------------------------------------------------------------------------
def generate(base) -> list[dict]:
    """Every case, in a fixed order (ids are positions)."""
    from pathlib import Path

    base = Path(base)
    rng = random.Random(SEED)
    frf_text = (base / "frf.csv").read_text()
    rec_text = (base / "rec.csv").read_text()
    cases = []
    add = cases.append

    # 1. estimator metadata in FRF CSVs: every key, every kind of bad value; API and the commands that fit
    for key in EST_KEYS:
        for bad in BAD_VALUES:
            if _valid_number(key, bad):
                continue
            content = _csv_with_comment(frf_text, f"# satmd estimator: {json.dumps({key: bad})}")
            add(case("estimator metadata", "api", "refuse", ["bad.csv", key], op="load_frf",
                     files={"bad.csv": content}, args=["{work}/bad.csv"]))
        bad = 5 if key in ("reference", "window") else "wide"
        content = _csv_with_comment(frf_text, f"# satmd estimator: {json.dumps({key: bad})}")
        for cmd in (["identify", "{work}/bad.csv", "--json"], ["discover", "{work}/bad.csv", "--json"],
                    ["tune", "{work}/bad.csv", "--json"]):
            add(case("estimator metadata", "cli", "refuse", ["bad.csv"], argv=cmd, files={"bad.csv": content}))
    for text in ("{", "[1,2]", "null", "1e999", "NaN", "[" * 5000 + "]" * 5000, '{"a":' * 3000 + "1" + "}" * 3000):
        add(case("estimator metadata", "api", "refuse", ["bad.csv"], op="load_frf",
                 files={"bad.csv": _csv_with_comment(frf_text, f"# satmd estimator: {text}")}, args=["{work}/bad.csv"]))
    for good in ({"method": "welch-H1", "kernel_rms_hz": 0.5, "noise_dof": 30.0}, {"future_key": [1, {"x": 2}]}):
        add(case("estimator metadata", "api", "answer", op="load_frf",
                 files={"ok.csv": _csv_with_comment(frf_text, f"# satmd estimator: {json.dumps(good)}")},
                 args=["{work}/ok.csv"]))

    # 2. line separators inside comments and values: valid files must load (no false refusal)
    for sep in SEPARATORS:
        for where in ("comment", "header comment"):
            comment = f"# note: a{sep}b" if where == "comment" else f"# satmd-frf v1 {sep}"
            expect = "answer" if where == "comment" else "either"
            add(case("line separators", "api", expect, ["ok.csv"], op="load_frf",
                     files={"ok.csv": _csv_with_comment(frf_text, comment)}, args=["{work}/ok.csv"]))
            add(case("line separators", "api", expect, ["ok.csv"], op="load_recording",
                     files={"ok.csv": _csv_with_comment(rec_text, comment)}, args=["{work}/ok.csv"]))
        add(case("line separators", "cli", "answer", argv=["info", "{work}/ok.csv"],
                 files={"ok.csv": _csv_with_comment(frf_text, f"# note: x{sep}y")}))
    add(case("line separators", "api", "answer", op="load_frf", files={"ok.csv": frf_text.replace("\n", "\r\n").encode()},
             args=["{work}/ok.csv"]))
    add(case("line separators", "api", "answer", op="load_frf", files={"ok.csv": frf_text.replace("\n", "\r").encode()},
             args=["{work}/ok.csv"]))

    # 3. paths that are not regular files, and files too large to read: refused up front, never read
    specials = {"fifo": ("fifo",), "zero": ("link", "/dev/zero"), "urandom": ("link", "/dev/urandom"),
                "null": ("link", "/dev/null"), "sparse": ("sparse", 16 * 2 ** 30), "dir": ("dir",)}
    for label, spec in specials.items():
        for suffix in (".csv", ".uff", ".mat", ".npz", ".txt", ".wav", ".unv"):
            name = f"x{suffix}"
            for op in ("load_frf", "load_recording", "is_recording"):
                sniffs = op != "is_recording" or (label == "sparse" and suffix not in (".txt", ".wav"))
                add(case("not a regular file", "api", "refuse" if sniffs else "either", [name], op=op,
                         files={name: spec}, args=["{work}/" + name]))
            if suffix in (".csv", ".wav"):
                for cmd in (["identify", "{work}/" + name], ["estimate-frf", "{work}/" + name, "-o", "{work}/o.csv"],
                            ["info", "{work}/" + name], ["modes", "{work}/" + name]):
                    add(case("not a regular file", "cli", "refuse", [name], argv=cmd, files={name: spec}))
        add(case("not a regular file", "api", "refuse", ["model.json"], op="load_model", files={"m/model.json": spec},
                 args=["{work}/m"]))

    # 4. requests whose size comes from the user: refused up front with an estimate
    for fs, dur in ((1e6, 1), (1e5, 60), (1e4, 3600), (5e4, 10), (1e7, 0.01), (2e3, 1e5), (1e9, 1e-3)):
        expect = "either" if fs * dur < 1e6 and fs < 1e5 else "refuse"  # 50 kHz for 10 s fits in memory
        add(case("memory from work", "cli", expect, ["--fs", "--duration"],
                 argv=["simulate", "--time", "--fs", str(fs), "--duration", str(dur), "-o", "{work}/r.csv"]))
        add(case("memory from work", "api", expect, ["Hz"], op="simulate_recording", args=[dur, fs]))
    for band in ("1e-300:1", "1e-200:1e200", "1e-30:1e30", "1e-9:1e9", "1e-12:1"):
        expect = "either" if band in ("1e-9:1e9", "1e-12:1") else "refuse"  # 10^4 grid points: 1.5 GB, allowed
        add(case("memory from work", "cli", expect, ["--band"], argv=["tune", "--rig", "--band", band, "--json"]))
    for draws in ("1000000000", "100000", "5000", "15", "-1"):
        add(case("memory from work", "cli", "refuse", ["--draws"],
                 argv=["tune", "--rig", "--robust", "--uncertainty", "kp=5e3", "--draws", draws, "--json"]))
    for freq in ("40:130:1000000000", "40:130:2000000", "1e-300:1:100"):
        add(case("memory from work", "cli", "refuse", ["--freq"], argv=["simulate", "--freq", freq, "-o", "{work}/s.csv"]))
    big = 2 ** 24 + 10
    add(case("memory from work", "api", "refuse", ["big.wav"], op="load_recording",
             files={"big.wav": _wav(4, 1, declared=big * 2)},
             args=["{work}/big.wav"]))
    add(case("memory from work", "api", "refuse", ["big.wav"], op="load_recording",
             files={"big.wav": ("wav_frames", big, 1)}, args=["{work}/big.wav"]))
    add(case("memory from work", "api", "refuse", ["big.npz"], op="load_recording",
             files={"big.npz": ("npz_zeros", big)}, args=["{work}/big.npz"]))
    mat = (base / "rec.mat").read_bytes()
    for dims in ((2 ** 31 - 1, 2 ** 31 - 1), (65536, 65536), (-1, 4), (0, 4), (2 ** 24 + 1, 1)):
        add(case("memory from work", "api", "refuse", ["d.mat"], op="load_recording",
                 files={"d.mat": _mat_with_dims(mat, dims)}, args=["{work}/d.mat"]))

    # 5. tune options: ranges and units
    for opt in ("--rig m1=1e300", "--rig kp=-5", "--rig R=1e-300", "--rig m2=nan", "--rig bogus=1",
                "--rig --bounds R=1e-300:1e300", "--rig --bounds L=0:1", "--rig --bounds R=5:1",
                "--rig --current R=-1", "--rig --current L=1e300", "--rig --current R=22,R=23",
                "--rig --robust --uncertainty kp=1e300", "--rig --robust --uncertainty kp=-5",
                "--rig --robust --uncertainty kp=0", "--rig --uncertainty kp=5e3", "--rig --robust 2",
                "--rig --band 200:20", "--rig --band 0:100", "--rig --design R,R", "--rig --design bogus"):
        argv = ["tune", *opt.split(), "--json"]
        flags = [w for w in opt.split()[1:] if w.startswith("--")] or ["--rig"]
        add(case("tune options", "cli", "refuse", flags, argv=argv))

    # 6. saved models, tampered (checksum recomputed, so only the content checks stand)
    for label, edit in _model_edits():
        add(case("saved model", "api", "refuse", ["model.json"], op="predict_model",
                 files={"m": ("model_edit", "net", label)}, args=["{work}/m", "{base}/paper.csv"]))
    add(case("saved model", "api", "answer", op="predict_model", args=["{base}/net", "{base}/paper.csv"], check_std=True,
             unexplained=True))
    add(case("saved model", "api", "answer", op="predict_model", args=["{base}/opt", "{base}/paper.csv"], check_std=True))
    add(case("saved model", "cli", "answer", argv=["inverse", "evaluate", "{base}/net", "--json"], check_std=True))
    add(case("saved model", "cli", "answer", argv=["inverse", "predict", "{base}/net", "{base}/paper.csv", "--json"],
             check_std=True, unexplained=True))

    # 7. the public API given the wrong types
    for k, value in enumerate(WRONG):
        for op, name in (("identify", "data"), ("discover", "data"), ("estimate_frf", "recording"),
                         ("identify_many", "datas[1]"), ("discover_many", "datas[1]")):
            add(case("API types", "api", "refuse", [name], op=op, args=[k]))
    for op in ("load_frf", "load_recording"):
        for value in (123, None, 1.5, ["a.csv"]):
            add(case("API types", "api", "refuse", [], op=op + "_raw", args=[value]))

    # 8. CLI options: duplicates, maps, options that do not apply, negative values, non-finite values
    rec, frf, uff = "{base}/rec.csv", "{base}/frf.csv", "{base}/frf.uff"
    for cmd in (["identify", frf], ["discover", frf], ["tune", frf, "--json"]):
        for opt, val in (("--channels", "a1,a1"), ("--free", "m2,m2"), ("--free", "kp,R,kp")):
            add(case("CLI options", "cli", "refuse", [opt], argv=[*cmd, opt, val]))
    for m in ("a1=#99", "a1=#1,a2=#1", "a1=1:3,a2=1:+Z", "a1=#2", "a9=#1", "a1=#0", "a1=x", "a1=#1,a1=#2"):
        add(case("CLI options", "cli", "refuse", ["--map", "frf.uff"], argv=["identify", uff, "--map", m]))
        add(case("CLI options", "api", "refuse", ["frf.uff"], op="load_frf", args=[uff], kwargs={"channel_map": m}))
    for m in ("force=#1,a1=#1,a2=#2", "force=#1,a1=#2,a2=#2", "a1=#9", "force=#0", "a1=#1,acc1=#2"):
        for r in ("{base}/rec.wav", "{base}/rec.uff"):
            add(case("CLI options", "cli", "refuse", ["--map"], argv=["estimate-frf", r, "-o", "{work}/o.csv", "--map", m]))
    ignored = [["simulate", "--time", "--freq", "40:130:60"], ["simulate", "--time", "--channels", "a1,a2"],
               ["simulate", "--fs", "1000"], ["simulate", "--duration", "60"], ["simulate", "--force-band", "20:200"],
               ["simulate", "--excitation", "random"], ["simulate", "--burn-in", "0"], ["simulate", "--force-rms", "1"],
               ["estimate-frf", rec, "--estimator", "H1", "--width", "0.5"],
               ["estimate-frf", rec, "--estimator", "H2", "--width", "0.3"],
               ["estimate-frf", rec, "--nperseg", "64", "--width", "0.5"],
               ["estimate-frf", rec, "--estimator", "lpm", "--nperseg", "64"],
               ["estimate-frf", rec, "--estimator", "lpm", "--window", "hann"]]
    for argv in ignored:
        out = ["-o", "{work}/o.csv"]
        flag = next(a for a in argv[1:] if a.startswith("--") and a not in ("--time", "--estimator"))
        add(case("ignored options", "cli", "refuse", [flag], argv=argv + out))
    for only in ("bogus", "forward,bogus", ",", "FORWARD"):
        add(case("ignored options", "cli", "refuse", ["--only"],
                 argv=["reproduce", "--only", only, "--quick", "--out", "{work}/rep"]))
    for opt in ("--m2", "--kp", "--R", "--L"):
        for v in ("-1", "nan", "1e999", "-0"):
            expect = "either" if v == "-0" and opt in ("--R", "--L") else "refuse"  # R = 0, L = 0 are shunts too
            add(case("CLI options", "cli", expect, [opt], argv=["simulate", opt, v, "-o", "{work}/s.csv"]))
    for v in ("1e300", "nan", "-1", "1e300:0", "0:1e300"):
        add(case("CLI options", "cli", "refuse", ["--noise"], argv=["simulate", "--noise", v, "-o", "{work}/s.csv"]))
    for v in ("200:20", "x:y", "20", "-5:10", "nan:100"):
        add(case("messages", "cli", "refuse", ["--force-band"],
                 argv=["simulate", "--time", "--force-band", v, "--duration", "2", "-o", "{work}/r.csv"]))
    for v in ("nan:1", "1:nan", "inf:1", "0:0", "0:-1", "x", "1", "1:2:3"):
        add(case("messages", "cli", "refuse", ["--freq-axis"],
                 argv=["info", "{base}/frf.txt", "--freq-axis", v]))
        add(case("messages", "api", "refuse", ["freq_axis"], op="load_frf", args=["{base}/frf.txt"],
                 kwargs={"freq_axis": v}))

    # 9. time axes that are not in seconds, sample rates no FRF can come from
    t = np.arange(400)
    for label, time in (("ms", t * 1.0), ("dt 1000 s", t * 1000.0), ("dt 0.5 s", t * 0.5), ("dt 0.1 s", t * 0.1),
                        ("us as s", t * 1e-6 * 1e6)):
        sig = np.sin(2 * np.pi * 0.05 * t) + 0.1 * np.random.default_rng(1).standard_normal(t.size)
        body = "time_s,force,acc1,acc2\n" + "\n".join(",".join(repr(float(v)) for v in (a, b, 2 * b, -b)) for a, b in zip(time, sig))
        files = {"t.csv": body.encode()}
        add(case("time axis", "api", "refuse", ["t.csv"], op="load_recording", files=files, args=["{work}/t.csv"]))
        add(case("time axis", "api", "refuse", ["t.csv"], op="estimate", files=files, args=["{work}/t.csv"]))
        for cmd in (["estimate-frf", "{work}/t.csv", "-o", "{work}/o.csv"], ["identify", "{work}/t.csv"],
                    ["estimate-frf", "{work}/t.csv", "-o", "{work}/o.csv", "--estimator", "H1"]):
            add(case("time axis", "cli", "refuse", ["t.csv"], argv=cmd, files=files))
    for fs in (0.001, 1.0, 10.0):
        add(case("time axis", "api", "refuse", ["x.npz"], op="load_recording",
                 files={"x.npz": _npz(fs_hz=np.float64(fs), force=np.ones(500) * np.arange(500) % 7,
                                      acc1=np.sin(np.arange(500.0)), acc2=np.cos(np.arange(500.0)))},
                 args=["{work}/x.npz"]))

    # 10. recordings that would mislead: glitches, unrelated channels, constant or zero channels
    rec_arr = _rec_array(rec_text)
    for ch in (1, 2, 3):
        for value in (3e38, -3e38, 1e20, 1e16, 1e12):
            a = rec_arr.copy()
            a[rng.randrange(a.shape[0]), ch] = value
            files = {"g.csv": _rec_csv(a)}
            add(case("glitch", "api", "warn", ["g.csv", "glitch", "reaches"], op="estimate", files=files,
                     args=["{work}/g.csv"]))
            if value in (3e38, 1e12):
                add(case("glitch", "cli", "warn", ["g.csv", "glitch", "reaches"],
                         argv=["estimate-frf", "{work}/g.csv", "-o", "{work}/o.csv"], files=files))
    noise = np.random.default_rng(3).standard_normal(rec_arr.shape)
    noise[:, 0] = rec_arr[:, 0]
    for est in ([], ["--estimator", "H1"], ["--estimator", "H2"]):
        add(case("unrelated channels", "cli", "warn", ["coherence", "n.csv"],
                 argv=["estimate-frf", "{work}/n.csv", "-o", "{work}/o.csv", *est], files={"n.csv": _rec_csv(noise)}))
    for ch in (1, 2, 3):
        for fill in (0.0, 5.0):
            a = rec_arr.copy()
            a[:, ch] = fill
            add(case("constant channel", "api", "refuse", ["c.csv", "constant"], op="estimate",
                     files={"c.csv": _rec_csv(a)}, args=["{work}/c.csv"]))
            add(case("constant channel", "cli", "refuse", ["c.csv"],
                     argv=["estimate-frf", "{work}/c.csv", "-o", "{work}/o.csv"], files={"c.csv": _rec_csv(a)}))

    # 11. WAV files whose header lies
    for label, blob in (("data chunk 100 MB, 12 kB held", _wav(2000, declared=100_000_000)),
                        ("data chunk odd", _wav(2000, declared=12_001)),
                        ("RIFF size lies", _wav(2000, riff=10 ** 8)),
                        ("block align 0", _wav(2000, block=0)),
                        ("zero channels", _wav(10, channels=1)[:22] + b"\x00\x00" + _wav(10, channels=1)[24:]),
                        ("no data chunk", _wav(10)[:36]), ("truncated", _wav(2000)[:5000]), ("empty data", _wav(0)),
                        ("not RIFF", b"RIFX" + _wav(2000)[4:]), ("one frame", _wav(1))):
        add(case("WAV header", "api", "refuse" if "RIFF size" not in label else "warn", ["w.wav"],
                 op="load_recording", files={"w.wav": blob}, args=["{work}/w.wav"]))
        add(case("WAV header", "cli", "refuse" if "RIFF size" not in label else "warn", ["w.wav"],
                 argv=["estimate-frf", "{work}/w.wav", "-o", "{work}/o.csv"], files={"w.wav": blob}))

    # 12. numbers no FRF holds, too few points, all-zero channels
    f = np.linspace(40, 130, 30)
    for label, freq, scale in (("f 1e300", f * 1e298, 1.0), ("f 1e-300", f * 1e-302, 1.0), ("f 1e12", f * 1e10, 1.0),
                               ("values 1e300", f, 1e300), ("values 1e-300", f, 1e-300), ("values 0", f, 0.0),
                               ("4 points", f[:4], 1.0), ("1 point", f[:1], 1.0), ("values 1e150", f, 1e150)):
        a = np.exp(1j * freq / 10.0) * scale if scale else np.zeros(freq.size, complex)
        body = "freq_hz,a1_re,a1_im,a2_re,a2_im\n" + "\n".join(
            ",".join(repr(float(v)) for v in (x, z.real, z.imag, 2 * z.real, 2 * z.imag)) for x, z in zip(freq, a))
        files = {"n.csv": body.encode()}
        for cmd in (["identify", "{work}/n.csv", "--json"], ["discover", "{work}/n.csv", "--json"],
                    ["inverse", "predict", "{base}/opt", "{work}/n.csv", "--json"], ["tune", "{work}/n.csv", "--json"]):
            add(case("extreme numbers", "cli", "either" if label == "4 points" else "refuse", ["n.csv"], argv=cmd,
                     files=files))

    # 13. control characters and escapes in names (echoed, never raw)
    for name in ("\x1b[31mred.csv", "a\x07bell.csv", "\u202egnp.csv", "tab\tname.csv", "new\nline.csv",
                 "\x1b]0;title\x07.csv"):
        for cmd in (["identify", "{work}/" + name], ["info", "{work}/" + name],
                    ["estimate-frf", "{work}/" + name, "-o", "{work}/o.csv"]):
            add(case("control characters", "cli", "refuse", [], argv=cmd, files={name: b"garbage,\n1,2\n"},
                     no_control=True))

    # 14. long output names (the temporary name must still fit NAME_MAX)
    for suffix in (".csv", ".uff", ".npz", ".mat"):
        name = "l" * (250 - len(suffix)) + suffix
        add(case("long names", "api", "answer", op="save_frf", args=["{base}/frf.csv", "{work}/" + name]))
        add(case("long names", "cli", "answer", argv=["simulate", "-o", "{work}/" + name]))
    for suffix in (".csv", ".wav", ".uff", ".npz"):
        name = "r" * (250 - len(suffix)) + suffix
        add(case("long names", "api", "answer", op="save_recording", args=["{base}/rec.csv", "{work}/" + name]))

    # 15. random damage to every format, through the loaders (as tests/io/test_fuzz.py, other seeds)
    for name in ("frf.csv", "frf.uff", "frf.npz", "frf.mat", "frf.txt", "rec.csv", "rec.wav", "rec.uff", "rec.npz",
                 "rec.mat"):
        seed_bytes = (base / name).read_bytes()[:20000]
        op = "load_frf" if name.startswith("frf") else "load_recording"
        kwargs = {"freq_axis": "40:3"} if name.endswith(".txt") else {}
        for k, blob in enumerate(mutations(seed_bytes, rng, 70)):
            add(case("random damage", "api", "either", [name], op=op, files={name: blob}, args=["{work}/" + name],
                     kwargs=kwargs))

    # 16. interruptions: SIGINT / SIGTERM at several moments; old outputs intact or new ones complete
    for sig in ("SIGTERM", "SIGINT"):
        for delay in (0.8, 1.6, 2.5, 4.0):
            add(case("signals", "proc", "either", argv=["estimate-frf", "{base}/rec.csv", "-o", "{work}/e.csv", "--plot",
                                                          "{work}/e.png"], signal=sig, delay=delay,
                     files={"e.csv": b"old\n", "e.png": b"old png\n"}, keep=["e.csv", "e.png"]))
            add(case("signals", "proc", "either", argv=["simulate", "--time", "--duration", "30", "-o", "{work}/r.wav"],
                     signal=sig, delay=delay, files={"r.wav": b"old\n"}, keep=["r.wav"]))
            add(case("signals", "proc", "either", argv=["reproduce", "--only", "forward", "--quick", "--out",
                                                          "{work}/rep"], signal=sig, delay=delay + 2,
                     files={"rep/index.md": b"old report\n", "rep/figures/old.png": b"old\n"}, keep=["rep"]))
    # 17. outputs that cannot be written whole: a full disk (RLIMIT_FSIZE), a FIFO or a symlink loop in the way
    for argv, name in ((["simulate", "--freq", "40:130:5000", "-o", "{work}/s.csv"], "s.csv"),
                       (["simulate", "--time", "--duration", "20", "-o", "{work}/r.wav"], "r.wav"),
                       (["estimate-frf", "{base}/rec.csv", "-o", "{work}/e.csv", "--plot", "{work}/e.png"], "e.csv")):
        add(case("outputs", "proc", "refuse", [name, "too large"], argv=argv, fsize=20_000,
                 files={name: b"old\n"}, keep=[name]))
        add(case("outputs", "cli", "either", [name], argv=argv, files={name: ("fifo",)}))
    for name, spec in (("loop.csv", ("link", "loop.csv")), ("n" * 300 + ".csv", None),
                       ("dangling.csv", ("link", "/nonexistent/x"))):
        files = {name: spec} if spec else {}  # a name longer than NAME_MAX cannot exist: only the path is given
        for cmd in (["identify", "{work}/" + name], ["estimate-frf", "{work}/" + name, "-o", "{work}/o.csv"]):
            add(case("outputs", "cli", "refuse", [name[:40]], argv=cmd, files=files))
        add(case("outputs", "api", "refuse", [name[:40]], op="load_frf", files=files, args=["{work}/" + name]))

    # 18. containers that hide something: pickled arrays, HDF5 .mat, object dtypes, NaN, mismatched lengths
    n = 600
    sig = np.sin(np.arange(n) / 3.0)
    for label, blob in (("object array", _npz(fs_hz=np.float64(1000), force=np.array([sig], dtype=object)[0:1])),
                        ("NaN sample", _npz(fs_hz=np.float64(1000), force=np.where(np.arange(n) == 7, np.nan, sig),
                                            acc1=sig, acc2=sig)),
                        ("lengths differ", _npz(fs_hz=np.float64(1000), force=sig, acc1=sig[:-1], acc2=sig)),
                        ("fs negative", _npz(fs_hz=np.float64(-1000), force=sig, acc1=sig, acc2=sig)),
                        ("fs array", _npz(fs_hz=np.arange(3.0), force=sig, acc1=sig, acc2=sig)),
                        ("complex signal", _npz(fs_hz=np.float64(1000), force=sig + 1j, acc1=sig, acc2=sig)),
                        ("string signal", _npz(fs_hz=np.float64(1000), force=np.array(["a"] * n), acc1=sig, acc2=sig)),
                        ("2-D signal", _npz(fs_hz=np.float64(1000), force=np.ones((n, 2)), acc1=sig, acc2=sig)),
                        ("HDF5 .mat", b"MATLAB 7.3 MAT-file" + bytes(600)),
                        ("v4 .mat", bytes(200))):
        suffix = ".mat" if "mat" in label else ".npz"
        add(case("containers", "api", "refuse", ["c" + suffix], op="load_recording", files={"c" + suffix: blob},
                 args=["{work}/c" + suffix]))
        add(case("containers", "cli", "refuse", ["c" + suffix],
                 argv=["estimate-frf", "{work}/c" + suffix, "-o", "{work}/o.csv"], files={"c" + suffix: blob}))

    for _ in range(len(cases), 1500 + 40):  # top up with further random damage of the CSV formats
        name = rng.choice(["frf.csv", "rec.csv"])
        blob = mutations((base / name).read_bytes()[:8000], rng, 1)[0]
        add(case("random damage", "api", "either", [name], op="load_frf" if name == "frf.csv" else "load_recording",
                 files={name: blob}, args=["{work}/" + name]))
    cases += issue38_cases(base)
    cases += structure_cases(base)
    from _fuzz_excitation import cases as excitation_cases

    cases += excitation_cases(case)
    for i, c in enumerate(cases):
        c["id"] = i
    return cases


# --- issue 38: Ctrl-C at any moment, one-member models, out-of-range options, reversed bands -------------------
CTRL_C_COMMANDS = [  # (argv, files made first, outputs that must stay whole)
    (["simulate", "--freq", "1:1000:1000000", "--noise", "0.01", "-o", "{work}/big.csv"], {"big.csv": b"old\n"},
     ["big.csv"]),
    (["identify", "{base}/paper.csv", "--json"], {}, []),
    (["discover", "{base}/frf.csv", "--plot", "{work}/d.png"], {"d.png": b"old png\n"}, ["d.png"]),
    (["inverse", "predict", "{base}/net", "{base}/paper.csv", "--json"], {}, []),
    (["inverse", "evaluate", "{base}/net2"], {}, []),
    (["inverse", "train", "--kind", "supervised", "--epochs", "4", "--samples-per-pair", "2", "--members", "2",
      "--quiet", "--out", "{work}/m"], {}, []),
    (["explain", "{base}/net2", "--quick", "--no-distill", "--quiet", "--out", "{work}/ex"], {}, []),
    (["info", "{base}/rec.csv"], {}, []),
    (["estimate-frf", "{base}/rec.csv", "-o", "{work}/e.csv"], {"e.csv": b"old\n"}, ["e.csv"]),
    (["tune", "{base}/frf.csv", "--json"], {}, []),
    (["reproduce", "--only", "forward", "--quick", "--out", "{work}/rep"],
     {"rep/index.md": b"old report\n", "rep/figures/old.png": b"old\n"}, ["rep"]),
    (["--help"], {}, []),
]
CTRL_C_DELAYS = (0.15, 0.4, 0.8, 1.5, 3.0)  # from the interpreter's start (imports take a second or more) to the work

# option -> out-of-range values (all refused, naming the option); {b}: base, {w}: work
OUT_OF_RANGE = [
    (["simulate", "-o", "{w}/s.csv"], {"--m2": ["1e300", "1e-300"], "--kp": ["1e308", "1e-300"], "--R": ["1e300"],
                                         "--L": ["1e300", "1e-300"], "--seed": ["-1", "1e20", "4294967296"]}),
    (["simulate", "--time", "--duration", "2", "-o", "{w}/r.csv"],
     {"--burn-in": ["1e9", "-1", "1e300"], "--fs": ["1e300", "1e-300", "0"], "--force-rms": ["1e300", "0"],
      "--level": ["1e300", "-1"], "--force-noise": ["1e300", "-1"], "--duration": ["1e300", "-1"]}),
    (["simulate", "--time", "--excitation", "multisine", "--duration", "8", "-o", "{w}/r.csv"],
     {"--periods": ["0", "-1", "1000000000"], "--realisations": ["0", "1000000000"]}),
    (["simulate", "--time", "--duration", "2", "-o", "{w}/r.csv", "--nonlinear"],
     {"cubic_absorber_spring:k3": ["1e300", "-1e300"], "absorber_friction:Fc": ["1e300", "-1"],
      "quadratic_damping:c2": ["1e300"]}),
    (["identify", "{b}/paper.csv"], {"--reg": ["1e300", "-1"], "--init": ["m2=1e300", "R=-5"]}),
    (["discover", "{b}/paper.csv"], {"--alpha": ["0", "1", "1e300", "-1"]}),
    (["inverse", "train", "--out", "{w}/m"],
     {"--epochs": ["0", "1000000000"], "--warm-start": ["1000000000", "90"], "--samples-per-pair": ["0", "1000000000"],
      "--members": ["0", "257", "1000000"], "--threads": ["0", "1000000"], "--noise": ["1", "-1", "1e300"],
      "--seed": ["-1", "1e30"]}),
    (["inverse", "train", "--preset", "box", "--out", "{w}/m"], {"--samples": ["1", "1000000000"]}),
    (["inverse", "evaluate", "{b}/net2"], {"--noise": ["1", "1e300", "-1"], "--seed": ["-1"]}),
    (["explain", "{b}/net2", "--out", "{w}/ex"], {"--threads": ["0", "1000000"]}),
    (["tune", "--rig", "--nonlinear", "cubic_absorber_spring:k3=2e11"], {"--levels": ["1e300", "0", "-1"]}),
    (["tune", "--rig", "--levels", "1", "--nonlinear"], {"cubic_absorber_spring:k3": ["1e300"]}),
    (["tune", "--rig", "--robust", "--uncertainty", "kp=5e3"], {"--draws": ["1000000000", "0"]}),
    (["tune", "--rig"], {"--current": ["R=1e300", "L=-1"], "--robust": ["2", "0.1"]}),
    (["estimate-frf", "{b}/rec.csv", "-o", "{w}/o.csv"], {"--width": ["0", "-1", "1e300"]}),
    (["estimate-frf", "{b}/rec.csv", "--estimator", "H1", "-o", "{w}/o.csv"],
     {"--nperseg": ["0", "1000000000000"], "--overlap": ["-1", "1", "1e300"]}),
]
# every option that takes a band (LO:HI), reversed; the refusal must name the option as typed
REVERSED_BANDS = [
    (["identify", "{b}/paper.csv"], "--band"), (["discover", "{b}/paper.csv"], "--band"),
    (["inverse", "predict", "{b}/net2", "{b}/paper.csv"], "--band"), (["tune", "{b}/paper.csv"], "--data-band"),
    (["tune", "--rig"], "--band"), (["estimate-frf", "{b}/rec.csv", "-o", "{w}/o.csv"], "--band"),
    (["simulate", "--time", "--duration", "2", "-o", "{w}/r.csv"], "--force-band"),
]


def _oom_files(base) -> dict:
    """FRF files no SATMD rig gives (a 1-DOF accelerance, white noise, the rig in g): tune must name the file."""
    f = np.linspace(40.0, 130.0, 60)
    w = 2 * np.pi * f
    rng = np.random.default_rng(38)
    one_dof = -w ** 2 / (4e6 - 1.0 * w ** 2 + 1j * 30.0 * w)
    noise = rng.standard_normal(60) + 1j * rng.standard_normal(60)
    from satmd.io import load_frf

    paper = load_frf(base / "paper.csv")
    out = {}
    for name, a1, a2 in (("one_dof.csv", one_dof, None), ("noise.csv", noise, noise[::-1]),
                         ("in_g.csv", paper["a1"] / 9.80665, paper["a2"] / 9.80665)):
        x = paper.freq_hz if name == "in_g.csv" else f
        head = "freq_hz,a1_re,a1_im" + (",a2_re,a2_im" if a2 is not None else "")
        rows = [",".join(repr(float(v)) for v in (x[i], a1[i].real, a1[i].imag) + (() if a2 is None else
                                                                                   (a2[i].real, a2[i].imag)))
                for i in range(len(x))]
        out[name] = ("# satmd-frf v1\n" + head + "\n" + "\n".join(rows) + "\n").encode()
    return out


def issue38_cases(base) -> list[dict]:
    """The classes of issue 38, each for every command it concerns."""
    cases = []
    add = cases.append
    # 19. Ctrl-C at several moments, from the interpreter's start (imports) to the work, once and twice
    for argv, files, keep in CTRL_C_COMMANDS:
        for delay in CTRL_C_DELAYS:
            add(case("Ctrl-C", "proc", "either", argv=argv, signal="SIGINT", delay=delay, files=files, keep=keep))
        add(case("Ctrl-C", "proc", "either", argv=argv, signal="SIGINT", delay=0.6, repeat=1, gap=0.05, files=files,
                 keep=keep))
        add(case("Ctrl-C", "proc", "either", argv=argv, signal="SIGINT", delay=1.0, repeat=2, gap=0.4, files=files,
                 keep=keep))
    # 20. one-member and two-epoch models: no std of 0 or 1e10 (a std, or none with its reason)
    for model, one in (("net", True), ("phys1", True), ("hyb1", True), ("net2", False)):
        unexplained = one and model != "hyb1"  # the hybrid's std is its least-squares one
        add(case("one-member models", "api", "answer", op="predict_model", args=["{base}/" + model, "{base}/paper.csv"],
                 check_std=True, unexplained=unexplained))
        add(case("one-member models", "cli", "answer", argv=["inverse", "predict", "{base}/" + model,
                                                                "{base}/paper.csv", "--json"],
                 check_std=True, unexplained=unexplained))
        add(case("one-member models", "cli", "answer", argv=["inverse", "predict", "{base}/" + model,
                                                                "{base}/paper.csv"], text_std=True))
        add(case("one-member models", "cli", "answer", argv=["inverse", "evaluate", "{base}/" + model, "--json"],
                 check_std=True))
        add(case("one-member models", "cli", "answer", argv=["inverse", "evaluate", "{base}/" + model, "--noise",
                                                                "0.01", "--json"], check_std=True))
    # 21. out-of-range values of every command's options, and the refusal names the option as typed
    for prefix, options in OUT_OF_RANGE:
        for opt, values in options.items():
            for v in values:
                argv = [a.replace("{b}", "{base}").replace("{w}", "{work}") for a in prefix]
                if opt.startswith("--"):
                    argv, names = argv + [opt, v], [opt]
                else:  # an element's parameter: --nonlinear NAME:key=VALUE
                    argv, names = argv + [f"{opt}={v}"], ["--nonlinear"]
                add(case("out-of-range options", "cli", "refuse", names, argv=argv))
    for window in ("boxcar", "bogus"):  # a window without a second-order kernel (boxcar) or none at all
        add(case("out-of-range options", "cli", "either", ["--window"],
                 argv=["estimate-frf", "{base}/rec.csv", "--estimator", "H1", "--window", window, "-o", "{work}/o.csv"]))
    # 22. reversed bands under every option name that takes one
    for prefix, opt in REVERSED_BANDS:
        argv = [a.replace("{b}", "{base}").replace("{w}", "{work}") for a in prefix]
        for band in ("120:40", "40:40", "200:-5"):
            add(case("reversed bands", "cli", "refuse", [opt], argv=argv + [opt, band]))
    add(case("reversed bands", "cli", "refuse", ["--freq"],
             argv=["simulate", "--freq", "130:40:60", "-o", "{work}/s.csv"]))
    # 23. refusals of data the model cannot describe name the file (satmd tune)
    for name, content in _oom_files(base).items():
        add(case("out-of-model files", "cli", "refuse", [name], argv=["tune", "{work}/" + name, "--json"],
                 files={name: content}))
        add(case("out-of-model files", "cli", "refuse", [name], argv=["tune", "{work}/" + name, "--no-discover"],
                 files={name: content}))
    return cases


def _valid_number(key, x) -> bool:
    from satmd.io.estmeta import SCHEMA

    try:
        return SCHEMA[key](x) is None and not (key == "kernel_rms_hz" and x is not None and x > 130)
    except Exception:  # noqa: BLE001
        return False


def _rec_array(text: str) -> np.ndarray:
    rows = [ln for ln in text.split("\n") if ln and not ln.startswith("#")][1:]
    return np.array([[float(x) for x in r.split(",")] for r in rows])


def _rec_csv(a: np.ndarray) -> bytes:
    return ("time_s,force,acc1,acc2\n" + "\n".join(",".join(repr(float(x)) for x in row) for row in a) + "\n").encode()


def _model_edits():
    """(label, function(meta) -> meta) for model.json tampering."""
    def deep(meta):
        d = 1
        for _ in range(5000):
            d = [d]
        return {**meta, "history": d}

    return [
        ("deep nesting", deep),
        ("NaN in scaler mean", lambda m: {**m, "scaler": {**m["scaler"], "mean": [float("nan")] + m["scaler"]["mean"][1:]}}),
        ("NaN in scaler scale", lambda m: {**m, "scaler": {**m["scaler"], "scale": [float("nan")] + m["scaler"]["scale"][1:]}}),
        ("zero scaler scale", lambda m: {**m, "scaler": {**m["scaler"], "scale": [0.0] * len(m["scaler"]["scale"])}}),
        ("negative std_scale", lambda m: {**m, "std_scale": [-1.0, 1.0]}),
        ("zero std_scale", lambda m: {**m, "std_scale": [0.0, 1.0]}),
        ("inf std_scale", lambda m: {**m, "std_scale": [1e400, 1.0]}),
        ("NaN std_scale", lambda m: {**m, "std_scale": [float("nan"), 1.0]}),
        ("mc_samples 1e9", lambda m: {**m, "params": {**m["params"], "mc_samples": 10 ** 9}}),
        ("mc_samples -1", lambda m: {**m, "params": {**m["params"], "mc_samples": -1}}),
        ("refine_nfev 1e12", lambda m: {**m, "params": {**m["params"], "refine_nfev": 10 ** 12}}),
        ("freq NaN", lambda m: {**m, "freq_hz": [float("nan")] * len(m["freq_hz"])}),
        ("freq decreasing", lambda m: {**m, "freq_hz": m["freq_hz"][::-1]}),
        ("rig m2 1e300", lambda m: {**m, "rig": {**m["rig"], "m2": 1e300}}),
        ("rig NaN", lambda m: {**m, "rig": {**m["rig"], "kp": float("nan")}}),
        ("members 1e9", lambda m: {**m, "network": {**m["network"], "n_members": 10 ** 9}}),
        ("sizes huge", lambda m: {**m, "network": {**m["network"], "sizes": [240, 10 ** 9, 2]}}),
        ("params string", lambda m: {**m, "params": "x"}),
    ]


def tamper(meta: dict, label: str) -> str:
    """model.json text after edit ``label``, with the checksum recomputed (so only content checks can refuse)."""
    import hashlib

    edit = dict(_model_edits())[label]
    new = edit(meta)
    if isinstance(new, dict):
        body = {k: v for k, v in new.items() if k != "sha256"}
        try:
            new["sha256"] = hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()
        except (RecursionError, ValueError):
            pass
    try:
        return json.dumps(new)
    except RecursionError:
        return "[" * 5000 + "]" * 5000


def npz_zeros(n: int) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        for name in ("force", "acc1", "acc2"):
            with z.open(f"{name}.npy", "w", force_zip64=True) as fh:
                header = io.BytesIO()
                np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (n,)})
                fh.write(header.getvalue())
                chunk = bytes(8 * 2 ** 20)
                left = 8 * n
                while left > 0:
                    fh.write(chunk[:min(left, len(chunk))])
                    left -= len(chunk)
        z.writestr("fs_hz.npy", _npy(np.float64(1000.0)))
    return buf.getvalue()


def _npy(x) -> bytes:
    buf = io.BytesIO()
    np.save(buf, x)
    return buf.getvalue()

"""Every command against generated bad input, run in-process through `satmd.cli.main`.

For each input the command must either refuse it (exit 2, one line
``satmd CMD: error: ...`` on stderr, no raw library text) or succeed without
printing NaN/Infinity (JSON output must be strict JSON). Either way no input
file changes, no temporary file is left behind, and a refusal writes nothing.
Anything else (a traceback included) is reported with the argv that caused it.

The inputs are generated deterministically (seeded): malformed FRF CSVs of
every class SPEC §7 names, damaged binary formats, damaged model folders,
bad option values and conflicting options. `test_enough_inputs` counts them.
"""
from __future__ import annotations

import contextlib
import io
import json
import random
import re
import shutil
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from satmd.cli import main

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
from _fuzz_cases import mutations  # noqa: E402  (one generator for this test and benchmarks/fuzz.py)

pytest.importorskip("torch")

ROOT_SEED = 20261123

# raw text of libraries / the OS that must never reach the user
RAW = re.compile(r"Traceback|\[Errno|supported formats|f\(a\) and f\(b\)|in 8\.\.[0-7]\b|"
                 r"<class |object at 0x|PytorchStreamReader|invalid load key|Error\(s\) in loading")
# Python's own warning format, or numpy's floating-point complaints, on stderr
RAW_WARNING = re.compile(r"\.py:\d+: \w*Warning|encountered in|RuntimeWarning")
NONFINITE = re.compile(r"(?<![\w.])[-+]?(nan|inf|infinity)(?![\w])", re.I)


@dataclass
class Case:
    """One command line; ``files`` are written into a fresh folder first (name -> bytes, or a folder copy)."""

    group: str
    argv: list
    files: dict = field(default_factory=dict)
    expect: tuple = (0, 2)  # allowed exit codes


# --- the run and its checks -------------------------------------------------------------
def _snapshot(folder: Path) -> dict:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def run_case(case: Case, base: Path, work: Path) -> str | None:
    """None when the command behaved; otherwise what went wrong."""
    for name, content in case.files.items():
        p = work / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, Path):
            shutil.copytree(content, p)
        else:
            p.write_bytes(content)
    before = _snapshot(work)
    argv = [str(a).replace("{base}", str(base)).replace("{work}", str(work)) for a in case.argv]
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv)
    except BaseException as exc:  # noqa: BLE001 - a traceback is the failure this test hunts
        return f"{type(exc).__name__}: {exc}"
    out, err = out.getvalue(), err.getvalue()
    after = _snapshot(work)
    leftovers = [n for n in after if ".tmp" in n]
    if leftovers:
        return f"left temporary files {leftovers}"
    changed = [n for n in before if after.get(n) != before[n]]
    if changed and rc != 0:
        return f"exit {rc} but changed {changed}"
    if [n for n in before if n not in after]:
        return f"removed {[n for n in before if n not in after]}"
    if RAW_WARNING.search(err):
        return f"raw warning on stderr: {RAW_WARNING.search(err).group(0)!r} in {err[-300:]!r}"
    if rc not in case.expect:
        return f"exit {rc} (expected {case.expect}); stderr {err.strip()[-300:]!r}"
    if rc == 2:
        lines = [ln for ln in err.splitlines() if ": error: " in ln]
        if len(lines) != 1 or not lines[0].startswith("satmd") or err.rstrip().splitlines()[-1] != lines[0]:
            return f"refusal is not one error line: {err!r}"
        if RAW.search(lines[0]):
            return f"raw library text: {lines[0]}"
        if set(after) - set(before):
            return f"refused but wrote {sorted(set(after) - set(before))}"
    if rc == 0:
        if "--json" in argv:
            try:
                json.loads(out, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
            except ValueError as exc:
                return f"exit 0 with invalid JSON ({exc}): {out[:200]!r}"
        elif NONFINITE.search(out):
            return f"exit 0 with a non-finite number: {NONFINITE.search(out).group(0)!r} in {out[:300]!r}"
    return None


def run_group(cases, base: Path, tmp_path: Path):
    assert cases
    failures = []
    for i, case in enumerate(cases):
        work = tmp_path / f"c{i}"
        work.mkdir()
        problem = run_case(case, base, work)
        if problem:
            failures.append(f"[{case.group}] {case.argv}: {problem}")
        shutil.rmtree(work, ignore_errors=True)
    assert not failures, f"{len(failures)} of {len(cases)} inputs misbehaved:\n" + "\n".join(failures[:25])


# --- valid material to start from ---------------------------------------------------------
@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """Valid files (never modified: checked at the end) and two saved models."""
    d = tmp_path_factory.mktemp("fuzzbase")
    quiet = contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO())
    with quiet[0], quiet[1]:
        assert main(["simulate", "--freq", "40:130:9", "--noise", "0.01", "--seed", "1", "-o", str(d / "frf.csv")]) == 0
        assert main(["simulate", "--noise", "0.01", "--seed", "1", "-o", str(d / "paper.csv")]) == 0
        assert main(["simulate", "--time", "--duration", "4", "--fs", "400", "--force-band", "20:150", "--seed", "2",
                     "--noise", "0.01", "-o", str(d / "rec.csv")]) == 0
        assert main(["inverse", "train", "--kind", "supervised", "--epochs", "1", "--samples-per-pair", "1",
                     "--members", "1", "--quiet", "--out", str(d / "net")]) == 0
        assert main(["inverse", "train", "--kind", "optimization", "--quiet", "--out", str(d / "opt")]) == 0
    before = _snapshot(d)
    yield d
    assert _snapshot(d) == before, "a command changed one of the valid input files"
    assert not [p for p in d.rglob("*") if ".tmp" in p.name]


def _csv_parts(text: str):
    lines = text.splitlines()
    head = [i for i, ln in enumerate(lines) if ln and not ln.startswith("#")][0]
    return lines, head


# --- generators ------------------------------------------------------------------------------
BAD_NUMBERS = ["nan", "NaN", "inf", "-inf", "Infinity", "", " ", "abc", "1e999", "-1e999", "0x1p3", "1.2.3", "--2",
               "1e", "∞", "null", "true", "1_0e", "½", "1 2"]
DATA_COMMANDS = [
    ["identify", "{file}", "--json"],
    ["identify", "{file}", "--local"],
    ["discover", "{file}", "--json"],
    ["inverse", "predict", "{base}/net", "{file}", "--json"],
    ["info", "{file}"],
]


def _with_tune(commands):
    from satmd.cli import _command_modules

    if "tune" in _command_modules():
        commands = commands + [["tune", "{file}", "--json"]]
    return commands


def bad_csv_files(seed_text: str, rng: random.Random) -> list[tuple[str, bytes]]:
    """(label, content): every malformation class of SPEC §7, plus random bad cells."""
    lines, h = _csv_parts(seed_text)
    header = lines[h].split(",")
    rows = lines[h + 1:]

    def with_rows(new_rows, new_header=None, pre=None):
        return "\n".join((pre if pre is not None else lines[:h]) + [new_header or lines[h]] + new_rows) + "\n"

    def set_cell(r, c, token):
        new = [row.split(",") for row in rows]
        new[r][c] = token
        return with_rows([",".join(x) for x in new])

    out = []
    for token in BAD_NUMBERS:  # a bad cell anywhere
        r, c = rng.randrange(len(rows)), rng.randrange(len(header))
        out.append((f"cell {token!r}", set_cell(r, c, token)))
    for _ in range(8):
        r, c = rng.randrange(len(rows)), rng.randrange(len(header))
        out.append(("cell nan", set_cell(r, c, rng.choice(["nan", "inf", "-inf"]))))
    std_col = header.index("a1_std")
    k = rng.randrange(len(rows))
    out += [
        ("zero std", set_cell(k, std_col, "0")),
        ("negative std", set_cell(k, std_col, "-1e-6")),
        ("zero frequency", set_cell(0, 0, "0")),
        ("negative frequency", set_cell(0, 0, "-40")),
        ("duplicate row", with_rows(rows[:k + 1] + rows[k:])),
        ("swapped rows", with_rows(rows[:1] and [rows[1], rows[0]] + rows[2:])),
        ("short row", with_rows(rows[:k] + [rows[k].rsplit(",", 1)[0]] + rows[k + 1:])),
        ("long row", with_rows(rows[:k] + [rows[k] + ",1.0"] + rows[k + 1:])),
        ("unknown channel", with_rows(rows, lines[h].replace("a2_re", "a3_re"))),
        ("missing _im", with_rows([",".join(r.split(",")[:2] + r.split(",")[3:]) for r in rows],
                                  ",".join(header[:2] + header[3:]))),
        ("duplicate column", with_rows(rows, lines[h].replace("a2_re", "a1_re"))),
        ("bad column name", with_rows(rows, lines[h].replace("a1_im", "a1_imag"))),
        ("freq column renamed", with_rows(rows, lines[h].replace("freq_hz", "frequency"))),
        ("only freq column", with_rows([r.split(",")[0] for r in rows], "freq_hz")),
        ("header only", with_rows([])),
        ("no header", "\n".join(lines[:h] + rows) + "\n"),
        ("version 2", with_rows(rows, pre=["# satmd-frf v2"])),
        ("transmissibility", "# satmd-transmissibility v1\nfreq_hz,t_re,t_im,t_std,coherence\n40,1,0,0.1,0.9\n"
                             "41,1,0,0.1,0.9\n"),
        ("semicolons", with_rows([r.replace(",", ";") for r in rows], lines[h].replace(",", ";"))),
    ]
    out = [(label, text.encode()) for label, text in out]
    out += [
        ("empty", b""),
        ("blank lines", b"\n\n  \n"),
        ("comments only", b"# satmd-frf v1\n# nothing else\n"),
        ("NUL byte", seed_text.encode()[:200] + b"\x00" + seed_text.encode()[200:]),
        ("latin-1", seed_text.encode().replace(b"freq_hz", b"fr\xe9q_hz")),
        ("binary", bytes(rng.randrange(256) for _ in range(300))),
        ("truncated mid-number", seed_text.encode()[:len(seed_text) - 7].rstrip(b"0123456789") + b"e"),
    ]
    return out


def cases_malformed_csv(base: Path) -> list[Case]:
    rng = random.Random(ROOT_SEED)
    files = bad_csv_files((base / "frf.csv").read_text(), rng)
    cases = []
    for command in _with_tune(DATA_COMMANDS):
        for label, content in files:
            argv = [a.replace("{file}", "{work}/bad.csv") for a in command]
            # `info` describes a file whose only fault is a zero std (the fitting commands refuse it)
            expect = (0, 2) if command[0] == "info" and label == "zero std" else (2,)
            cases.append(Case(f"csv {label}", argv, {"bad.csv": content}, expect=expect))
    return cases


def cases_damaged_formats(base: Path) -> list[Case]:
    """Other FRF formats and recordings, randomly damaged, through every data command."""
    from satmd.io import load_frf, save_frf

    rng = random.Random(ROOT_SEED + 1)
    frf = load_frf(base / "frf.csv")
    seeds = {}
    tmp = base.parent / "fuzzseeds"
    tmp.mkdir(exist_ok=True)
    for suffix in (".uff", ".npz", ".mat"):
        save_frf(frf, tmp / f"s{suffix}")
        seeds[suffix] = (tmp / f"s{suffix}").read_bytes()
    seeds[".rec.csv"] = (base / "rec.csv").read_bytes()[:6000]
    seeds[".txt"] = "\n".join(str(complex(k, -k)) for k in range(1, 12)).encode()
    cases = []
    commands = _with_tune(DATA_COMMANDS)
    for suffix, seed in seeds.items():
        name = "bad" + (".csv" if suffix == ".rec.csv" else suffix)
        for k, content in enumerate(mutations(seed, rng, 24)):
            # `info` reads every variant; the data commands take turns (they share one loader)
            for command in (["info", "{file}"], commands[k % len(commands)]):
                argv = [a.replace("{file}", "{work}/" + name) for a in command]
                if suffix == ".txt":
                    argv += ["--freq-axis", "40:10"]
                cases.append(Case(f"damaged {suffix}", argv, {name: content}))
    # recordings in every format through estimate-frf (and info)
    from satmd.io import load_recording, save_recording

    short = load_recording(base / "rec.csv")
    short = type(short)(short.fs_hz, {k: v[:400] for k, v in short.channels.items()})
    for suffix in (".csv", ".uff", ".wav", ".npz"):
        save_recording(short, tmp / f"r{suffix}")
        for k, content in enumerate(mutations((tmp / f"r{suffix}").read_bytes(), rng, 16)):
            command = [["estimate-frf", "{f}", "-o", "{work}/o.csv"], ["estimate-frf", "{f}", "-o", "{work}/o.uff",
                                                                       "--estimator", "H1"], ["info", "{f}"]][k % 3]
            argv = [a.replace("{f}", "{work}/r" + suffix) for a in command]
            cases.append(Case(f"damaged recording {suffix}", argv, {"r" + suffix: content}))
    return cases


def cases_bad_options(base: Path) -> list[Case]:
    """Option values that must be refused, for every command, and options that conflict."""
    frf, rec, net = "{base}/frf.csv", "{base}/rec.csv", "{base}/net"
    out = "{work}/out.csv"
    numbers = ["nan", "inf", "-inf", "abc", "", "1e999", "0x10"]
    cases = []

    def bad(*argv, expect=(2,)):
        cases.append(Case("option", list(argv), expect=expect))

    for n in numbers + ["-1", "0"]:
        for opt_name in ("--m2", "--kp", "--L"):
            if not (opt_name == "--L" and n == "0"):  # L = 0 is a resistive shunt
                bad("simulate", opt_name, n, "-o", out)
        bad("simulate", "--noise", n, "-o", out)
        bad("simulate", "--time", "--duration", n, "-o", out)
        bad("simulate", "--time", "--fs", n, "-o", out)
        bad("discover", frf, "--alpha", n)
        bad("identify", frf, "--reg", "-1" if n == "0" else n)
        if n not in ("", "0"):  # an open or zero lower end is a valid band
            bad("simulate", "--noise", f"0.01:{n}", "-o", out)
            bad("identify", frf, "--band", f"{n}:100")
        if n not in ("-1", "0"):  # out-of-range starts: see test_fit_edges
            bad("identify", frf, "--init", f"m2={n}")
        bad("inverse", "evaluate", net, "--noise", n if n != "0" else "1")
        bad("inverse", "train", "--noise", n if n != "0" else "1", "--out", "{work}/m")
        bad("inverse", "train", "--epochs", n, "--out", "{work}/m")
        bad("inverse", "train", "--members", n, "--out", "{work}/m")
        bad("estimate-frf", rec, "-o", out, "--nperseg", n)
        bad("explain", net, "--threads", n)
    for n in ("-1", "1.5", "x", "99999999999999999999"):
        bad("simulate", "--seed", n, "-o", out)
        bad("inverse", "train", "--seed", n, "--out", "{work}/m")
        bad("inverse", "evaluate", net, "--seed", n)
    for v in ("2", "1", "0", "nan", "-0.5", "1e-400"):
        bad("discover", frf, "--alpha", v)
    for f in ("130:40:60", "40:130", "0:130:60", "40:130:1", "40:130:1000000000", "40:130:6.5", "a:b:c", "::"):
        bad("simulate", "--freq", f, "-o", out)
    for band in ("130:40", "70:70", "x:y", "40", "1e6:2e6", "200:300"):
        for command in (["identify", frf], ["discover", frf], ["inverse", "predict", net, "{base}/paper.csv"]):
            bad(*command, "--band", band)
    for ch in ("a3", "", ",", "a1,a1x", "u9"):
        bad("simulate", "--channels", ch, "-o", out)
        bad("identify", frf, "--channels", ch)
    for free in ("bogus", "m2,bogus", "", ","):
        bad("identify", frf, "--free", free)
        bad("discover", frf, "--free", free)
    for eff in ("bogus", "extra_mode", "extra_mode:f_hz=nan", "time_delay:tau_s=5", "sensor_gain:gain_a1",
                ":x=1", "parameter_offset:m2:value=1"):
        bad("simulate", "--effect", eff, "-o", out)
        bad("identify", frf, "--effect", eff)
    for cand in ("bogus", ",", "extra_mode,bogus"):
        bad("discover", frf, "--candidates", cand)
    for m in ("a1", "a1=", "a9=1:3", "a1=x:3", "a1=#0", "a1=1:9"):
        bad("info", "{base}/frf.csv", "--map", m)
        bad("estimate-frf", rec, "-o", out, "--map", m)
    for fa in ("x", "1:0", "0:-1", "nan:1", "1"):
        bad("info", "{work}/v.txt", "--freq-axis", fa)
    # conflicting options: refused, not ignored
    bad("simulate", "--time", "--freq", "40:130:10", "-o", out)
    bad("simulate", "--time", "--channels", "u1", "-o", out)
    bad("simulate", "--duration", "5", "-o", out)
    bad("simulate", "--fs", "2000", "-o", out)
    bad("simulate", "--force-band", "10:50", "-o", out)
    bad("simulate", "--time", "--duration", "1e7", "-o", out)
    bad("simulate", "--time", "--plot", "{work}/x.png", "-o", out)
    bad("inverse", "train", "--preset", "paper", "--samples", "10", "--out", "{work}/m")
    bad("inverse", "train", "--preset", "box", "--samples-per-pair", "10", "--out", "{work}/m")
    bad("inverse", "train", "--kind", "optimization", "--epochs", "3", "--out", "{work}/m")
    for dev in ("bogus", "cuda:x", "gpu", "cuda:99"):
        bad("inverse", "train", "--device", dev, "--out", "{work}/m")
    for kind in ("bogus", ""):
        bad("inverse", "train", "--kind", kind, "--out", "{work}/m")
    for est in ("--overlap", "--width"):
        for v in ("nan", "-1", "abc"):
            bad("estimate-frf", rec, "-o", out, est, v)
    bad("estimate-frf", rec, "-o", out, "--window", "bogus", "--estimator", "H1")
    bad("estimate-frf", rec, "-o", out, "--nperseg", "1000000000", "--estimator", "H1")
    bad("estimate-frf", rec, "-o", out, "--nperseg", "4", "--estimator", "H1")
    bad("estimate-frf", rec, "-o", out, "--scale", "force=2")
    bad("estimate-frf", rec, "-o", out, "--estimator", "H3")
    for cmd in (["simulate"], ["identify"], ["discover"], ["inverse"], ["inverse", "predict"], ["explain"],
                ["info"], ["estimate-frf"], ["bogus-command"], []):
        bad(*cmd)  # missing arguments: usage error, one line
    return cases


def cases_bad_paths(base: Path) -> list[Case]:
    """Outputs that cannot be written (checked before any work) and inputs that are not files."""
    frf, rec = "{base}/frf.csv", "{base}/rec.csv"
    cases = []

    def bad(*argv, files=None, expect=(2,)):
        cases.append(Case("path", list(argv), files or {}, expect=expect))

    precious = {"keep.csv": b"do not destroy\n", "sub/x": b"x"}
    for target in ("{work}/missing/out.csv", "{work}/sub", "{work}/out.xyz", "{work}/out", "{work}/keep.csv/x.csv"):
        bad("simulate", "-o", target, files=precious)
        bad("estimate-frf", rec, "-o", target, files=precious)
    for plot in ("{work}/bad.xyz", "{work}/missing/f.png", "{work}/sub", "{work}/noext"):
        bad("simulate", "-o", "{work}/keep.csv", "--plot", plot, files=precious)
        bad("estimate-frf", rec, "-o", "{work}/keep.csv", "--plot", plot, files=precious)
        bad("identify", frf, "--plot", plot, files=precious)
        bad("discover", frf, "--plot", plot, files=precious)
    bad("simulate", "-o", "{work}/keep.csv", "--plot", "{work}/keep.csv", files=precious)
    bad("estimate-frf", "{work}/r.csv", "-o", "{work}/r.csv", files={"r.csv": (base / "rec.csv").read_bytes()})
    bad("identify", "{work}/f.csv", "--plot", "{work}/f.csv", files={"f.csv": (base / "frf.csv").read_bytes()})
    bad("estimate-frf", rec, "-o", "{work}/out.uff", "--plot", "{work}/out.uff")
    for command in _with_tune(DATA_COMMANDS) + [["estimate-frf", "{file}", "-o", "{work}/o.csv"]]:
        for target in ("{work}/missing.csv", "{work}/sub", "{work}/f.unknown", "{work}/noext"):
            argv = [a.replace("{file}", target) for a in command]
            bad(*argv, files={"sub/x": b"x", "f.unknown": b"1,2\n", "noext": b"1,2\n"})
    for m in ("{work}/missing", "{work}/keep.csv", "{work}/sub"):
        bad("inverse", "predict", m, frf, files=precious)
        bad("inverse", "evaluate", m, files=precious)
        bad("explain", m, files=precious)
    bad("inverse", "train", "--out", "{work}/keep.csv", files=precious)
    bad("inverse", "train", "--out", "{work}/keep.csv/m", files=precious)
    bad("explain", "{base}/opt", "--out", "{work}/keep.csv", files=precious)  # refused: no network
    return cases


def cases_damaged_models(base: Path) -> list[Case]:
    """Saved models with an edited model.json or a damaged weights.pt."""
    rng = random.Random(ROOT_SEED + 2)
    meta = json.loads((base / "net" / "model.json").read_text())
    weights = (base / "net" / "weights.pt").read_bytes()
    metas = []
    for kind in ("physics", "hybrid", "optimization", "bogus", None, 3):
        metas.append({**meta, "kind": kind})
        metas.append({**meta, "kind": kind, "params": {**meta["params"], "kind": kind}})
    metas.append({**meta, "fit_info": {**meta["fit_info"], "kind": "physics"}, "kind": "physics",
                  "params": {**meta["params"], "kind": "physics"}})
    for key in ("schema", "params", "rig", "bounds", "freq_hz", "std_scale", "network", "scaler"):
        metas.append({k: v for k, v in meta.items() if k != key})
        metas.append({**meta, key: "garbage"})
        metas.append({**meta, key: None})
    metas += [{**meta, "freq_hz": meta["freq_hz"][:10]}, {**meta, "rig": {**meta["rig"], "m2": -1}},
              {**meta, "rig": {**meta["rig"], "bogus": 1}}, {**meta, "std_scale": [1, 2, 3]},
              {**meta, "network": {"n_members": 10 ** 9, "sizes": meta["network"]["sizes"]}},
              {**meta, "network": {"n_members": 1, "sizes": [240, 10 ** 9, 2]}},
              {**meta, "network": {"n_members": 2, "sizes": meta["network"]["sizes"]}},
              {**meta, "params": {**meta["params"], "noise": "x"}}, [], "text", 1]
    # each edit as saved (the checksum then disagrees) and without the checksum (older models have none),
    # so the structural checks are exercised too
    texts = [json.dumps(m).encode() for m in metas]
    texts += [json.dumps({k: v for k, v in m.items() if k != "sha256"}).encode() for m in metas if isinstance(m, dict)]
    whole = json.dumps(meta).encode()
    texts += [whole[:rng.randrange(len(whole))] for _ in range(8)] + [b"", b"\xff\xfe", b"{}"]
    damaged_weights = [weights[:rng.randrange(len(weights))] for _ in range(12)]
    damaged_weights += [b"", b"garbage", bytes(rng.randrange(256) for _ in range(500))]
    flipped = []
    for _ in range(10):  # flips land in the zip structure or in the numbers: refused or finite answers
        w = bytearray(weights)
        for _ in range(rng.randint(1, 8)):
            w[rng.randrange(len(w))] = rng.randrange(256)
        flipped.append(bytes(w))
    nan_weights = bytearray(weights)  # NaN bit patterns written into the tensor data
    i = weights.rfind(b"archive/data/0") + 200
    nan_weights[i:i + 16] = np.full(4, np.nan, np.float32).tobytes()
    cases = []
    commands = [["inverse", "predict", "{work}/m", "{base}/paper.csv", "--json"], ["inverse", "evaluate", "{work}/m"]]
    explain = ["explain", "{work}/m", "--quick", "--no-distill"]  # the same loader: every 4th variant
    for k, text in enumerate(texts):
        for cmd in commands + ([explain] if k % 4 == 0 else []):
            cases.append(Case("model.json", cmd, {"m/model.json": text, "m/weights.pt": weights}, expect=(2,)))
    for k, w in enumerate(damaged_weights):
        for cmd in commands + ([explain] if k % 4 == 0 else []):
            cases.append(Case("weights.pt", cmd, {"m/model.json": whole, "m/weights.pt": w}, expect=(2,)))
    for w in flipped + [bytes(nan_weights)]:
        for cmd in commands:
            cases.append(Case("weights.pt flipped", cmd, {"m/model.json": whole, "m/weights.pt": w}))
    return cases


def cases_semantic_edges(base: Path) -> list[Case]:
    """Well-formed files that no fit can use (issue 16 item 11): refused, or answered without NaN."""
    from satmd.io import load_frf, save_frf

    frf = load_frf(base / "paper.csv")
    tmp = base.parent / "fuzzedges"
    tmp.mkdir(exist_ok=True)
    variants = {
        "one_row": frf.band(40.0, 40.5),
        "two_rows": frf.band(40.0, 42.0),
        "huge": type(frf)(frf.freq_hz, {c: v * 1e300 for c, v in frf.channels.items()},
                          {c: s * 1e300 for c, s in frf.std.items()}),
        "mhz": type(frf)(frf.freq_hz * 1e6, frf.channels, frf.std),
    }
    files = {}
    for name, data in variants.items():
        save_frf(data, tmp / f"{name}.csv")
        files[f"{name}.csv"] = (tmp / f"{name}.csv").read_bytes()
    cases = []
    for name in files:
        for command in (["identify", "{work}/" + name, "--json"], ["identify", "{work}/" + name],
                        ["discover", "{work}/" + name, "--json"], ["info", "{work}/" + name]):
            cases.append(Case("edge", command, {name: files[name]}))
    for extra in (["--band", "70:71"], ["--init", "m2=-1"], ["--init", "m2=0"], ["--init", "m2=1e300"]):
        cases.append(Case("edge", ["identify", "{base}/paper.csv", "--json", *extra]))
    return cases


GROUPS = {
    "malformed_csv": cases_malformed_csv,
    "damaged_formats": cases_damaged_formats,
    "bad_options": cases_bad_options,
    "bad_paths": cases_bad_paths,
    "damaged_models": cases_damaged_models,
}


@pytest.mark.parametrize("group", list(GROUPS))
def test_commands_survive_bad_input(group, base, tmp_path):
    run_group(GROUPS[group](base), base, tmp_path)


def test_fit_edges(base, tmp_path):
    run_group(cases_semantic_edges(base), base, tmp_path)


def test_enough_inputs(base):
    counts = {name: len(make(base)) for name, make in {**GROUPS, "edges": cases_semantic_edges}.items()}
    assert sum(counts.values()) >= 1000, counts

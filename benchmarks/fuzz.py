"""Hostile inputs against every command and the public API (issue 28): counts per outcome class.

    nice python benchmarks/fuzz.py [--workers 2] [--limit N] [--only FAMILY]

The cases come from `benchmarks/_fuzz_cases.py` (1500+, deterministic). Each
runs in a worker process under an address-space limit (`resource.setrlimit`,
RLIMIT_AS, default 6 GiB) and a time limit; API calls and ``satmd.cli.main``
run inside the worker, ``python -m satmd`` subprocesses are used for the cases
that send SIGINT / SIGTERM. Every case is classified:

refused          a clean refusal naming the file or option (and what is wrong)
answered         a correct answer (with the warning the case requires, finite std >= 0, not absurd and not
                 far below the error beside it, or no std with its reason said)
unclear          a refusal that does not name the file or option, shows an array repr or raw control characters
accepted         hostile input taken silently (should have been refused)
silent           an answer without the warning the case requires (a glitch, unrelated channels)
false_refusal    a valid input refused
traceback        any other exception (after Ctrl-C: anything but one line "satmd: interrupted" and exit 130)
hang             past the time limit
memory           MemoryError or the worker killed (the address-space limit)
leftover         a temporary file left behind
damaged          an interruption left an old output destroyed or a new one incomplete
bad_std          a std that is negative, infinite or absurd, 0 beside an error, missing without a reason,
                 or ``explained`` for a prediction that says nothing

Writes ``benchmarks/results/fuzz.json`` and prints one line of counts.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT))

import _fuzz_cases as fc  # noqa: E402

CLASSES = ("refused", "answered", "unclear", "accepted", "silent", "false_refusal", "traceback", "hang", "memory",
           "leftover", "damaged", "bad_std")
GOOD = ("refused", "answered")
CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f\u202a-\u202e\u2066-\u2069]")


class _Timeout(BaseException):
    pass


def portable(text: str, root=ROOT) -> str:
    """A case's output with this machine's paths named for what they are (a traceback quotes its files): the
    results file is read on other machines."""
    for path, name in ((str(root), "{repo}"), (sys.base_prefix, "{python}"), (str(Path.home()), "~")):
        text = text.replace(path, name)
    return text


def _alarm(signum, frame):  # noqa: ARG001
    raise _Timeout()


def _limit(nbytes):
    def apply():
        resource.setrlimit(resource.RLIMIT_AS, (nbytes, nbytes))
    return apply


# --- one case --------------------------------------------------------------------------------
def _sub(value, base, work):
    if isinstance(value, str):
        return value.replace("{base}", str(base)).replace("{work}", str(work))
    if isinstance(value, list):
        return [_sub(v, base, work) for v in value]
    return value


def _materialise(files, base, work):
    for name, spec in files.items():
        p = work / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(spec, bytes):
            p.write_bytes(spec)
        elif spec[0] == "fifo":
            os.mkfifo(p)
        elif spec[0] == "link":
            p.symlink_to(spec[1])
        elif spec[0] == "sparse":
            with open(p, "wb") as fh:
                fh.truncate(spec[1])
        elif spec[0] == "dir":
            p.mkdir()
        elif spec[0] == "wav_frames":
            p.write_bytes(fc._wav(spec[1], spec[2]))
        elif spec[0] == "npz_zeros":
            p.write_bytes(fc.npz_zeros(spec[1]))
        elif spec[0] == "model_edit":
            shutil.copytree(base / spec[1], p)
            meta = json.loads((p / "model.json").read_text())
            (p / "model.json").write_text(fc.tamper(meta, spec[2]))


def _api(c, base, work):
    from satmd import identify
    from satmd.discovery import discover, discover_many
    from satmd.identification import identify_many
    from satmd.io import is_recording, load_frf, load_recording, save_frf, save_recording
    from satmd.signal import estimate_frf
    from satmd.simulation import simulate_recording
    from satmd.physics import Rig

    op, args, kw = c["op"], _sub(c.get("args", []), base, work), c.get("kwargs", {})
    valid = None
    if op in ("identify_many", "discover_many"):
        valid = load_frf(base / "frf.csv")
    table = {
        "load_frf": lambda: load_frf(*args, **kw), "load_recording": lambda: load_recording(*args, **kw),
        "load_frf_raw": lambda: load_frf(*args), "load_recording_raw": lambda: load_recording(*args),
        "is_recording": lambda: is_recording(args[0]), "estimate": lambda: estimate_frf(load_recording(args[0])),
        "simulate_recording": lambda: simulate_recording(args[0], args[1], Rig()),
        "load_model": lambda: _model().load(args[0]),
        "predict_model": lambda: _model().load(args[0]).predict_one(load_frf(args[1])),
        "identify": lambda: identify(fc.WRONG[args[0]]), "discover": lambda: discover(fc.WRONG[args[0]]),
        "estimate_frf": lambda: estimate_frf(fc.WRONG[args[0]]),
        "identify_many": lambda: identify_many([valid, fc.WRONG[args[0]]]),
        "discover_many": lambda: discover_many([valid, fc.WRONG[args[0]]]),
        "save_frf": lambda: load_frf(save_frf(load_frf(args[0]), args[1])),
        "save_recording": lambda: load_recording(save_recording(load_recording(args[0]), args[1])),
    }
    return table[op]()


def _model():
    from satmd.inverse import InverseModel

    return InverseModel


def _names_ok(c, message):
    m = message.lower()
    return not c["names"] or any(n.lower() in m for n in c["names"])


def _clean_message(message):
    return "array(" not in message and "Traceback" not in message and not CONTROL.search(message)


# a std beyond ten widths of the inverse model's training box (R 0..103 Ω, L 0..0.5 H) is absurd (issue 38: 6.9e10 Ω)
ABSURD_STD = {"R_std": 1030.0, "L_std": 5.0}


MAX_Z = 1e3  # an error this many std off: the std claims a certainty the answer does not have (issue 38: 4e301 σ)


def _std_problem(obj, excused=False):
    """A std that is negative, infinite or absurd (`ABSURD_STD`) anywhere in a result (dict / JSON), or one
    that an error beside it (``abs_err_X``) exceeds `MAX_Z` times (a std of 0 with an error), else None.

    A missing std (null / NaN) passes only when ``excused``: the output says why it gives none ("no std: ...",
    e.g. a one-member ensemble); without a reason it is a std gone missing.
    """
    import math

    import numpy as np

    if isinstance(obj, dict):
        for k, v in obj.items():
            if k.endswith("_std") and not isinstance(v, dict):
                try:
                    values = np.ravel(np.asarray(v, dtype=float))  # null -> NaN
                except (TypeError, ValueError):
                    values = []
                for x in values:
                    if math.isnan(x) and not excused:
                        return f"{k} = {x} without a reason (no 'no std: ...' said)"
                    if math.isinf(x) or x < 0 or x > ABSURD_STD.get(k, math.inf):
                        return f"{k} = {x}"
                err = obj.get("abs_err_" + k[:-4])
                if isinstance(err, (int, float)) and values.size == 1 and math.isfinite(values[0]) and \
                        err > MAX_Z * values[0]:
                    return f"{k} = {values[0]:.3g} beside an error of {err:.3g}"
            p = _std_problem(v, excused)
            if p:
                return p
    elif isinstance(obj, list):
        for v in obj:
            p = _std_problem(v, excused)
            if p:
                return p
    return None


TEXT_STD = re.compile(r"± ?(0(\.0*)?(?![\d.e])|[\d.]+e\+\d+)")  # "± 0" or "± 3.5e+10" in a text report


def _explained(obj):
    if isinstance(obj, dict):
        if obj.get("explained") is True:
            return True
        return any(_explained(v) for v in obj.values())
    return isinstance(obj, list) and any(_explained(v) for v in obj)


def run_api_case(c, base, work):
    import warnings

    from satmd.errors import SatmdError

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = _api(c, base, work)
        except MemoryError:
            return "memory", "MemoryError"
        except (SatmdError, TypeError, OSError) as exc:
            message = str(exc)
            if isinstance(exc, TypeError) and c["family"] != "API types" and c["op"] not in ("load_frf_raw",
                                                                                            "load_recording_raw"):
                return "traceback", f"TypeError: {message}"[:300]
            if c["expect"] == "answer":
                return "false_refusal", message[:300]
            ok = _names_ok(c, message) and _clean_message(message)
            return ("refused" if ok else "unclear"), message[:300]
    texts = " | ".join(str(w.message) for w in caught)
    if c["expect"] == "refuse":
        return "accepted", f"returned {type(result).__name__}: {str(result)[:150]}"
    if c["expect"] == "warn" and not _names_ok(c, texts):
        return "silent", "no warning naming " + "/".join(c["names"])
    if c.get("check_std"):
        problem = _std_problem(result if isinstance(result, dict) else {}, excused="no std" in texts)
        if problem:
            return "bad_std", problem
        if c.get("unexplained") and _explained(result):
            return "bad_std", "explained: true for a prediction whose std says nothing"
    return "answered", texts[:200]


def run_cli_case(c, base, work):
    import contextlib
    import io

    from satmd.cli import main

    argv = _sub(c["argv"], base, work)
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = main(argv)
    except MemoryError:
        return "memory", "MemoryError"
    except _Timeout:
        raise
    except BaseException as exc:  # noqa: BLE001
        return "traceback", f"{type(exc).__name__}: {exc}"[:300]
    return _judge_cli(c, rc, out.getvalue(), err.getvalue())


def _judge_cli(c, rc, out, err):
    if rc == 2:
        lines = [ln for ln in err.splitlines() if ": error: " in ln]
        message = lines[-1] if lines else err.strip()[-300:]
        if c["expect"] == "answer":
            return "false_refusal", message[:300]
        ok = len(lines) == 1 and _names_ok(c, message) and _clean_message(message) and "Traceback" not in err
        if c.get("no_control") and CONTROL.search(err + out):
            ok = False
        return ("refused" if ok else "unclear"), message[:300]
    if rc != 0:
        return "traceback", f"exit {rc}: {err.strip()[-300:]}"
    if c["expect"] == "refuse":
        return "accepted", (out + err)[-200:]
    if c["expect"] == "warn" and not _names_ok(c, err):
        return "silent", "no warning naming " + "/".join(c["names"])
    if c.get("no_control") and CONTROL.search(err + out):
        return "unclear", "raw control characters echoed"
    if c.get("text_std") and TEXT_STD.search(out):
        return "bad_std", f"text report shows {TEXT_STD.search(out).group(0)!r}"
    if c.get("check_std"):
        try:
            doc = json.loads(out, parse_constant=lambda x: float("nan"))
        except ValueError:
            return "traceback", "invalid JSON"
        problem = _std_problem(doc, excused="no std" in err)
        if problem:
            return "bad_std", problem
        if c.get("unexplained") and _explained(doc):
            return "bad_std", "explained: true for a prediction whose std says nothing"
    return "answered", err.strip()[-200:]


def run_proc_case(c, base, work, limit, timeout):
    argv = [sys.executable, "-m", "satmd", *_sub(c["argv"], base, work)]
    old = {n: _snapshot(work / n) for n in c.get("keep", [])}
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    fsize = c.get("fsize")

    def limits():
        _limit(limit)()
        if fsize:  # a full disk: writes beyond this many bytes fail (EFBIG; Python ignores SIGXFSZ)
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize, fsize))

    p = subprocess.Popen(argv, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, preexec_fn=limits)
    if c.get("signal"):
        time.sleep(c["delay"])
        for k in range(1 + int(c.get("repeat", 0))):  # "repeat": further presses, "gap" s apart (a double Ctrl-C)
            if k:
                time.sleep(c.get("gap", 0.05))
            if p.poll() is None:
                p.send_signal(getattr(signal, c["signal"]))
    try:
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        p.communicate()
        return "hang", f"past {timeout} s"
    out, err = out.decode(errors="replace"), err.decode(errors="replace")
    if "Traceback" in err:
        return "traceback", err.strip()[-300:]
    if not c.get("signal"):
        cls, detail = _judge_cli(c, p.returncode, out, err)
        for name, before in old.items():  # a refused write leaves the old output as it was
            if cls == "refused" and _snapshot(work / name) != before:
                return "damaged", f"{name} changed by a refused command"
        return cls, detail
    if c["signal"] == "SIGINT" and p.returncode not in (0, 2):  # Ctrl-C: one line and 130, at any moment (issue 38)
        lines = [ln for ln in err.splitlines() if ln.strip()]
        if p.returncode != 130 or lines[-1:] != ["satmd: interrupted"] or lines.count("satmd: interrupted") != 1:
            return "traceback", f"exit {p.returncode} after Ctrl-C: {err.strip()[-200:]!r}"
    for name, before in old.items():
        now = _snapshot(work / name)
        if now != before and not _complete(work / name):
            return "damaged", f"{name} changed but is not a complete new output (exit {p.returncode})"
    return "answered", f"exit {p.returncode}"


def _snapshot(path: Path):
    if path.is_dir():
        return {q.relative_to(path).as_posix(): q.read_bytes() for q in sorted(path.rglob("*")) if q.is_file()}
    return path.read_bytes() if path.exists() else None


def _complete(path: Path) -> bool:
    """A new output that is whole: loads (data), is a PNG, or a report whose figures all exist."""
    try:
        if path.is_dir():
            text = (path / "index.md").read_text()
            figs = re.findall(r"\]\((figures/[^)]+)\)", text)
            return text.startswith("# satmd report") and all((path / f).is_file() for f in figs) and \
                not (path / "figures" / "old.png").exists()
        if path.suffix == ".png":
            return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        if path.suffix == ".csv":
            from satmd.io import load_frf

            load_frf(path)
            return True
        from satmd.io import load_recording

        load_recording(path)
        return True
    except Exception:  # noqa: BLE001
        return False


def run_case(c, base, scratch, limit, timeout):
    work = Path(tempfile.mkdtemp(prefix=f"c{c['id']}_", dir=scratch))
    t0 = time.perf_counter()
    try:
        _materialise(c.get("files", {}), base, work)
        before = {q.as_posix() for q in work.rglob("*")}
        signal.signal(signal.SIGALRM, _alarm)
        signal.alarm(int(timeout))
        try:
            if c["kind"] == "api":
                cls, detail = run_api_case(c, base, work)
            elif c["kind"] == "cli":
                cls, detail = run_cli_case(c, base, work)
            else:
                signal.alarm(0)
                cls, detail = run_proc_case(c, base, work, limit, timeout)
        finally:
            signal.alarm(0)
        left = [q.name for q in work.rglob("*") if (".tmp" in q.name or q.name.endswith(".old"))
                and q.as_posix() not in before]
        left += [q.name for q in base.rglob("*") if ".tmp" in q.name]
        if left and cls in GOOD:
            cls, detail = "leftover", f"left {left[:3]}"
    except _Timeout:
        cls, detail = "hang", f"past {timeout} s"
    except MemoryError:
        cls, detail = "memory", "MemoryError"
    except Exception as exc:  # noqa: BLE001 - the harness itself must not stop
        cls, detail = "traceback", "harness: " + "".join(traceback.format_exception_only(exc)).strip()[:300]
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return {"id": c["id"], "class": cls, "detail": detail, "s": round(time.perf_counter() - t0, 3)}


# --- workers ----------------------------------------------------------------------------------
def _worker(conn, cases, base, scratch, limit, timeout):
    _limit(limit)()
    os.environ.setdefault("MPLBACKEND", "Agg")
    import warnings

    warnings.simplefilter("ignore")
    for c in cases:
        conn.send(("start", c["id"]))
        conn.send(("done", run_case(c, Path(base), Path(scratch), limit, timeout)))
    conn.send(("end", None))


def run_all(cases, base, scratch, workers, limit, timeout):
    import multiprocessing as mp

    ctx = mp.get_context("spawn")  # not fork: torch's thread pools deadlock in a forked child
    queue = list(cases)
    chunk = 40
    results, running = {}, []

    def launch():
        batch, queue[:] = queue[:chunk], queue[chunk:]
        parent, child = ctx.Pipe()
        proc = ctx.Process(target=_worker, args=(child, batch, str(base), str(scratch), limit, timeout), daemon=True)
        proc.start()
        running.append({"proc": proc, "conn": parent, "batch": batch, "current": None, "since": time.time()})

    while queue or running:
        while queue and len(running) < workers:
            launch()
        for w in list(running):
            try:
                while w["conn"].poll(0.05):
                    kind, value = w["conn"].recv()
                    if kind == "start":
                        w["current"], w["since"] = value, time.time()
                    elif kind == "done":
                        results[value["id"]] = value
                        w["current"] = None
                    else:
                        w["proc"].join()
                        running.remove(w)
                        break
            except (EOFError, OSError):
                pass
            if w not in running:
                continue
            dead = not w["proc"].is_alive()
            stuck = w["current"] is not None and time.time() - w["since"] > timeout + 60
            if dead or stuck:
                if stuck:
                    w["proc"].kill()
                w["proc"].join()
                if w["current"] is not None:
                    cls = "hang" if stuck else "memory"
                    results[w["current"]] = {"id": w["current"], "class": cls, "s": None,
                                             "detail": f"worker {'stuck' if stuck else 'died'} "
                                                       f"(exit {w['proc'].exitcode})"}
                queue[:0] = [c for c in w["batch"] if c["id"] not in results and c["id"] != w["current"]]
                running.remove(w)
        time.sleep(0.01)
    return [results[c["id"]] for c in cases]


def describe(c) -> str:
    if c["kind"] == "api":
        args = ", ".join(str(a)[:40] for a in c.get("args", []))
        return f"{c['op']}({args})" + (f" {c['kwargs']}" if c.get("kwargs") else "")
    text = "satmd " + " ".join(str(a)[:40] for a in c["argv"])
    again = f" (x{1 + c['repeat']}, {c.get('gap', 0.05)} s apart)" if c.get("repeat") else ""
    return text + (f" + {c['signal']} after {c['delay']} s{again}" if c.get("signal") else "")


def main():
    sys.path.insert(0, str(HERE))
    from _machine import describe as machine_text
    from _machine import load_after, machine

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--limit", type=int, default=None, help="run only the first N cases")
    ap.add_argument("--only", default=None, help="run only these families (comma-separated)")
    ap.add_argument("--memory-gib", type=float, default=6.0, help="address-space limit per worker (GiB)")
    ap.add_argument("--timeout", type=float, default=90.0, help="seconds per case")
    ap.add_argument("--out", default=str(HERE / "results" / "fuzz.json"))
    args = ap.parse_args()
    result = {"machine": machine(device="cpu", threads=args.workers)}
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="satmd_fuzz_") as tmp:
        base, scratch = Path(tmp) / "base", Path(tmp) / "work"
        base.mkdir()
        scratch.mkdir()
        fc.make_base(base)
        cases = fc.generate(base)
        if args.only:
            cases = [c for c in cases if c["family"] in args.only.split(",")]
        if args.limit:
            cases = cases[:args.limit]
        limit = int(args.memory_gib * 2 ** 30)
        results = run_all(cases, base, scratch, args.workers, limit, args.timeout)
    counts = Counter(r["class"] for r in results)
    families = {}
    for c, r in zip(cases, results):
        families.setdefault(c["family"], Counter())[r["class"]] += 1
    failures = [{"id": c["id"], "family": c["family"], "case": describe(c), "class": r["class"],
                 "detail": portable(r["detail"])} for c, r in zip(cases, results) if r["class"] not in GOOD]
    result.update({
        "cases": len(cases), "workers": args.workers, "memory_limit_gib": args.memory_gib, "timeout_s": args.timeout,
        "wall_s": round(time.perf_counter() - t0, 1),
        "counts": {k: counts.get(k, 0) for k in CLASSES},
        "families": {f: {k: v for k, v in sorted(n.items())} for f, n in families.items()},
        "kinds": dict(Counter(c["kind"] for c in cases)),
        "failures": failures,
        "examples": {cls: next((f"{describe(c)} -> {portable(r['detail'])}" for c, r in zip(cases, results)
                                if r["class"] == cls), None) for cls in GOOD},
    })
    result["machine"].update(load_after())
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=1, default=str) + "\n")
    line = f"fuzz: {len(cases)} cases in {result['wall_s']:.0f} s: " + ", ".join(
        f"{k} {counts.get(k, 0)}" for k in CLASSES)
    print(line + " | " + machine_text(result["machine"]))
    for f in failures[:30]:
        print(f"  [{f['class']}] {f['family']}: {f['case']} -> {f['detail']}")


def readme_markdown(result: dict) -> str:
    """The README's fuzz table: outcome classes per family of hostile input."""
    shown = list(CLASSES)
    head = "| family | cases | " + " | ".join(k.replace("_", " ") for k in shown) + " |"
    rows = [head, "|" + "---|" * (len(shown) + 2)]
    for fam, n in result["families"].items():
        rows.append(f"| {fam} | {sum(n.values())} | " + " | ".join(str(n.get(k, 0)) for k in shown) + " |")
    c = result["counts"]
    rows.append(f"| **all** | **{result['cases']}** | " + " | ".join(f"**{c.get(k, 0)}**" for k in shown) + " |")
    kinds = result.get("kinds", {})
    load = (result.get("machine") or {}).get("load_average_1_5_15_before")
    rows.append("")
    rows.append(f"{result['cases']} cases: {kinds.get('api', 0)} API calls and {kinds.get('cli', 0)} command lines "
                f"in worker processes, {kinds.get('proc', 0)} `python -m satmd` processes (sent SIGINT or SIGTERM, "
                f"or writing to a full disk); {result['workers']} worker{'' if result['workers'] == 1 else 's'}, each under a "
                f"{result['memory_limit_gib']:g} GiB address-space limit and {result['timeout_s']:g} s per case; "
                f"{result['wall_s']:.0f} s on a shared 2-core machine"
                + (f" (load {load[0] if isinstance(load, list) else load})" if load else "")
                + ". Refused: a one-line error naming the file or option; answered: a correct result (with the "
                "warning the case calls for, std finite and >= 0). `python benchmarks/fuzz.py` (classes in its "
                "docstring).")
    return "\n".join(rows)


if __name__ == "__main__":
    main()

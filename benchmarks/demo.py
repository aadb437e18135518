"""`make demo`'s main job, measured: wall time, CPU time and peak memory of `satmd reproduce`.

    python benchmarks/demo.py [--out benchmarks/results/demo.json] [--quick]

Runs the installed `satmd reproduce --out DIR` in a subprocess (a fresh interpreter, as `make demo`
does, into a temporary folder) and records its wall time, CPU time (user + system: on a busy machine
wall time includes waiting for a core), peak resident memory (the child's ``ru_maxrss``) against the
4 GB the demo must stay within (issue 23), the sections that failed (none should) and each section's
own time from the report. Writes a JSON file and prints one line.
"""
from __future__ import annotations

import argparse
import json
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import describe, load_after, machine  # noqa: E402

LIMIT_GB = 4.0
_SCRIPT = Path(sys.executable).with_name("satmd")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "results" / "demo.json"))
    ap.add_argument("--quick", action="store_true", help="reproduce --quick (a smoke run)")
    args = ap.parse_args(argv)
    result = {"machine": machine(device="cpu")}
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [str(_SCRIPT) if _SCRIPT.exists() else sys.executable, *([] if _SCRIPT.exists() else ["-m", "satmd"]),
               "reproduce", "--out", str(Path(tmp) / "report"), *(["--quick"] if args.quick else [])]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        index = Path(tmp) / "report" / "index.md"
        md = index.read_text(encoding="utf-8") if index.exists() else ""
    titles = re.findall(r"^## (.+)$", md, flags=re.M)
    seconds = [float(s) for s in re.findall(r"\*\(section computed in ([0-9.]+) s\)\*", md)]
    result.update({
        "command": " ".join(Path(c).name if i == 0 else c for i, c in enumerate(cmd)), "quick": args.quick,
        "exit_code": proc.returncode, "wall_s": round(wall, 1),
        "cpu_s": round((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), 1),
        "peak_rss_gb": round(after.ru_maxrss / 2**20, 2), "limit_gb": LIMIT_GB,
        "sections_s": dict(zip(titles, seconds)),
        "failed": [line for line in proc.stderr.splitlines() if line.startswith("  ")],
    })
    result["within_limit"] = result["peak_rss_gb"] <= LIMIT_GB and proc.returncode == 0
    result["machine"].update(load_after())
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    print(f"demo: exit {proc.returncode}, {result['wall_s']} s wall, {result['cpu_s']} s CPU, peak "
          f"{result['peak_rss_gb']} GB (limit {LIMIT_GB} GB) | " + describe(result["machine"]))
    return 0 if result["within_limit"] else 1


def readme_markdown(result: dict) -> str:
    """The README's sentence on `make demo` (region ``demo``), from demo.json."""
    m = result["machine"]
    load = m.get("load_average_1_5_15_before") or [float("nan")]
    slow = sorted(result["sections_s"].items(), key=lambda kv: -kv[1])[:2]
    return (f"`make demo`'s main job (`satmd reproduce`, measured by `benchmarks/demo.py`): "
            f"{result['wall_s'] / 60:.1f} min wall ({result['cpu_s'] / 60:.1f} min CPU) on a "
            f"{m['cpu_count']}-core machine at load average {load[0]:.1f}, peak memory "
            f"{result['peak_rss_gb']:.2f} GB (limit {result['limit_gb']:.0f} GB), exit status {result['exit_code']}; "
            "the longest sections: " + ", ".join(f"{t} {s:.0f} s" for t, s in slow) + ".\n")


if __name__ == "__main__":
    sys.exit(main())

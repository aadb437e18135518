"""Start-up time: `import satmd` and `satmd --help`, each in a fresh interpreter.

    python benchmarks/startup.py [--repeats 9] [--out benchmarks/results/startup.json]

Every measurement is a new subprocess (nothing cached in memory but the OS
file cache), timed from spawn to exit; the figure is the median of
``--repeats`` runs after one warm-up run each, with a bare ``python -c pass``
for reference. The subprocesses may write and read bytecode (``.pyc``), as an
installed package does (pip compiles it on install), whatever
``PYTHONDONTWRITEBYTECODE`` says in the caller's environment: with it set,
every run compiled satmd's 62 modules afresh, 0.12 s of a 0.44 s ``--help``. It also records which heavy modules (scipy.optimize,
scipy.stats, matplotlib, torch) `import satmd` loaded: none should be, they
load where they are used. CPU time (user + system) is recorded beside wall
time: on a busy machine wall time includes waiting for a core. Writes a JSON
file and prints one line.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

TARGET_S = 0.3  # issue 13: `import satmd` and `satmd --help` within 0.3 s
HEAVY = ("scipy.optimize", "scipy.stats", "matplotlib", "torch")
_SCRIPT = Path(sys.executable).with_name("satmd")  # the installed console script, as a user runs it
COMMANDS = {
    "python_bare": [sys.executable, "-c", "pass"],
    "import_satmd": [sys.executable, "-c", "import satmd"],
    "satmd_help": [str(_SCRIPT), "--help"] if _SCRIPT.exists()
    else [sys.executable, "-c", "import sys; from satmd.cli import main; sys.exit(main(['--help']))"],
}


#: the children's environment: bytecode written on the warm-up run and read after it (`__doc__`)
CHILD_ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def run_once(cmd) -> tuple[float, float]:
    """Wall seconds from spawn to exit of one subprocess, and the CPU seconds it used (user + system).

    On a busy machine wall time includes waiting for a core; CPU time is what start-up itself costs.
    """
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=CHILD_ENV)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def heavy_modules_loaded() -> list[str]:
    """Heavy modules present in sys.modules right after `import satmd` (fresh interpreter)."""
    code = f"import sys, satmd; print(','.join(m for m in {HEAVY!r} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True,
                         env=CHILD_ENV).stdout.strip()
    return [m for m in out.split(",") if m]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=9)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "startup.json"))
    args = ap.parse_args(argv)

    for cmd in COMMANDS.values():  # warm-up: OS file cache and .pyc files
        run_once(cmd)
    times = {k: [] for k in COMMANDS}
    cpu = {k: [] for k in COMMANDS}
    for _ in range(args.repeats):  # round-robin, so a change of machine load hits all alike
        for k, cmd in COMMANDS.items():
            w, c = run_once(cmd)
            times[k].append(w)
            cpu[k].append(c)
    median = {k: statistics.median(v) for k, v in times.items()}
    median_cpu = {k: statistics.median(v) for k, v in cpu.items()}
    heavy = heavy_modules_loaded()
    sys.path.insert(0, str(Path(__file__).parent))
    from _machine import machine  # after the timings: it imports numpy (and asks torch its version)

    result = {
        "median_s": median,
        "min_s": {k: min(v) for k, v in times.items()},
        "runs_s": times,
        "median_cpu_s": median_cpu,
        "repeats": args.repeats,
        "target_s": TARGET_S,
        "meets_target": bool(median["import_satmd"] <= TARGET_S and median["satmd_help"] <= TARGET_S),
        # on a loaded machine wall time waits for a core; CPU time is start-up's own cost
        "meets_target_cpu": bool(median_cpu["import_satmd"] <= TARGET_S and median_cpu["satmd_help"] <= TARGET_S),
        "heavy_modules_after_import": heavy,
        "bytecode": "cached (written on the warm-up run)",
        "caller_had_PYTHONDONTWRITEBYTECODE": "PYTHONDONTWRITEBYTECODE" in os.environ,
        "python": platform.python_version(),
        "machine": machine(device="cpu", threads=1),
        "cpu_count": os.cpu_count(),
        "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    }
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"startup (median of {args.repeats}): import satmd {median['import_satmd']:.3f} s, "
          f"satmd --help {median['satmd_help']:.3f} s, bare python {median['python_bare']:.3f} s "
          f"(target {TARGET_S} s: {'met' if result['meets_target'] else 'NOT met'}; CPU time "
          f"{median_cpu['import_satmd']:.3f} / {median_cpu['satmd_help']:.3f} s, load average "
          f"{result['load_average'][0]:.1f} on {os.cpu_count()} cores); "
          f"heavy modules loaded: {', '.join(heavy) or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

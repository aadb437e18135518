"""Benchmark: memory and time of `identify` on large FRFs (issue 16, item 8).

Each size runs in a fresh subprocess that simulates a noisy FRF on
``linspace(40, 130, N)`` (a1, a2, std not given), then calls
``identify(data)`` with the defaults (global search included). The child
reports its peak resident set size (``resource.getrusage``, whole process:
Python, NumPy and SciPy included), the peak before the fit (imports and
data), the identify wall time and the fit's relative error.

Target: 16,384 points in ≤ 300 MB peak and ≤ 3 s of identify wall time.
Also timed: the CLI end to end on a 16,384-point CSV in a cold process
(interpreter start, imports, CSV parsing and the fit).
Writes benchmarks/results/memory.json and prints one line.

    python benchmarks/memory.py [--quick]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import provenance  # noqa: E402

OUT = Path(__file__).resolve().parent / "results" / "memory.json"
TARGET = {"points": 16384, "peak_mb": 300.0, "time_s": 3.0}

CHILD = r"""
import json, resource, sys, time
import numpy as np
from satmd import Rig, simulate
from satmd.io.frfdata import FRFData
from satmd.identification import identify

n = int(sys.argv[1])
d = simulate(np.linspace(40.0, 130.0, n), Rig(m2=0.6, R=40.0), noise=(0.01, 0.001), seed=1)
d = FRFData(d.freq_hz, dict(d.channels), {}, {})  # no std: the relative fit, as for most lab files
t0 = time.perf_counter()
identify(simulate(noise=0.01, seed=2), warn=False)  # warm-up: SciPy's lazy imports are not the fit's cost
warmup = time.perf_counter() - t0
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
t0 = time.perf_counter()
fit = identify(d, warn=False)
wall = time.perf_counter() - t0
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"points": n, "peak_mb": peak, "peak_before_fit_mb": before, "identify_s": wall,
                  "first_fit_60_points_s": warmup,
                  "rel_error": fit.rel_error, "nfev": fit.nfev, "values": fit.values}))
"""


def run(n: int) -> dict:
    """One size in a fresh interpreter (ru_maxrss is a per-process high-water mark)."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", CHILD, str(n)], capture_output=True, text=True, check=True)
    row = json.loads(out.stdout.strip().splitlines()[-1])
    row["process_s"] = time.perf_counter() - t0
    return row


def run_cli(n: int) -> dict:
    """End to end as a user meets it: `satmd identify FILE --json` on an N-point CSV, cold process.

    Run before any other child: RUSAGE_CHILDREN's peak is the largest child so far.
    """
    import resource
    import tempfile

    import numpy as np

    from satmd import Rig, simulate
    from satmd.io import save_frf

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "big.csv"
        save_frf(simulate(np.linspace(40.0, 130.0, n), Rig(m2=0.6, R=40.0), noise=(0.01, 0.001), seed=1), path)
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-m", "satmd", "identify", str(path), "--json"],
                             capture_output=True, text=True, check=True)
        wall = time.perf_counter() - t0
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return {"points": n, "command": "satmd identify FILE --json (std columns given)", "wall_s": wall,
            "peak_mb": peak, "fit_wall_time_s": json.loads(out.stdout)["wall_time_s"]}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="only 60 and 16,384 points")
    args = ap.parse_args(argv)
    sizes = [60, 16384] if args.quick else [60, 1024, 4096, 16384, 65536, 200000]
    cli = run_cli(TARGET["points"])
    rows = [run(n) for n in sizes]
    at = next(r for r in rows if r["points"] == TARGET["points"])
    big = [r for r in rows if r["points"] >= 4096]
    slope = None
    if len(big) >= 2:  # growth of the peak per frequency point above the interpreter's baseline
        a, b = big[0], big[-1]
        slope = 1024 * (b["peak_mb"] - a["peak_mb"]) / (b["points"] - a["points"])
    result = {
        "benchmark": "memory",
        "setup": "identify(data) with defaults on a simulated noisy a1, a2 FRF over linspace(40, 130, N), "
                 "no std; fresh subprocess per size; peak RSS of the whole process",
        "rows": rows,
        "kb_per_point_above_4096": slope,
        "cli_end_to_end": cli,
        "target": TARGET,
        "met": at["peak_mb"] <= TARGET["peak_mb"] and at["identify_s"] <= TARGET["time_s"],
        "quick": args.quick,
        "machine": {**provenance(), "python": sys.version.split()[0], "platform": platform.platform(),
                    "cpus": os.cpu_count(),
                    "load_avg_1min": os.getloadavg()[0] if hasattr(os, "getloadavg") else None},
    }
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(result, indent=2), encoding="utf-8")
    slope_txt = f", {slope:.2g} KB/point" if slope is not None else ""
    print(f"memory: {at['points']} points peak {at['peak_mb']:.0f} MB, identify {at['identify_s']:.2f} s "
          f"(target <= {TARGET['peak_mb']:.0f} MB, <= {TARGET['time_s']:g} s: "
          f"{'met' if result['met'] else 'NOT met'}){slope_txt}; CLI end to end {cli['wall_s']:.2f} s, "
          f"{cli['peak_mb']:.0f} MB")


if __name__ == "__main__":
    main()

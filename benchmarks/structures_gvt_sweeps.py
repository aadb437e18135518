"""Ground vibration tests swept instead of multisined (issue 47): is the joint placed and named from sine sweeps?

The independent simulator of `structures_gvt` (`benchmarks/_indep_gvt.py`, numpy/scipy only), each test's
structure and joint as there, driven by one linear sine sweep down the band (40 → 5 Hz in 40 s, its RMS over the
sweep the multisine's level) with 40 s of quiet recorded after it, so that the response rings out within the
record (`satmd.structure.transient_spectra` needs it). Written to CSV, read back and located as a user who asks
for it would (`discover` refuses sweeps; these figures are why):

    locate_joint([transient_spectra(load_recording(f)) for f in ("L1.csv", "L3.csv", "L5.csv", "L7.csv")])

Scored as `structures_gvt` scores the place and the law (nulls: no joint). No model is fitted.

    python benchmarks/structures_gvt_sweeps.py [--seeds 0,1,2 | --count 12 --seed0 0] [--out PATH]

Writes benchmarks/results/structures_gvt_sweeps.json and prints one line of figures.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
import _indep_gvt as sim  # noqa: E402
from _machine import machine  # noqa: E402
from structures_gvt import FITTED, plan  # noqa: E402

from satmd.errors import DataError  # noqa: E402
from satmd.io import load_recording  # noqa: E402
from satmd.structure import locate_joint, transient_spectra  # noqa: E402

OUT = ROOT / "benchmarks" / "results" / "structures_gvt_sweeps.json"


def case(structure: str, law: str | None, seed: int) -> dict:
    test = sim.make_test(seed, structure, law)
    t0 = time.perf_counter()
    recs = sim.simulate(test, excitation="sweep")
    row = {**test.describe(), "simulate_s": round(time.perf_counter() - t0, 1)}
    with tempfile.TemporaryDirectory() as tmp:
        for lv, rec in enumerate(recs, 1):
            sim.write_csv(rec, Path(tmp) / f"L{lv}.csv")
        t0 = time.perf_counter()
        try:
            loc = locate_joint([transient_spectra(load_recording(Path(tmp) / f"L{lv}.csv")) for lv in FITTED])
        except DataError as err:
            row["error"] = str(err)
            return row
        row["locate_s"] = round(time.perf_counter() - t0, 1)
    found = loc.between if loc.detected else None
    row["found_between"] = list(found) if found else None
    row["found_law"] = loc.law if found else None
    row["delta_bic_next"] = loc.location[1]["delta_bic"] if found and len(loc.location) > 1 else None
    truth = None if law is None else sorted(row["between"])
    row["placed"] = None if law is None else bool(found) and sorted(found) == truth
    row["named"] = None if law is None else bool(found) and loc.law == law
    row["null_clean"] = None if law is not None else not found
    return row


def summarise(rows) -> dict:
    def share(key):
        scored = [r[key] for r in rows if r.get(key) is not None]
        return {"n": len(scored), "right": int(sum(scored))}

    return {"tests": len(rows), "placed": share("placed"), "named": share("named"), "null_clean": share("null_clean"),
            "errors": sum("error" in r for r in rows),
            "locate_s_median": sorted(r.get("locate_s", 0.0) for r in rows)[len(rows) // 2] if rows else None}


def line(result) -> str:
    s = result["summary"]
    return (f"structures_gvt_sweeps: {s['tests']} swept tests: placed {s['placed']['right']}/{s['placed']['n']}, "
            f"law {s['named']['right']}/{s['named']['n']}, nulls clean {s['null_clean']['right']}/"
            f"{s['null_clean']['n']}, errors {s['errors']}, locate {s['locate_s_median']} s (median)")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=12)
    ap.add_argument("--seed0", type=int, default=0)
    ap.add_argument("--seeds", type=lambda t: [int(x) for x in t.split(",")], default=None)
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    tests = plan(args.count, args.seed0, args.seeds)
    for i, (structure, law, seed) in enumerate(tests, 1):
        rows.append(case(structure, law, seed))
        r = rows[-1]
        print(f"[{i}/{len(tests)}] {structure} {law} seed {seed}: {r.get('found_between')} {r.get('found_law')} "
              f"(truth {r['between']}) {r.get('error', '')} ({r.get('locate_s')} s)", flush=True)
        result = {"machine": machine(), "rows": rows, "summary": summarise(rows),
                  "benchmark_seconds": round(time.perf_counter() - t0, 1)}
        args.out.write_text(json.dumps(result, indent=1))
    print(line(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())

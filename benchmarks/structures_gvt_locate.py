"""Where the joint acts on ground vibration tests satmd never saw (issue 47): `locate_joint` alone, fast.

The tests of `benchmarks/structures_gvt.py` (the independent simulator `benchmarks/_indep_gvt.py`, the same
seeds, levels 1, 3, 5, 7 written to CSV and read back as a user's files), with the frequency-domain location
alone: no output-error fit, no prediction. A whole test there takes 1–4 minutes; here 10–60 s, so a change to
how places are weighed can be compared on the same tests within one sitting. Per test: the place and law
`locate_joint` gives, the true place's rank and ΔBIC, and the true pair's stroke-to-noise ratio at the top
level (RMS over the excited lines of the relative displacement against the spread of the periods' means):
a pair that barely moves against its neighbours is where the place is hardest to tell.

The law here is the spectra's; `discover` then weighs the named laws by simulating them
(`satmd.structure.fit_structure`), so its law count is the one `structures_gvt.py` reports, not this one.

    python benchmarks/structures_gvt_locate.py [--count 40] [--seed0 0] [--out PATH]
    python benchmarks/structures_gvt_locate.py --merge part1.json part2.json [--out PATH]

Writes benchmarks/results/structures_gvt_locate.json and prints one line of figures.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
import _indep_gvt as sim  # noqa: E402
from _machine import describe  # noqa: E402
from structures_gvt import merge, run_plan  # noqa: E402
from satmd.io import load_recording  # noqa: E402
from satmd.structure import locate_joint  # noqa: E402
from satmd.structure.spectra import periodic_spectra  # noqa: E402

FITTED = (1, 3, 5, 7)
OUT = ROOT / "benchmarks" / "results" / "structures_gvt_locate.json"


def stroke_to_noise(spectrum, a: str, b: str) -> float:
    """RMS over the excited lines of a's displacement relative to b's (or the ground's), over its noise."""
    w2 = (2 * np.pi * spectrum.freq_hz) ** 2
    other = spectrum.responses[b] if b != "ground" else 0.0
    var = spectrum.std[a] ** 2 + (spectrum.std[b] ** 2 if b != "ground" else 0.0)
    d = (spectrum.responses[a] - other) / w2
    return float(np.sqrt(np.sum(np.abs(d) ** 2) / max(np.sum(2 * var / w2 ** 2), 1e-300)))


def case(structure: str, law: str | None, seed: int) -> dict:
    test = sim.make_test(seed, structure, law)
    recs = sim.simulate(test)
    row = {key: value for key, value in test.describe().items() if key in ("structure", "seed", "law", "sensors",
                                                                          "between", "drive", "noise")}
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = []
        for lv in FITTED:
            sim.write_csv(recs[lv - 1], Path(tmp) / f"L{lv}.csv")
            loaded.append(load_recording(Path(tmp) / f"L{lv}.csv"))
        t0 = time.perf_counter()
        loc = locate_joint(loaded)
        row["locate_s"] = round(time.perf_counter() - t0, 1)
        top = periodic_spectra(loaded[-1])
    row.update(found_between=list(loc.between), found_law=loc.law, detected=bool(loc.detected),
               evidence=round(float(loc.evidence), 1))
    if law is not None:
        truth = sorted(test.between)
        rank = next((i for i, e in enumerate(loc.location) if sorted(e["between"]) == truth), None)
        row.update(true_rank=rank, true_delta_bic=None if rank is None else loc.location[rank]["delta_bic"],
                   placed=sorted(loc.between) == truth and loc.detected, named=loc.law == law and loc.detected,
                   stroke_to_noise=round(stroke_to_noise(top, *test.between), 1))
    return row


def summarise(rows: list) -> dict:
    joints = [r for r in rows if r["law"] is not None]
    nulls = [r for r in rows if r["law"] is None]
    placed = [r for r in joints if r["placed"]]
    missed = [r for r in joints if not r["placed"]]
    return {"joints": len(joints), "placed": len(placed), "named": sum(r["named"] for r in joints),
            "nulls": len(nulls), "nulls_detected": sum(r["detected"] for r in nulls),
            "median_stroke_to_noise": {
                "placed": round(float(np.median([r["stroke_to_noise"] for r in placed])), 1) if placed else None,
                "missed": round(float(np.median([r["stroke_to_noise"] for r in missed])), 1) if missed else None},
            "missed": [[r["structure"], r["law"], r["seed"]] for r in missed],
            "median_locate_s": float(np.median([r["locate_s"] for r in rows])) if rows else None}


def line(result: dict) -> str:
    s = result["summary"]
    return (f"structures_gvt_locate: placed {s['placed']}/{s['joints']}, law (spectra) {s['named']}/{s['joints']}, "
            f"nulls detected {s['nulls_detected']}/{s['nulls']} (the fit in time decides them), median stroke/noise "
            f"{s['median_stroke_to_noise']['placed']} placed, {s['median_stroke_to_noise']['missed']} missed; "
            f"locate median {s['median_locate_s']} s")


def readme_markdown(result: dict) -> str:
    """The summary and the tests placed wrong (benchmarks/readme_tables.py renders the region from it)."""
    s = result["summary"]
    out = [line(result) + ".", "",
           "| test | joint | found | true place's rank, ΔBIC | true pair's stroke/noise |", "|---|---|---|---|---|"]
    for r in result["rows"]:
        if r["law"] is not None and not r["placed"]:
            out.append(f"| {r['structure']} {r['law']} {r['seed']} | {' – '.join(r['between'])} "
                       f"| {' – '.join(r['found_between'])} ({r['found_law']}) | {r['true_rank']}, "
                       f"{r['true_delta_bic']:.0f} | {r['stroke_to_noise']} |")
    placed = [r["stroke_to_noise"] for r in result["rows"] if r["law"] is not None and r["placed"]]
    out += ["", f"(Placed right: stroke/noise {min(placed):.0f}–{max(placed):.0f}, median "
                f"{s['median_stroke_to_noise']['placed']:.0f}.)" if placed else ""]
    return "\n".join(out)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=40)
    ap.add_argument("--seed0", type=int, default=0)
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--merge", nargs="+", default=None)
    args = ap.parse_args(argv)
    if args.merge:
        print(line(merge(args.merge, args.out, summarise)))
        return 0
    result = run_plan(case, summarise, args.count, args.seed0, args.out, {},
                      lambda r: f"{r['found_between']} {r['found_law']} (true rank {r.get('true_rank')}, {r['locate_s']} s)")
    print(line(result) + " | " + describe(result["machine"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Discovery benchmark: shared acceptance files, false positives, hit rates, time.

In one run:
1. `satmd discover FILE --json` on every file of ../shared/acceptance/discovery/
   (as a user would run it), scored with ../shared/tools/score_discovery.py;
   time per case.
2. False-positive rate over N simulated null datasets (std given) and over
   N/2 without std (noise estimated).
3. Hit rate over N simulated concealed single-effect cases (std given):
   a seed picks the rig, the effect and its magnitude; magnitudes are scaled
   until the refitted nominal model is statistically wrong yet within 4x the
   noise to the eye. Cases whose effect the free parameters absorb entirely
   (the nominal model passes the χ² test even at 64x magnitude) are counted
   as undetectable and reported apart.
4. Two-effect cases and strong effects without std (noise estimated).
Every simulated case also records whether it was called `model_adequate` false
(``called_inadequate``: an in-model rig, so it must stay 0 on the nulls; a concealed effect that the
free parameters absorb only at absurd values, e.g. a shunt capacitance fitted as R ~ 1 kΩ, L ~ 5 H,
is called not adequate for those values, as `identify` calls that fit). Data
the model cannot describe (issue 24) have their own benchmark,
`benchmarks/out_of_model.py` (results/out_of_model.json), run through the CLI.

Writes benchmarks/results/discovery.json and prints one line of figures.
Usage: python benchmarks/discovery.py [--n 100] [--workers 2] [--parts acceptance,null,single,two]
(a subset of parts updates those entries of an existing discovery.json).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import provenance  # noqa: E402

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
from satmd.io.shared import shared_dir  # noqa: E402
SHARED = shared_dir() or ROOT.parent / "shared"
ACCEPTANCE = SHARED / "acceptance" / "discovery"
SCORER = SHARED / "tools" / "score_discovery.py"


def acceptance():
    if not ACCEPTANCE.is_dir():
        return {"skipped": f"{ACCEPTANCE} not found"}
    satmd = [sys.executable, "-m", "satmd.cli"]
    cases = {}
    with tempfile.TemporaryDirectory() as tmp:
        for csv in sorted(ACCEPTANCE.glob("*.csv")):
            t0 = time.perf_counter()
            out = subprocess.run(satmd + ["discover", str(csv), "--json"], capture_output=True, text=True)
            dt = time.perf_counter() - t0
            (Path(tmp) / csv.name.replace(".csv", ".json")).write_text(out.stdout)
            try:
                adequate = json.loads(out.stdout).get("model_adequate")
            except ValueError:
                adequate = None
            cases[csv.name] = {"time_s": dt, "exit": out.returncode, "model_adequate": adequate}
        score = subprocess.run([sys.executable, str(SCORER), str(ACCEPTANCE / "truth.json"), tmp],
                               capture_output=True, text=True).stdout
    for line in score.splitlines():
        parts = line.split()
        if parts and parts[0] in cases:
            cases[parts[0]]["result"] = " ".join(parts[1:])
    last = score.strip().splitlines()[-1] if score.strip() else "discovery score: ?"
    ok, n = last.split(":")[1].strip().split("/")
    times = [c["time_s"] for c in cases.values()]
    return {"score": int(ok), "n": int(n), "cases": cases, "median_time_s": float(np.median(times)),
            "called_inadequate": sum(c["model_adequate"] is not True for c in cases.values()),
            "note": "wall time per `satmd discover --json` process, Python start-up included"}


def _one(job):
    from satmd.discovery import discover
    from satmd.discovery.scenarios import concealed_case, judge

    seed, n_effects, std_given = job
    sc = concealed_case(seed, n_effects=n_effects, std_given=std_given)
    t0 = time.perf_counter()
    rep = discover(sc.data)
    dt = time.perf_counter() - t0
    return {"seed": seed, "truth": sc.truth_names, "found": rep.effect_names,
            "equivalent": [e.equivalent for e in rep.effects], "detectable": sc.detectable,
            "correct": bool(judge(rep, sc)), "flagged": bool(rep.significant_mismatch), "time_s": dt,
            "adequate": bool(rep.model_adequate),
            "chi2_before": rep.fit_before["chi2_reduced"], "chi2_after": rep.fit_after["chi2_reduced"]}


def simulated(pool, n_cases, n_effects, std_given, base_seed):
    jobs = [(base_seed + i, n_effects, std_given) for i in range(n_cases)]
    rows = list(pool.map(_one, jobs))
    det = [r for r in rows if r["detectable"]]
    out = {"n": len(rows), "median_time_s": float(np.median([r["time_s"] for r in rows])),
           "std_given": std_given, "effects_per_case": n_effects,
           "called_inadequate": sum(not r["adequate"] for r in rows),  # nulls: must stay 0 (see the docstring)
           "called_inadequate_cases": [r for r in rows if not r["adequate"]]}
    if n_effects == 0:
        out["false_positives"] = sum(r["flagged"] for r in rows)
        out["false_positive_rate"] = out["false_positives"] / len(rows)
    else:
        out["detectable"] = len(det)
        out["correct_of_detectable"] = sum(r["correct"] for r in det)
        out["hit_rate"] = out["correct_of_detectable"] / max(len(det), 1)
        out["correct_of_all"] = sum(r["correct"] for r in rows)
        out["misses"] = [r for r in det if not r["correct"]]
        out["undetectable_truths"] = sorted({t for r in rows if not r["detectable"] for t in r["truth"]})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100, help="simulated cases per population (default 100)")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--parts", default="acceptance,null,single,two",
                    help="comma-separated parts to run (others are kept from an existing discovery.json)")
    args = ap.parse_args()
    parts = set(args.parts.split(","))
    t0 = time.perf_counter()
    out = ROOT / "benchmarks" / "results" / "discovery.json"
    result = json.loads(out.read_text()) if parts != {"acceptance", "null", "single", "two"} and \
        out.is_file() else {}
    result.pop("out_of_model", None)  # now benchmarks/out_of_model.py (results/out_of_model.json)
    result.update({"benchmark": "discovery", "machine": {**provenance(), "cpus": os.cpu_count(),
                                                          "python": platform.python_version()}})
    if "acceptance" in parts:
        result["acceptance"] = acceptance()
    with ProcessPoolExecutor(args.workers) as pool:
        if "null" in parts:
            result["null_std_given"] = simulated(pool, args.n, 0, True, 10_000)
            result["null_noise_estimated"] = simulated(pool, args.n // 2, 0, False, 20_000)
        if "single" in parts:
            result["single_effect"] = simulated(pool, args.n, 1, True, 30_000)
            result["single_effect_noise_estimated"] = simulated(pool, args.n // 2, 1, False, 40_000)
        if "two" in parts:
            result["two_effects"] = simulated(pool, args.n // 4, 2, True, 50_000)
    result["wall_time_s"] = time.perf_counter() - t0
    targets = {
        "acceptance_all": result["acceptance"].get("score") == result["acceptance"].get("n"),
        "acceptance_never_called_inadequate": result["acceptance"].get("called_inadequate") == 0,
        "false_positives_le_1pct": result["null_std_given"]["false_positive_rate"] <= 0.01,
        "hit_rate_ge_95pct": result["single_effect"]["hit_rate"] >= 0.95,
        "median_time_le_3s": result["single_effect"]["median_time_s"] <= 3.0,
        "estimated_noise_null_le_1pct": result["null_noise_estimated"]["false_positive_rate"] <= 0.01,
        "nulls_never_called_inadequate": result["null_std_given"]["called_inadequate"] == 0 and
        result["null_noise_estimated"]["called_inadequate"] == 0,
    }
    result["targets"] = targets
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2, default=float))
    a, s, se, two = result["acceptance"], result["single_effect"], result["single_effect_noise_estimated"], \
        result["two_effects"]
    print(f"discovery: acceptance {a.get('score')}/{a.get('n')} (median {a.get('median_time_s', float('nan')):.1f} s "
          f"per CLI run) | false positives {result['null_std_given']['false_positives']}/{args.n} std given, "
          f"{result['null_noise_estimated']['false_positives']}/{args.n // 2} estimated | "
          f"concealed {s['correct_of_detectable']}/{s['detectable']} detectable "
          f"({s['n'] - s['detectable']} absorbed by free R, L, kp) median {s['median_time_s']:.2f} s | "
          f"noise estimated {se['correct_of_detectable']}/{se['detectable']} | "
          f"two effects {two['correct_of_detectable']}/{two['detectable']} | "
          f"called inadequate: {result['null_std_given']['called_inadequate']} nulls std given, "
          f"{result['null_noise_estimated']['called_inadequate']} estimated, {s['called_inadequate']} single")


if __name__ == "__main__":
    main()

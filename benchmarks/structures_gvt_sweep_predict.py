"""Another excitation of the same structures (issue 47): models fitted on multisines, judged on sine sweeps.

The issue asks a structure's model, fitted on four multisine levels, to predict other excitations of the same
structure too (on the F-16, NRMSE <= 0.35 on every channel). A ground vibration test's classic is the sine sweep:
it dwells on each resonance in turn, so the joint meets strokes a multisine of the same RMS spreads over the band.
Each test here is one of `structures_gvt`'s (the independent simulator `benchmarks/_indep_gvt.py`, numpy/scipy
only), run as a user would:

    satmd discover L1.csv L3.csv L5.csv L7.csv --json --save-model model.json     (multisines)
    satmd predict model.json S1.csv ... S7.csv --json                              (sweeps, every level)

each sweep one linear sweep down the band (40 -> 5 Hz in 40 s) with 40 s of quiet after it, its RMS over the sweep
the multisine's at that level. Scored per test at its worst sweep level and channel: within 3x the noise floor, at
most 0.35 (the issue's bound for the F-16's other excitations), below the level-1 linear model's; and the same
over the sweep levels whose joint force `satmd predict` finds within the fitted recordings' (a sweep dwells on
each resonance, so its top levels drive the joint beyond them: `joint_force_over_fitted` > 1, an extrapolation).

    python benchmarks/structures_gvt_sweep_predict.py [--seeds 1,2,5] [--out PATH] [--models DIR]

``--models DIR`` keeps each test's saved model (``DIR/model_SEED.json``) and its sweep files (``S{level}_SEED.csv``);
``--predict-only DIR`` predicts those again and scores them, without a fit (after a change to how a model is driven).

Writes benchmarks/results/structures_gvt_sweep_predict.json and prints one line of figures.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
import _indep_gvt as sim  # noqa: E402
from _machine import describe, load_after, machine  # noqa: E402
from structures_gvt import FITTED, _finite, _satmd, discovered, plan  # noqa: E402

OUT = ROOT / "benchmarks" / "results" / "structures_gvt_sweep_predict.json"
SWEPT = tuple(range(1, 8))
BOUND = 0.35  # the issue's NRMSE bound on the F-16's other excitations
SEEDS = (1, 2, 5, 7, 8, 11, 12, 15, 17, 22)  # every law and structure, each predicted within 3x noise on multisines; a null


def case(structure: str, law: str | None, seed: int, keep: Path | None = None) -> dict:
    test = sim.make_test(seed, structure, law)
    row = {k: v for k, v in test.describe().items() if k in ("structure", "seed", "law", "between", "noise")}
    multisines, sweeps = sim.simulate(test), sim.simulate(test, excitation="sweep")
    with tempfile.TemporaryDirectory() as tmp:
        for lv in SWEPT:
            sim.write_csv(sweeps[lv - 1], Path(tmp) / f"S{lv}_{seed}.csv")
        found, row["discover_s"] = discovered(multisines, Path(tmp), f"model_{seed}.json")
        if "error" in found:
            row["error"] = found["error"]
            return row
        if keep is not None:
            keep.mkdir(parents=True, exist_ok=True)
            for name in (f"model_{seed}.json", *(f"S{lv}_{seed}.csv" for lv in SWEPT)):
                (keep / name).write_bytes((Path(tmp) / name).read_bytes())
        return judged(row, Path(tmp))


def judged(row: dict, folder: Path) -> dict:
    """``row`` with the sweeps in ``folder`` (``S{level}_{seed}.csv``) predicted by its model (``model_{seed}.json``)
    through `satmd predict`, scored; the joint found is the model's."""
    from satmd.structure import StructureModel

    seed = row["seed"]
    joint = StructureModel.load(folder / f"model_{seed}.json").joint
    row["found_between"], row["found_law"] = (list(joint.between), joint.law) if joint else (None, None)
    pred = _satmd("predict", f"model_{seed}.json", *(f"S{lv}_{seed}.csv" for lv in SWEPT), "--json", cwd=folder)
    if "error" in pred:
        row["error"] = pred["error"]
        return row
    row["swept"] = [{"level": lv, "nrmse": r["nrmse"], "linear_nrmse": r["linear_nrmse"],
                     "extrapolated": r["extrapolated"], "joint_force_over_fitted": r.get("joint_force_over_fitted")}
                    for lv, r in zip(SWEPT, pred["recordings"])]
    return _score(row)


def _score(row: dict) -> dict:
    worst = [max(_finite(s["nrmse"])) for s in row["swept"]]
    linear = [max(_finite(s["linear_nrmse"])) for s in row["swept"]]
    row["worst_nrmse"], row["worst_linear_nrmse"] = round(max(worst), 4), round(max(linear), 4)
    row["beyond_fitted"] = [s["level"] for s in row["swept"] if (s.get("joint_force_over_fitted") or 0) > 1]
    inside = [w for w, s in zip(worst, row["swept"]) if s["level"] not in row["beyond_fitted"]]
    row["worst_nrmse_within_reach"] = round(max(inside), 4) if inside else None
    floor = 3 * row["noise"]["acc"]
    row["right"] = {"within_3x_noise": max(worst) <= floor, "within_bound": max(worst) <= BOUND,
                    "better_than_linear": all(w < lin for w, lin in zip(worst, linear) if lin > floor),
                    "within_3x_noise_within_reach": bool(inside) and max(inside) <= floor}
    return row


def summarise(rows) -> dict:
    done = [r for r in rows if "right" in r]
    count = {k: {"n": len(done), "right": sum(r["right"][k] for r in done)}
             for k in ("within_3x_noise", "within_bound", "better_than_linear", "within_3x_noise_within_reach")}
    return {"tests": len(rows), "errors": len(rows) - len(done), **count,
            "median_worst_over_noise": round(float(np.median([r["worst_nrmse"] / r["noise"]["acc"] for r in done])), 1)
            if done else None,
            "with_a_level_beyond_fitted": sum(bool(r["beyond_fitted"]) for r in done)}


def line(result) -> str:
    s = result["summary"]

    def f(k):
        return f"{s[k]['right']}/{s[k]['n']}"
    return (f"structures_gvt_sweep_predict: {s['tests']} tests, sweeps at 7 levels from multisine-fitted models: "
            f"within 3x noise {f('within_3x_noise')}, worst NRMSE <= {BOUND} {f('within_bound')}, better than the "
            f"level-1 linear model {f('better_than_linear')}, median worst/noise {s['median_worst_over_noise']}; "
            f"a level beyond the fitted joint force on {s['with_a_level_beyond_fitted']}, within 3x noise over the "
            f"levels within it {f('within_3x_noise_within_reach')}; errors {s['errors']} | "
            f"{describe(result['machine'])}")


def readme_markdown(result: dict) -> str:
    """The summary and every test's worst sweep level (benchmarks/readme_tables.py renders the region from it)."""
    out = [line(result) + ".", "",
           "| test | found | worst NRMSE over the sweeps (noise) | linear model's | worst level | beyond the fitted joint "
           "force | worst within it |", "|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        if "right" not in r:
            out.append(f"| {r['structure']} {r['law']} {r['seed']} | error: {r.get('error')} | | | | | |")
            continue
        worst = max(r["swept"], key=lambda s: max(_finite(s["nrmse"])))
        found = f"{' – '.join(r['found_between'])} ({r['found_law']})" if r["found_between"] else "no joint"
        beyond = ", ".join(f"level {lv}" for lv in r["beyond_fitted"]) or "none"
        out.append(f"| {r['structure']} {r['law'] or 'null'} {r['seed']} | {found} | {r['worst_nrmse']:.3f} "
                   f"({r['noise']['acc']:.3f}) | {r['worst_linear_nrmse']:.3f} | {worst['level']} | {beyond} "
                   f"| {'–' if r['worst_nrmse_within_reach'] is None else format(r['worst_nrmse_within_reach'], '.3f')} |")
    return "\n".join(out)


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default=",".join(map(str, SEEDS)), help="comma-separated test seeds of structures_gvt")
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--models", type=Path, default=None, help="keep each test's model and sweep files here")
    ap.add_argument("--predict-only", type=Path, default=None, metavar="DIR",
                    help="no fit: the models and sweeps kept in DIR by --models, predicted again and scored")
    args = ap.parse_args(argv)
    info = machine()
    t0 = time.perf_counter()
    rows = []
    tests = plan(0, 0, [int(s) for s in args.seeds.split(",")])
    for i, (structure, law, seed) in enumerate(tests, 1):
        if args.predict_only:
            test = sim.make_test(seed, structure, law)
            rows.append(judged({k: v for k, v in test.describe().items()
                                if k in ("structure", "seed", "law", "between", "noise")}, args.predict_only))
        else:
            rows.append(case(structure, law, seed, args.models))
        r = rows[-1]
        print(f"[{i}/{len(tests)}] {structure} {law} seed {seed}: {r.get('error') or r['right']} "
              f"worst {r.get('worst_nrmse')} (noise {r['noise']['acc']:.4f}; linear {r.get('worst_linear_nrmse')}) "
              f"({r.get('discover_s')} s)", file=sys.stderr, flush=True)
    result = {"machine": info, "fitted_levels": list(FITTED), "swept_levels": list(SWEPT), "rows": rows,
              "summary": summarise(rows), "benchmark_seconds": round(time.perf_counter() - t0, 1)}
    if args.predict_only:
        result["predicted_again_from"] = str(args.predict_only)
    result["machine"].update(load_after())
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1))
    print(line(result))
    return result


if __name__ == "__main__":
    main()

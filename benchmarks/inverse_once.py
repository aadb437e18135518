"""Issue 29, train the inverse once: the method before (hold-out + refit) against the new default (cross-fit).

Run as ``python benchmarks/inverse_once.py [--seeds 0,1,2,3,4] [--thread-counts 1,2]
[--coverage-noise 0.01] [--methods old,new] [--only coverage|threads]`` (or through
``python benchmarks/inverse.py --once``, the same options; its docstring lists the
jobs; ``--summary`` only recomputes the summary); this module holds the work and ``readme_markdown``, which
``benchmarks/readme_tables.py`` renders into the README's ``inverse_once``
region from benchmarks/results/inverse_once.json.
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
OUT = RESULTS / "inverse_once.json"
sys.path.insert(0, str(Path(__file__).resolve().parent))

#: The two methods, as InverseModel settings (everything else at its default).
METHODS = {"old": {"calibration": "holdout", "jacobian": "fd"}, "new": {}}
TARGET_S = 30.0  # issue 29: paper preset, physics, default settings, wall seconds on the 2-core machine


def fit_and_score(method: str, seed: int, threads: int, noise: float, blind, run: str = "") -> dict:
    """One default paper-preset physics fit by ``method``: wall and CPU seconds, Table 2 and blind-set scores."""
    import os

    import torch

    from satmd.inverse import InverseModel, evaluate

    torch.set_num_threads(threads)
    model = InverseModel("physics", "paper", noise, seed=seed, threads=threads, verbose=False, **METHODS[method])
    load = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), time.process_time()
    model.fit()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    t2 = evaluate(model)
    b = evaluate(model, blind, noise, 0)
    info = model.fit_info_
    return {"method": method, "seed": seed, "threads": threads, "noise": noise, "wall_s": wall, "cpu_s": cpu,
            "load_1min_before": load, "load_1min_after": os.getloadavg()[0],
            "table2_mae_R": t2["mae_R"], "table2_mae_L": t2["mae_L"], "blind_mae_R": b["mae_R"],
            "blind_mae_L": b["mae_L"], "coverage": b["coverage"], "coverage_R": b["coverage_R"],
            "coverage_L": b["coverage_L"], "n_blind": b["n"], "std_scale": list(map(float, model.std_scale_)),
            "calibration": info.get("calibration"), "val_coverage_2sd": info.get("val_coverage_2sd"),
            "settings": METHODS[method], "date": time.strftime("%Y-%m-%d %H:%M:%S"), "run": run}


def member_batching(steps: int = 60) -> dict:
    """CPU ms of one supervised training step (forward, backward) of 5 members x 64 samples, three ways."""
    import copy

    import torch
    from torch.func import functional_call, stack_module_state, vmap

    from satmd.inverse.nets import EnsembleNet, InverseNet

    torch.set_num_threads(1)
    gen = torch.Generator().manual_seed(0)
    x, y = torch.randn(5, 64, 240, generator=gen), torch.rand(5, 64, 2, generator=gen)
    stacked = EnsembleNet(5, generator=gen)
    nets = [InverseNet() for _ in range(5)]
    params, buffers = stack_module_state(nets)
    params = {k: v.detach().requires_grad_() for k, v in params.items()}
    base = copy.deepcopy(nets[0]).to("meta")
    vmapped = vmap(lambda p, b, xi: functional_call(base, (p, b), (xi,)))

    def bmm():
        stacked.zero_grad(set_to_none=True)
        ((stacked(x) - y) ** 2).mean().backward()

    def vm():
        for v in params.values():
            v.grad = None
        ((vmapped(params, buffers, x) - y) ** 2).mean().backward()

    def loop():
        for n in nets:
            n.zero_grad(set_to_none=True)
        sum(((n(x[k]) - y[k]) ** 2).mean() for k, n in enumerate(nets)).backward()

    out = {}
    for name, fn in (("baddbmm", bmm), ("vmap", vm), ("loop", loop)):
        for _ in range(5):
            fn()
        c0 = time.process_time()
        for _ in range(steps):
            fn()
        out[name] = 1e3 * (time.process_time() - c0) / steps
    return out


def _key(r):
    return (r["method"], r["seed"], r["threads"], r["noise"])


def summarise(records: list) -> dict:
    """Per-seed and mean MAE (noise 0, 1 thread), timings per thread count, coverage, against the targets."""
    by = {_key(r): r for r in records}
    seeds = sorted({r["seed"] for r in records if r["threads"] == 1 and r["noise"] == 0
                    and ("old", r["seed"], 1, 0.0) in by and ("new", r["seed"], 1, 0.0) in by})
    out = {"seeds": seeds, "per_seed": [], "timing": [], "coverage": []}
    for s in seeds:
        o, n = by[("old", s, 1, 0.0)], by[("new", s, 1, 0.0)]
        out["per_seed"].append({"seed": s, "same_run": o.get("run") == n.get("run"),
                                **{f"{m}_{k}": r[k] for m, r in (("old", o), ("new", n))
                                   for k in ("table2_mae_R", "table2_mae_L", "blind_mae_R", "blind_mae_L", "wall_s",
                                             "cpu_s")}})
    for k in ("table2_mae_R", "table2_mae_L", "blind_mae_R", "blind_mae_L"):
        for m in ("old", "new"):
            out[f"{m}_mean_{k}"] = float(np.mean([by[(m, s, 1, 0.0)][k] for s in seeds])) if seeds else None
    for (m, s, t, z), r in sorted(by.items()):
        if m == "new" and z == 0 and ("old", s, t, z) in by and by[("old", s, t, z)].get("run") == r.get("run"):
            o = by[("old", s, t, z)]
            out["timing"].append({"seed": s, "threads": t, "old_wall_s": o["wall_s"], "new_wall_s": r["wall_s"],
                                  "old_cpu_s": o["cpu_s"], "new_cpu_s": r["cpu_s"],
                                  "ratio_wall": r["wall_s"] / o["wall_s"], "ratio_cpu": r["cpu_s"] / o["cpu_s"],
                                  "load_1min": [o["load_1min_before"], r["load_1min_after"]]})
        if m == "new" and z > 0 and ("old", s, t, z) in by:
            o = by[("old", s, t, z)]
            out["coverage"].append({"seed": s, "noise": z, "old": o["coverage"], "new": r["coverage"],
                                    "old_R_L": [o["coverage_R"], o["coverage_L"]],
                                    "new_R_L": [r["coverage_R"], r["coverage_L"]],
                                    "old_blind_mae": [o["blind_mae_R"], o["blind_mae_L"]],
                                    "new_blind_mae": [r["blind_mae_R"], r["blind_mae_L"]], "n": r["n_blind"]})
    walls = {t["threads"]: t["new_wall_s"] for t in out["timing"]}
    out["meets"] = {
        "wall_le_30s": {str(t): w <= TARGET_S for t, w in walls.items()},
        "mae_R_no_worse": seeds and out["new_mean_table2_mae_R"] <= out["old_mean_table2_mae_R"],
        "mae_L_no_worse": seeds and out["new_mean_table2_mae_L"] <= out["old_mean_table2_mae_L"],
        "coverage_090_098": [0.90 <= c["new"] <= 0.98 for c in out["coverage"]],
    }
    return out


def headline(summary: dict) -> str:
    """The line of figures."""
    parts = []
    for n in sorted({t["threads"] for t in summary["timing"]}):
        ts = [t for t in summary["timing"] if t["threads"] == n]
        mean = {k: float(np.mean([t[k] for t in ts])) for k in ("old_wall_s", "new_wall_s", "old_cpu_s", "new_cpu_s")}
        parts.append(f"{n} thread(s) ({len(ts)} pair(s)): old {mean['old_wall_s']:.1f} s, new {mean['new_wall_s']:.1f} s "
                     f"wall (x{mean['new_wall_s'] / mean['old_wall_s']:.2f}; CPU {mean['old_cpu_s']:.1f} -> "
                     f"{mean['new_cpu_s']:.1f} s)")
    if summary["seeds"]:
        parts.append(f"Table 2 MAE over seeds {','.join(map(str, summary['seeds']))}: R old "
                     f"{summary['old_mean_table2_mae_R']:.4f} new {summary['new_mean_table2_mae_R']:.4f} Ω, L old "
                     f"{summary['old_mean_table2_mae_L']:.3g} new {summary['new_mean_table2_mae_L']:.3g} H")
    for c in summary["coverage"]:
        parts.append(f"2σ coverage at {100 * c['noise']:g} % on {c['n']} FRFs: old {c['old']:.3f}, new {c['new']:.3f}")
    return "inverse once: " + "; ".join(parts)


def run_once(seeds, thread_counts, coverage_noise, methods=("old", "new"), only=None) -> dict:
    """The jobs of ``--once``, each old then new back to back; records merged into inverse_once.json."""
    from _machine import describe, load_after, machine

    from satmd.inverse import BLIND_PAIRS, pairs_dataset

    blind = pairs_dataset(BLIND_PAIRS, per_pair=40, seed=1000)
    run = time.strftime("%Y-%m-%dT%H:%M:%S")  # timings are compared only within one run
    jobs = [(s, 1, 0.0) for s in seeds]
    jobs += [(seeds[0], t, 0.0) for t in thread_counts if t != 1]
    if coverage_noise:
        jobs.append((seeds[0], 1, float(coverage_noise)))
    if only == "coverage":
        jobs = [j for j in jobs if j[2] > 0]
    elif only == "threads":
        jobs = [j for j in jobs if j[1] != 1]
    res = json.loads(OUT.read_text(encoding="utf-8")) if OUT.is_file() else {"records": []}
    res["machine"] = machine("cpu", 1)
    records = {_key(r): r for r in res["records"]}
    mine = {}  # the records this run made: they replace the file's, the file's others are kept
    for seed, threads, noise in jobs:
        for method in methods:
            r = fit_and_score(method, seed, threads, noise, blind, run)
            mine[_key(r)] = r
            if OUT.is_file():  # another run may have added records meanwhile: keep them
                records = {_key(q): q for q in json.loads(OUT.read_text(encoding="utf-8"))["records"]}
            records.update(mine)
            print(f"[once] {method} seed {seed} threads {threads} noise {noise:g}: {r['wall_s']:.1f} s wall, "
                  f"{r['cpu_s']:.1f} s CPU, Table 2 MAE R {r['table2_mae_R']:.4f} L {r['table2_mae_L']:.3g}, "
                  f"coverage {r['coverage']:.3f}", file=sys.stderr, flush=True)
            res["records"] = sorted(records.values(), key=lambda q: (q["noise"], q["threads"], q["seed"], q["method"]))
            OUT.write_text(json.dumps(res, indent=1), encoding="utf-8")  # after every fit: a killed run keeps its work
    res["member_batching_ms"] = member_batching()
    res["records"] = json.loads(OUT.read_text(encoding="utf-8"))["records"]
    res["summary"] = summarise(res["records"])
    res["machine"].update(load_after())
    OUT.write_text(json.dumps(res, indent=1), encoding="utf-8")
    print(headline(res["summary"]) + " " + describe(res["machine"]))
    return res


def readme_markdown(res: dict) -> str:
    """The README region: old vs new, per seed and mean, timings and coverage."""
    s = res["summary"]
    lines = ["| seed | old Table 2 MAE R [Ω] | new | old MAE L [H] | new | old train CPU [s] | new |",
             "|---|---|---|---|---|---|---|"]
    for p in s["per_seed"]:
        lines.append(f"| {p['seed']} | {p['old_table2_mae_R']:.4f} | {p['new_table2_mae_R']:.4f} | "
                     f"{p['old_table2_mae_L']:.3g} | {p['new_table2_mae_L']:.3g} | {p['old_cpu_s']:.0f} | "
                     f"{p['new_cpu_s']:.0f} |")
    if s["seeds"]:
        lines.append(f"| **mean** | {s['old_mean_table2_mae_R']:.4f} | {s['new_mean_table2_mae_R']:.4f} | "
                     f"{s['old_mean_table2_mae_L']:.3g} | {s['new_mean_table2_mae_L']:.3g} | | |")
    lines.append("")
    for t in s["timing"]:
        lines.append(f"- {t['threads']} torch thread(s), seed {t['seed']}: old {t['old_wall_s']:.1f} s, new "
                     f"{t['new_wall_s']:.1f} s wall (×{t['ratio_wall']:.2f}); CPU {t['old_cpu_s']:.1f} s → "
                     f"{t['new_cpu_s']:.1f} s (×{t['ratio_cpu']:.2f}); load average {t['load_1min'][0]:.1f} on "
                     f"{res['machine']['cpu_count']} cores.")
    for c in s["coverage"]:
        lines.append(f"- 2σ coverage at {100 * c['noise']:g} % noise on the {c['n']} blind FRFs: old {c['old']:.3f}, "
                     f"new {c['new']:.3f}.")
    b = res.get("member_batching_ms")
    if b:
        lines.append(f"- One training step of the 5 members (CPU ms): stacked weights with `baddbmm` "
                     f"{b['baddbmm']:.2f}, `torch.func.vmap` {b['vmap']:.2f}, a loop over members {b['loop']:.2f}.")
    return "\n".join(lines)


def main(argv=None):
    """Command line (``--help``); ``python benchmarks/inverse.py --once ...`` takes the same options."""
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_arguments(ap)
    ap.add_argument("--summary", action="store_true", help="only recompute the summary of inverse_once.json")
    args = ap.parse_args(argv)
    if args.summary:
        r = json.loads(OUT.read_text(encoding="utf-8"))
        r["summary"] = summarise(r["records"])
        OUT.write_text(json.dumps(r, indent=1), encoding="utf-8")
        print(headline(r["summary"]))
        return r
    return run_args(args)


def add_arguments(ap) -> None:
    """The options of the comparison (shared with ``benchmarks/inverse.py --once``)."""
    ap.add_argument("--seeds", default="0,1,2,3,4", help="seeds of the MAE comparison (1 torch thread, noise 0)")
    ap.add_argument("--thread-counts", default="1,2", help="torch threads timed on the first seed (old and new "
                    "back to back, wall and CPU seconds)")
    ap.add_argument("--coverage-noise", type=float, default=0.01, help="noise of the coverage check (0: none)")
    ap.add_argument("--methods", default="old,new", help="methods to run (records of the others are kept)")
    ap.add_argument("--only", choices=("coverage", "threads"), help="only the coverage or the thread-count jobs")


def run_args(args) -> dict:
    """`run_once` with parsed `add_arguments` options."""
    return run_once([int(x) for x in args.seeds.split(",") if x],
                    [int(x) for x in args.thread_counts.split(",") if x], args.coverage_noise,
                    tuple(args.methods.split(",")), args.only)


if __name__ == "__main__":
    main()

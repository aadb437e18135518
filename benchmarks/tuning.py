"""Tuning benchmark: exact optima, tuning from noisy FRFs, concealed effects, robust tuning, CLI time.

In one run:
1. Textbook checks: classic TMD (μ = 0.05, Nishihara & Asami), piezo RL shunt
   on an undamped host (equal-peak closed form vs the numerical minimax).
2. Rigs drawn in SPEC §9's ranges, noisy FRFs (1 % noise, std given):
   `discover` -> `tune`; the true peak at the returned R, L vs the true optimum.
3. Concealed host effects (k1 off by 5 %; an extra host mode in the band):
   true peak when tuned on the discovered (augmented) model vs on the nominal
   model, each against the true optimum.
4. Robust tuning from the fit covariance (10 % noise so the uncertainty
   matters): over 200 fresh parameter draws, the 95 % quantile of the true
   peak at the robust and at the nominal setting, and how often the reported
   guaranteed attenuation holds.
5. `satmd tune FILE --json` on a 60-point FRF (H∞ and H2): wall time of the
   whole process and of the command inside a running interpreter.
6. (not with --quick) A tuning law: R_opt, L_opt over a grid of (m2, kp),
   distilled with `satmd.explain.distill` (SINDy back end) in log variables.

Writes benchmarks/results/tuning.json and prints one line of figures.
Usage: python benchmarks/tuning.py [--quick] [--n 12] [--workers 2]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import provenance  # noqa: E402

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "tuning.json"
RANGES = {"m2": (0.3, 0.8), "kp": (5e4, 2e5), "R": (5.0, 100.0), "L": (0.02, 0.5)}  # SPEC §9
BAND = (20.0, 200.0)


def db(a, b):
    return 20 * math.log10(a / b)


def random_rig(seed):
    from satmd import Rig

    rng = np.random.default_rng(seed)
    return Rig(**{k: float(rng.uniform(lo, hi)) for k, (lo, hi) in RANGES.items()})


def true_peak(rig, effects, design):
    from satmd.tuning.objective import Objective

    return float(Objective("hinf", "u1", BAND)(rig.replace(**design), effects)[0])


# --- 1. textbook ---------------------------------------------------------------------------------
def textbook():
    from satmd.report.parts.tune import _textbook_rows

    return [{"check": a, "satmd": b, "exact": c} for a, b, c in _textbook_rows()]


# --- 2./3. noisy FRFs, with and without a concealed effect ------------------------------------------
def _case(job):
    from satmd import discover, effect, simulate, tune

    warnings.simplefilter("ignore")  # discovery's trial fits warn about poor fits by design

    seed, kind = job
    rig = random_rig(seed)
    effects = []
    if kind == "k1_offset":
        effects = [effect("parameter_offset:k1", value=1.05 * rig.k1)]
    elif kind == "extra_mode":
        rng = np.random.default_rng(seed + 1)
        effects = [effect("extra_mode", f_hz=float(rng.uniform(60, 120)), zeta=0.01,
                          mass_ratio=float(rng.uniform(0.02, 0.05)))]
    data = simulate(rig=rig, effects=effects, noise=0.01, seed=seed)
    t0 = time.perf_counter()
    rep = discover(data)
    refused = not rep.model_adequate  # tune refuses such a model; tuned anyway (force) and counted
    res = tune(rep, closed_form_check=False, force=refused)
    wall = time.perf_counter() - t0
    truth = tune(rig, effects=effects, closed_form_check=False)
    row = {"seed": seed, "kind": kind, "truth": {k: getattr(rig, k) for k in RANGES}, "found": rep.effect_names,
           "design": res.design, "true_optimum": truth.design, "gap_db": db(true_peak(rig, effects, res.design),
                                                                            truth.value),
           "time_s": wall, "called_inadequate": refused}
    if kind != "none":
        nominal = tune(rep.nominal_fit, closed_form_check=False, force=True)  # the comparison, adequate or not
        row["nominal_design"] = nominal.design
        row["nominal_gap_db"] = db(true_peak(rig, effects, nominal.design), truth.value)
    return row


def cases(pool, n, kind, base):
    rows = list(pool.map(_case, [(base + i, kind) for i in range(n)]))
    gaps = np.array([r["gap_db"] for r in rows])
    out = {"n": n, "max_gap_db": float(gaps.max()), "median_gap_db": float(np.median(gaps)),
           "within": int(np.sum(gaps <= (0.1 if kind == "none" else 0.2))),
           "called_inadequate": int(sum(r["called_inadequate"] for r in rows)), "rows": rows}
    if kind != "none":
        nom = np.array([r["nominal_gap_db"] for r in rows])
        out.update(nominal_max_gap_db=float(nom.max()), nominal_median_gap_db=float(np.median(nom)),
                   found_effect=int(sum(bool(r["found"]) for r in rows)))
    return out


# --- 4. robust ---------------------------------------------------------------------------------------
def robust(n_fresh=200, seed=11):
    from satmd import identify, simulate, tune
    from satmd.tuning.robust import draws_from_covariance
    from satmd.tuning.objective import Objective

    warnings.simplefilter("ignore")
    rig = random_rig(seed)
    fit = identify(simulate(rig=rig, noise=0.10, seed=seed))
    t0 = time.perf_counter()
    res = tune(fit, robust=True, closed_form_check=False)
    wall = time.perf_counter() - t0
    nominal = res.robust["nominal_optimum"]["design"]
    fresh = draws_from_covariance(fit.names, fit.theta, fit.covariance, exclude=("R", "L"), n=n_fresh, seed=seed + 99)
    obj = Objective("hinf", "u1", BAND)
    d_rig, d_eff = fresh.apply(fit.rig, fit.effects)
    at_robust = obj(d_rig.replace(**res.design), d_eff)
    at_nominal = obj(d_rig.replace(**nominal), d_eff)
    at_current = obj(d_rig.replace(**res.current_design), d_eff)
    att = 20 * np.log10(at_current / at_robust)
    guaranteed = res.robust["guaranteed_attenuation_db"]["vs_current"]
    return {"parameters": res.robust["parameters"], "std": {k: fit.std[k] for k in res.robust["parameters"]},
            "robust_design": res.design, "nominal_design": nominal,
            "q95_robust": float(np.quantile(at_robust, 0.95)), "q95_nominal": float(np.quantile(at_nominal, 0.95)),
            "q95_improvement_db": db(float(np.quantile(at_nominal, 0.95)), float(np.quantile(at_robust, 0.95))),
            "guaranteed_db": guaranteed, "coverage": float(np.mean(att >= guaranteed)), "n_fresh": n_fresh,
            "time_s": wall}


# --- 5. CLI time -------------------------------------------------------------------------------------
def cli_time(repeats=3):
    from satmd import save_frf, simulate
    from satmd.cli import main

    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "rig60.csv"
        save_frf(simulate(noise=0.01, seed=5), path)
        for objective in ("hinf", "h2"):
            argv = ["tune", str(path), "--json", "--objective", objective]
            proc, cpu, inproc = [], [], []
            for _ in range(repeats):
                before = resource.getrusage(resource.RUSAGE_CHILDREN)
                t0 = time.perf_counter()
                r = subprocess.run([sys.executable, "-m", "satmd", *argv], capture_output=True, text=True)
                proc.append(time.perf_counter() - t0)
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
                assert r.returncode == 0, r.stderr
                with open(os.devnull, "w") as sink:
                    stdout, sys.stdout = sys.stdout, sink
                    try:
                        t0 = time.perf_counter()
                        main(argv)
                        inproc.append(time.perf_counter() - t0)
                    finally:
                        sys.stdout = stdout
            out[objective] = {"process_s": float(np.median(proc)), "process_cpu_s": float(np.median(cpu)),
                              "in_process_s": float(np.median(inproc))}
    out["note"] = ("process_s: wall time of `python -m satmd tune FILE --json` (start-up, imports, discovery and "
                   "tuning); process_cpu_s: its CPU time, which other load on the machine does not inflate")
    return out


# --- 6. tuning law -----------------------------------------------------------------------------------
def tuning_law(n=6):
    from satmd import Rig, tune
    from satmd.explain.distillation import distill

    m2s, kps = np.linspace(0.3, 0.8, n), np.geomspace(5e4, 2e5, n)
    X, R, L = [], [], []
    for m2 in m2s:
        for kp in kps:
            res = tune(Rig(m2=m2, kp=kp), closed_form_check=False, n_starts=2)
            X.append((math.log(m2), math.log(kp)))
            R.append(math.log(res.design["R"]))
            L.append(math.log(res.design["L"]))
    X, R, L = np.array(X), np.array(R), np.array(L)
    out = {}
    for name, y in (("ln_R_opt", R), ("ln_L_opt", L)):
        d = distill(X, np.array(y), backend="sindy", names=("ln_m2", "ln_kp"), zscore=False, degree=2,
                    max_complexity=13, test_size=0.2)
        out[name] = {"expression": str(d.expression), "r2_test": d.r2_test, "mae_test": d.mae_test,
                     "variables": "x0 = ln m2 [kg], x1 = ln kp [N/m]"}
    f_e = 1 / (2 * np.pi * np.sqrt(np.exp(L) * 27e-6))  # optimal electrical resonance
    f_a = np.sqrt(np.exp(X[:, 1] - X[:, 0])) / (2 * np.pi)  # the absorber's own frequency √(kp/m2)/2π
    out["grid"] = {"m2": m2s.tolist(), "kp": kps.tolist(), "R_opt": np.exp(R).tolist(), "L_opt": np.exp(L).tolist()}
    out["electrical_resonance_hz"] = {"min": float(f_e.min()), "max": float(f_e.max())}
    out["absorber_frequency_hz"] = {"min": float(f_a.min()), "max": float(f_a.max())}
    out["classical"] = ("single-mode laws: L = 1/(Cp ω²) with ω² ∝ kp/m2 gives ln L = const + ln m2 − ln kp; "
                        "R = √(3/2) k_c/(Cp ω) gives ln R = const + ½ ln m2 − ½ ln kp + ln k_c")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer cases, no tuning law (about a minute)")
    ap.add_argument("--n", type=int, default=None, help="rigs per population (default 12, quick 4)")
    ap.add_argument("--workers", type=int, default=min(2, os.cpu_count() or 1))
    args = ap.parse_args()
    n = args.n or (4 if args.quick else 12)
    t0 = time.perf_counter()
    result = {"benchmark": "tuning", "quick": args.quick,
              "machine": {**provenance(), "cpus": os.cpu_count(), "python": platform.python_version()}}
    result["textbook"] = textbook()
    with ProcessPoolExecutor(args.workers) as pool:
        result["noisy"] = cases(pool, n, "none", 1000)
        result["k1_offset"] = cases(pool, max(2, n // 2), "k1_offset", 2000)
        result["extra_mode"] = cases(pool, max(2, n // 2), "extra_mode", 3000)
    result["robust"] = robust()
    result["cli"] = cli_time(2 if args.quick else 3)
    if not args.quick:
        result["tuning_law"] = tuning_law()
    result["wall_time_s"] = time.perf_counter() - t0
    nz, k1, em, rb, cli = (result[k] for k in ("noisy", "k1_offset", "extra_mode", "robust", "cli"))
    result["targets"] = {
        "noisy_within_0.1dB": nz["within"] == nz["n"],
        "concealed_within_0.2dB": k1["within"] == k1["n"] and em["within"] == em["n"],
        "robust_q95_no_worse": rb["q95_robust"] <= rb["q95_nominal"] * (1 + 1e-9),
        "robust_guarantee_holds_95pct": rb["coverage"] >= 0.95,
        "cli_cpu_le_2s": max(cli[k]["process_cpu_s"] for k in ("hinf", "h2")) <= 2.0,
        "cli_wall_le_2s": max(cli[k]["process_s"] for k in ("hinf", "h2")) <= 2.0,  # inflated by other load
    }
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(result, indent=2, default=float))
    print(f"tuning: noisy {nz['within']}/{nz['n']} within 0.1 dB (max {nz['max_gap_db']:.3f} dB) | "
          f"k1+5 % {k1['within']}/{k1['n']} within 0.2 dB (max {k1['max_gap_db']:.3f}; nominal model max "
          f"{k1['nominal_max_gap_db']:.2f} dB) | extra mode {em['within']}/{em['n']} (max {em['max_gap_db']:.3f}; "
          f"nominal max {em['nominal_max_gap_db']:.2f} dB) | robust q95 {rb['q95_improvement_db']:+.3f} dB vs "
          f"nominal, guarantee holds {100 * rb['coverage']:.0f} % | CLI hinf {cli['hinf']['process_s']:.2f} s "
          f"(CPU {cli['hinf']['process_cpu_s']:.2f} s), h2 {cli['h2']['process_s']:.2f} s "
          f"(CPU {cli['h2']['process_cpu_s']:.2f} s) | {result['wall_time_s']:.0f} s")


if __name__ == "__main__":
    main()

"""Benchmark: the Silverbox arrow predicted by a single-mode cubic-stiffness model (issue 27 item 5).

The model ÿ + cẏ + ky + k2z² + k3z³ = g·u(t − τ), z = y − λẏ (λ a small lag of the nonlinear
force; ``--no-lag``: z = y), observed as y + y0, is fitted by simulation
output error (`satmd.identification.oscillator.fit_oscillator`) on the multisine part of
SNLS80mV.mat, and the same run reports its best linear model (the linear output-error fit the
nonlinear fit starts from). The splits are those of the nonlinear_benchmarks package (Beintema):

* fit: samples 40650 … 40650 + 65062 (the first 75 % of the multisine part 40650 … 127400);
* multisine test: the rest of it, up to 127400;
* arrow, full: samples 100 … 40575, simulated from rest, the first 50 samples not scored;
* arrow, no extrapolation: its first 32000 samples (the amplitude the multisine reaches), ditto.

Errors: RMS in mV and in % of the RMS of the measured output over the scored samples.
Anchor: the freq-statespace package's Silverbox example reports 13.2 % (linear) and 0.44 %
(nonlinear LFR) of the output RMS, on its multisine estimation data.

Writes benchmarks/results/silverbox.json and prints one line. Needs ../shared/data/real/silverbox (or $SATMD_SHARED)
(or ``--mat PATH``).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy.io import loadmat
from satmd.io.shared import shared_dir  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import describe, load_after, machine  # noqa: E402

from satmd.identification.oscillator import fit_oscillator, rms_error  # noqa: E402

MAT = (shared_dir() or Path(__file__).resolve().parents[1].parent / "shared") / "data" / "real" / "silverbox" / "SNLS80mV.mat"
OUT = Path(__file__).resolve().parent / "results" / "silverbox.json"
FS = 610.35
MULTISINE = (40650, 127400)
FIT = (MULTISINE[0], MULTISINE[0] + int(0.75 * (MULTISINE[1] - MULTISINE[0])))
ARROW = (100, 40575)
NO_EXTRAPOLATION = 32000
SKIP = 50
ANCHOR = {"source": "freq-statespace, examples/nonlinear_benchmarks/silverbox_inference_and_learning.py",
          "linear_pct": 13.17, "nonlinear_pct": 0.44, "data": "multisine estimation data (NRMSE)"}


def splits(u, y):
    """The named (input, output, first scored, last scored) test records."""
    arrow_u, arrow_y = u[ARROW[0]:ARROW[1]], y[ARROW[0]:ARROW[1]]
    return {
        "arrow_full": (arrow_u, arrow_y, SKIP, None),
        "arrow_no_extrapolation": (arrow_u[:NO_EXTRAPOLATION], arrow_y[:NO_EXTRAPOLATION], SKIP, None),
        "multisine_test": (u[FIT[1]:MULTISINE[1]], y[FIT[1]:MULTISINE[1]], SKIP, None),
    }


def figures(fit, u, y):
    """Linear and nonlinear errors on every test record."""
    out = {}
    for name, (uu, yy, lo, hi) in splits(u, y).items():
        row = {}
        for label, linear in (("linear", True), ("nonlinear", False)):
            e = rms_error(fit.predict(uu, linear=linear), yy, lo, hi)
            row[label] = {"rms_mV": 1e3 * e["rms"], "pct": e["pct"], "n": e["n"]}
        row["ratio"] = row["linear"]["rms_mV"] / row["nonlinear"]["rms_mV"]
        row["output_rms_mV"] = 1e3 * float(np.sqrt(np.mean(np.asarray(yy)[lo:hi] ** 2)))
        out[name] = row
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mat", type=Path, default=MAT, help="path of SNLS80mV.mat")
    ap.add_argument("--substeps", type=int, default=6, help="RK4 steps per sample")
    args = ap.parse_args()
    if not args.mat.exists():
        sys.exit(f"silverbox: {args.mat} not found")
    result = {"benchmark": "silverbox", "machine": machine(device="cpu", threads=1), "models": {}}
    d = loadmat(args.mat)
    u, y = d["V1"].ravel().astype(float), d["V2"].ravel().astype(float)
    for name, lag in (("cubic", False), ("cubic_lag", True)):
        t0 = time.perf_counter()
        fit = fit_oscillator(u, y, FS, ranges=[FIT], substeps=args.substeps, lag=lag)
        fit_s = time.perf_counter() - t0
        t1 = time.perf_counter()
        errors = figures(fit, u, y)
        predict_s = time.perf_counter() - t1
        au = u[ARROW[0]:ARROW[1]]
        t2 = time.perf_counter()
        seg = fit.predict(au, segmented=True)
        segmented_s = time.perf_counter() - t2
        serial = fit.predict(au)
        scored = y[FIT[0] + fit.options["warmup"]:FIT[1]]
        errors["fitted_samples"] = {"nonlinear": {"rms_mV": 1e3 * fit.rms_fit,
                                                  "pct": 100 * fit.rms_fit / float(np.sqrt(np.mean(scored ** 2)))},
                                    "linear": {"rms_mV": 1e3 * fit.rms_fit_linear,
                                               "pct": 100 * fit.rms_fit_linear / float(np.sqrt(np.mean(scored ** 2)))}}
        result["models"][name] = {
            "lag": lag, "errors": errors, "fit_s": fit_s, "predict_s": predict_s, "fit": fit.to_dict(),
            "arrow_segmented_vs_serial_max_mV": 1e3 * float(np.max(np.abs(seg - serial))),
            "arrow_segmented_s": segmented_s}
    result["splits"] = {"fit": FIT, "multisine": MULTISINE, "arrow": ARROW, "no_extrapolation": NO_EXTRAPOLATION,
                        "skip": SKIP, "fs": FS, "substeps": args.substeps}
    result["anchor"] = ANCHOR
    best = result["models"]["cubic_lag"]
    full = best["errors"]["arrow_full"]
    result["targets"] = {"arrow_ratio_ge_10": full["ratio"] >= 10.0,
                         "arrow_nonlinear_pct_le_1": full["nonlinear"]["pct"] <= 1.0}
    result["machine"].update(load_after())
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(result, indent=2, default=float))
    parts = []
    for name, m in result["models"].items():
        e = m["errors"]
        f, r, ms = e["arrow_full"], e["arrow_no_extrapolation"], e["multisine_test"]
        parts.append(f"{name}: arrow linear {f['linear']['pct']:.2f} % ({f['linear']['rms_mV']:.2f} mV), nonlinear "
                     f"{f['nonlinear']['pct']:.3f} % ({f['nonlinear']['rms_mV']:.3f} mV), ratio {f['ratio']:.1f}; "
                     f"in range {r['linear']['pct']:.2f} % / {r['nonlinear']['pct']:.3f} % (ratio {r['ratio']:.1f}); "
                     f"multisine test {ms['linear']['pct']:.2f} % / {ms['nonlinear']['pct']:.3f} %; fitted samples "
                     f"{e['fitted_samples']['linear']['pct']:.2f} % / {e['fitted_samples']['nonlinear']['pct']:.3f} %; "
                     f"fit {m['fit_s']:.0f} s")
    print("silverbox: " + " | ".join(parts) + " | " + describe(result["machine"]))


if __name__ == "__main__":
    main()

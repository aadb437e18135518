"""Nonlinear model benchmark (issue 27): coefficient recovery and 95 % coverage per element, held-out
level prediction against the best linear model (error against the noisy recording, and against the
noise-free truth the benchmark knows), tuning across levels, integrator speed.

Recordings come from the INDEPENDENT simulator `benchmarks/_indep_nl_sim.py` (RK4, its own equations,
shares no code with satmd; run at 2x the rate and decimated, see UP), 40 s at 2048 Hz, random force spectra, white noise 1 % on the
accelerometers and 0.5 % on the force. Per element and seed: a rig drawn at random (m2, kp, R, L),
the element at a strength that moves its equivalent parameter by ~12 % (kp, k1, L) or ~3 N·s/m (cp)
at the top level, three levels: 1, 4 and 10 N RMS. The model (element + m2, kp, R, L) is fitted by
`satmd.identification.nonlinear.fit_nonlinear` on the 1 and 10 N recordings (first ``--seconds`` s
of each), the 4 N recording is held out and predicted; the best linear model (m2, kp, R, L fitted in
the time domain on the same two recordings) predicts it too.

Tuning: on one seed per element, `tune_nonlinear` on the fitted model over 1, 4, 10 N; its design is
simulated on the TRUE rig (satmd's integrator with the true element) and compared with the true
optimum, a 9 x 9 direct-simulation grid search on the true rig refined once; also the cost of the
low-level linear tuning on the true rig.

Usage: python benchmarks/nonlinear_model.py [--seeds 4] [--seconds 30] [--elements a,b] [--no-tune]
Writes benchmarks/results/nonlinear_model.json and prints one line of figures.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import _indep_nl_sim as indep  # noqa: E402
from _machine import describe, load_after, machine  # noqa: E402

FS = 2048.0
LEVELS = (1.0, 4.0, 10.0)  # train on the first and last, hold out the middle
TUNE_BAND = (20.0, 200.0)
UP = 2


def _strength(name, rig, rng):
    """Element parameters moving the equivalent parameter by ~12 % (or ~3 N·s/m) at 10 N."""
    from satmd.physics.nonlinear import response_rms

    rms = {k: float(v) for k, v in response_rms(rig, TUNE_BAND, LEVELS[-1]).items()}
    f = rng.uniform(0.8, 1.25)
    if name == "cubic_absorber_spring":
        return {"k3": f * 0.12 * rig.kp / (3 * rms["d"] ** 2)}
    if name == "cubic_host_spring":
        return {"k3": f * 0.12 * rig.k1 / (3 * rms["u1"] ** 2)}
    if name == "quadratic_damping":
        return {"c2": f * 3.0 / (math.sqrt(8 / math.pi) * rms["v"])}
    if name == "absorber_friction":  # a cp change of ~3 N·s/m at the LOW level (it fades with level)
        v_lo = rms["v"] * LEVELS[0] / LEVELS[-1]
        return {"Fc": f * 3.0 * v_lo * math.sqrt(math.pi / 2), "v0": 0.1 * v_lo}
    return {"isat": rms["i"] / math.sqrt(f * 0.12)}  # L -12 % at 10 N


def _indep_par(name, params):
    return (params["Fc"], params["v0"]) if name == "absorber_friction" else next(iter(params.values()))


def _upsample(x, k):
    """Band-limited interpolation to k x the rate (zero-padded FFT), every k-th sample the input."""
    if k == 1:
        return x
    n = x.shape[-1]
    pad = 4096
    padded = np.zeros(x.shape[:-1] + (n + 2 * pad,))
    padded[..., pad:pad + n] = x
    spec = np.fft.rfft(padded)
    return (np.fft.irfft(spec, k * padded.shape[-1]) * k)[..., k * pad:k * (pad + n)]


def _recordings(name, rigs, params, seconds, seed):
    """One independent-simulator run per (rig, level): {(i, level): Recording}."""
    from satmd.io.recdata import Recording

    rng = np.random.default_rng(seed)
    n = int(seconds * FS)
    out, clean = {}, {}
    for i, (rig, par) in enumerate(zip(rigs, params)):
        shape = str(rng.choice(["flat", "up", "down", "notch"]))
        forces = np.stack([lv * indep.random_force(n, FS, rng, shape=shape) for lv in LEVELS])
        # the reference runs at UP x the rate (RK4 at 2048 Hz errs by ~1e-3 on a fast shunt pole, R/L ~ 1500/s)
        a1, a2, _ = indep.simulate(_upsample(forces, UP), UP * FS, name, _indep_par(name, par),
                                   rig={k: float(getattr(rig, k)) for k in ("m2", "kp", "R", "L")})
        a1, a2 = a1[:, ::UP], a2[:, ::UP]
        for j, lv in enumerate(LEVELS):
            clean[(i, lv)] = np.vstack([a1[j], a2[j]])
            chans = {}
            for ch, x, rel in (("force", forces[j], 0.005), ("acc1", a1[j], 0.01), ("acc2", a2[j], 0.01)):
                chans[ch] = x + rel * np.sqrt(np.mean(x * x)) * rng.standard_normal(n)
            out[(i, lv)] = Recording(FS, chans, {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"},
                                     {"force_rms": f"{lv:g}"})
    return out, clean


def _clean_error(fit, rec, truth, seconds):
    """RMS(prediction - noise-free truth) / RMS(truth) over a1 and a2 of the held-out recording."""
    from satmd.identification.nonlinear import predict

    p = predict(fit, rec, seconds)
    k = int(2.0 * FS)
    n = p["a1"].size
    err = [np.sum((p[ch][k:] - truth[c, k:n]) ** 2) / np.sum(truth[c, k:n] ** 2) for c, ch in enumerate(("a1", "a2"))]
    return float(np.sqrt(np.mean(err)))


def _fit_case(name, rig, par, recs, seconds, clean_held):
    from satmd.identification.nonlinear_compare import compare_models

    t0 = time.perf_counter()
    out = compare_models([recs[LEVELS[0]], recs[LEVELS[-1]]], [recs[LEVELS[1]]], name, seconds=seconds)
    nl, lin = out.pop("fits")
    truth = {**{k: float(getattr(rig, k)) for k in ("m2", "kp", "R", "L")}, **par}
    covered = {k: bool(nl.ci95[k][0] <= v <= nl.ci95[k][1]) for k, v in truth.items() if k in nl.ci95}
    rel_err = {k: float(nl.values[k] / v - 1) for k, v in truth.items() if k in nl.values}
    held = [r for r in out["levels"] if r["held_out"]][0]
    vs_truth = {"linear": _clean_error(lin, recs[LEVELS[1]], clean_held, seconds),
                "nonlinear": _clean_error(nl, recs[LEVELS[1]], clean_held, seconds)}
    return {"truth": truth, "fitted": nl.values, "ci95": nl.ci95, "covered": covered, "rel_error": rel_err,
            "held_out_td_error": held["td_error"], "held_out_ratio": held["td_ratio"],
            "held_out_error_vs_noise_free_truth": vs_truth,
            "held_out_ratio_vs_truth": vs_truth["linear"] / max(vs_truth["nonlinear"], 1e-300),
            "frf_residual": [{"level": r["level"], **r["frf_residual"]} for r in out["levels"]],
            "td_error": [{"level": r["level"], **r["td_error"]} for r in out["levels"]],
            "seconds": time.perf_counter() - t0, "fit": nl}


def _tune_case(name, rig, par, fit):
    from satmd.physics import nonlinear_element
    from satmd.tuning.nonlinear import simulated_peaks, tune_nonlinear

    true_el = [nonlinear_element(name, **par)]
    res = tune_nonlinear(fit.rig, [fit.element], LEVELS, TUNE_BAND)
    sim = dict(band_hz=TUNE_BAND, duration_s=40.0, fs_hz=1024.0, seed=0)

    def worst(R, L):
        return 20 * np.log10(simulated_peaks(rig, true_el, R, L, LEVELS, **sim)).max(axis=1)

    # true optimum: 9 x 9 grid around the true rig's equivalent design, then a finer one
    center = np.log([res.equivalent_design["R"], res.equivalent_design["L"]])
    for span in (0.5, 0.1):
        g = np.linspace(-1, 1, 9) * span
        X = np.array([[center[0] + a, center[1] + b / 3] for a in g for b in g])
        w = worst(np.exp(X[:, 0]), np.exp(X[:, 1]))
        center, best = X[int(np.argmin(w))], float(np.min(w))
    tuned = float(worst(res.design["R"], res.design["L"])[0])
    linear = float(worst(res.linear_design["R"], res.linear_design["L"])[0])
    return {"design": res.design, "linear_design": res.linear_design, "true_optimum_db": best,
            "tuned_worst_db_on_true_rig": tuned, "gap_to_true_optimum_db": tuned - best,
            "linear_worst_db_on_true_rig": linear, "cost_of_linear_tuning_db": linear - tuned,
            "seconds": res.wall_time}


def _speed():
    from satmd.physics import Rig, integrate, nonlinear_element
    from satmd.physics.nonlinear import kernel

    n = int(90 * FS)
    F = indep.random_force(n, FS, np.random.default_rng(0), shape="flat")
    el = nonlinear_element("cubic_absorber_spring", k3=2e11)
    integrate(Rig(), F[:4096], FS, [el])  # compile
    out = {"numba": kernel.available}
    for backend in (["numba"] if kernel.available else []) + ["numpy"]:
        t0 = time.perf_counter()
        integrate(Rig(), 10 * F, FS, [el], backend=backend)
        out[f"{backend}_s_90s_2048Hz"] = time.perf_counter() - t0
    return out


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=30.0, help="seconds of each recording used by the fits")
    ap.add_argument("--duration", type=float, default=40.0, help="recording length")
    ap.add_argument("--elements", default=",".join(indep.ELEMENTS))
    ap.add_argument("--no-tune", action="store_true")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    from satmd.physics import Rig

    result = {"machine": machine(device="cpu", threads=1), "settings": vars(args), "levels": LEVELS}
    t_all = time.perf_counter()
    result["speed"] = _speed()
    per = {}
    for e_i, name in enumerate(args.elements.split(",")):
        rng = np.random.default_rng(1000 + e_i)
        rigs = [Rig(m2=rng.uniform(0.4, 0.7), kp=rng.uniform(8e4, 1.5e5), R=rng.uniform(10, 60),
                    L=rng.uniform(0.04, 0.2)) for _ in range(args.seeds)]
        params = [_strength(name, r, rng) for r in rigs]
        t0 = time.perf_counter()
        recs, clean = _recordings(name, rigs, params, args.duration, 2000 + e_i)
        sim_s = time.perf_counter() - t0
        cases = []
        for i, (rig, par) in enumerate(zip(rigs, params)):
            case = _fit_case(name, rig, par, {lv: recs[(i, lv)] for lv in LEVELS}, args.seconds, clean[(i, LEVELS[1])])
            if i == 0 and not args.no_tune:
                case["tuning"] = _tune_case(name, rig, par, case["fit"])
            case.pop("fit")
            cases.append(case)
            print(name, i, {k: round(v, 4) for k, v in case["rel_error"].items()}, case["covered"],
                  "ratio %.1f (vs truth %.1f)" % (case["held_out_ratio"], case["held_out_ratio_vs_truth"]),
                  "%.0f s" % case["seconds"], flush=True)
        strength = [k for k in params[0] if k != "v0"][0]
        per[name] = {
            "strength_parameter": strength,
            "coverage": float(np.mean([c["covered"][strength] for c in cases])),
            "coverage_all_parameters": float(np.mean([v for c in cases for v in c["covered"].values()])),
            "median_abs_rel_error": float(np.median([abs(c["rel_error"][strength]) for c in cases])),
            "held_out_ratio_min": float(min(c["held_out_ratio"] for c in cases)),
            "held_out_ratio_median": float(np.median([c["held_out_ratio"] for c in cases])),
            "held_out_ratio_vs_truth_min": float(min(c["held_out_ratio_vs_truth"] for c in cases)),
            "simulation_s": sim_s, "cases": cases}
        if "tuning" in cases[0]:
            per[name]["tuning"] = cases[0]["tuning"]
            print(name, "tuning", {k: v for k, v in cases[0]["tuning"].items() if "design" not in k}, flush=True)
        result["elements"] = per  # written after every element: a partial run keeps what it measured
        (ROOT / "benchmarks" / "results" / "nonlinear_model.json").write_text(
            json.dumps(result, indent=1, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))
    result["elements"] = per
    result["seconds"] = time.perf_counter() - t_all
    result["machine"].update(load_after())
    path = ROOT / "benchmarks" / "results" / "nonlinear_model.json"
    path.write_text(json.dumps(result, indent=1, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))
    cov = ", ".join(f"{k} {100 * v['coverage']:.0f}%" for k, v in per.items())
    ratio = ", ".join(f"{k} {v['held_out_ratio_min']:.1f}x ({v['held_out_ratio_vs_truth_min']:.0f}x vs truth)"
                      for k, v in per.items())
    tune = ", ".join(f"{k} gap {v['tuning']['gap_to_true_optimum_db']:+.2f} dB cost {v['tuning']['cost_of_linear_tuning_db']:.2f} dB"
                     for k, v in per.items() if "tuning" in v)
    speed = result["speed"]
    print(f"coverage {cov} | held-out ratio (min) {ratio} | tuning {tune} | integrator 90 s at 2 kHz: "
          f"numba {speed.get('numba_s_90s_2048Hz', float('nan')):.2f} s, numpy {speed['numpy_s_90s_2048Hz']:.2f} s "
          f"| {result['seconds']:.0f} s | " + describe(result["machine"]))


if __name__ == "__main__":
    main()

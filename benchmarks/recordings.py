"""Recordings benchmark: discovery and identification from lab-like time recordings.

Every recording is made by `satmd.io.simulate_recording` with its realistic
defaults: random non-periodic band-limited force (20–200 Hz), rig at rest at
t = 0, white noise on the force *and* on both accelerometers. Settings are
drawn per recording: fs 1–5 kHz, 30–180 s, accelerometer noise 1–5 % and force
noise 0.5–2 % of RMS, rig anywhere in the SPEC §9 ranges. Each recording goes
through exactly what `satmd discover REC` does (LPM estimate, then discovery).

1. False alarms over N null recordings (nothing missing from the physics).
2. The same nulls → identification: coverage of the 95 % intervals
   (estimate ± 1.96 std) per parameter.
3. Concealed single effects, per effect: found from the recording, and no
   spurious effect in the report. The reference is the FRF-domain path *at the
   same information*: the true model on the estimate's grid with the
   estimate's std as Gaussian noise (`discover` on FRFs). Rates are over the
   cases that path detects.
4. Two simultaneous effects: both found.
5. Estimator bias at the first resonance, noise-free: LPM vs the Welch H1
   default, relative to the noise std of a 2 %-noise recording.
6. Seconds per 120 s recording at 2 kHz (estimate + discover, one process, after the pool has
   finished): null recordings and recordings with a hidden effect (`--timing-only` reruns just
   these into an existing result file, e.g. on a quiet machine).

Writes benchmarks/results/recordings.json and prints one line of figures.
Usage: python benchmarks/recordings.py [--nulls 200] [--per-effect 8] [--pairs 10] [--workers 2] [--quick]
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

EFFECTS = ["extra_mode", "time_delay", "structural_damping", "sensor_gain", "dielectric_loss",
           "shunt_capacitance", "parameter_offset:k1", "parameter_offset:c1"]
PARAMS = ("m2", "kp", "R", "L")


def machine_info(workers):
    import os

    return {"python": platform.python_version(), "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(), "workers": workers,
            "load_average_1min": os.getloadavg()[0]}


def draw_settings(rng):
    return dict(duration_s=float(rng.uniform(30, 180)), fs_hz=float(rng.choice([1000, 2000, 3000, 4000, 5000])),
                noise=float(rng.uniform(0.01, 0.05)), force_noise=float(rng.uniform(0.005, 0.02)))


def names_with_equivalents(report):
    out = []
    for e in report.effects:
        out.append({e.name, *getattr(e, "equivalent", [])})
    return out


def score(report, truth):
    """(all truth effects found, any spurious effect reported)."""
    found_sets = names_with_equivalents(report)
    found = all(any(t in s for s in found_sets) for t in truth)
    spurious = any(not (s & set(truth)) for s in found_sets)
    return found, spurious


def run_null(seed):
    from satmd import discover
    from satmd.discovery.scenarios import random_rig
    from satmd.io import estimate_frf, simulate_recording

    rng = np.random.default_rng(1000 + seed)
    rig = random_rig(rng)
    s = draw_settings(rng)
    rec = simulate_recording(s["duration_s"], s["fs_hz"], rig, noise=s["noise"], force_noise=s["force_noise"],
                             seed=seed)
    t0 = time.perf_counter()
    rep = discover(estimate_frf(rec))
    fit = rep.nominal_fit
    cover = {p: bool(abs(fit.values[p] - getattr(rig, p)) <= 1.96 * fit.std[p]) for p in PARAMS}
    z = {p: float((fit.values[p] - getattr(rig, p)) / fit.std[p]) for p in PARAMS}
    return {"seed": seed, **s, "alarm": bool(rep.significant_mismatch), "effects": rep.effect_names,
            "measurement": [m["name"] for m in rep.measurement], "cover": cover, "z": z,
            "chi2_reduced": rep.fit_before["chi2_reduced"], "seconds": time.perf_counter() - t0}


def run_effect(args):
    name_list, seed = args
    from satmd import discover
    from satmd.discovery.scenarios import random_effect, random_rig
    from satmd.io import FRFData, estimate_frf, simulate_recording
    from satmd.physics import frf

    rng = np.random.default_rng(5000 + seed)
    rig = random_rig(rng)
    effects = [random_effect(n, rng, np.array([40.0, 180.0])) for n in name_list]
    s = draw_settings(rng)
    rec = simulate_recording(s["duration_s"], s["fs_hz"], rig, effects, noise=s["noise"],
                             force_noise=s["force_noise"], seed=seed)
    t0 = time.perf_counter()
    data = estimate_frf(rec)
    rep = discover(data)
    seconds = time.perf_counter() - t0
    # the FRF-domain path at the same information: true model + Gaussian noise of the estimate's std
    true = frf(data.freq_hz, rig, effects, outputs=tuple(data.channels))
    noisy = {c: true.channel(c) + data.std[c] * (rng.standard_normal(len(data)) + 1j * rng.standard_normal(len(data)))
             for c in data.channels}
    ref = discover(FRFData(data.freq_hz, noisy, dict(data.std)))
    found, spurious = score(rep, name_list)
    ref_found, _ = score(ref, name_list)
    return {"seed": seed, "truth": name_list, **s, "found": found, "spurious": spurious,
            "reported": rep.effect_names, "measurement": [m["name"] for m in rep.measurement],
            "frf_path_found": ref_found, "frf_path_reported": ref.effect_names, "seconds": seconds}


def estimator_bias():
    """Relative error at the first resonance of noise-free estimates, against a 2 %-noise std."""
    from satmd.io import estimate_frf, simulate_recording
    from satmd.physics import Rig, frf

    clean = simulate_recording(120.0, 1000.0, noise=0.0, force_noise=0.0, seed=1)
    noisy = simulate_recording(120.0, 1000.0, noise=0.02, seed=1)
    out = {}
    for label, opts in (("lpm", {}), ("welch_h1_default", {"estimator": "H1"})):
        d, dn = estimate_frf(clean, **opts), estimate_frf(noisy, **opts)
        truth = frf(d.freq_hz, Rig(), outputs=("a1",)).a1
        i = int(np.argmax(np.abs(truth)))
        out[label] = {"freq_hz": float(d.freq_hz[i]), "rel_error_at_peak": float(abs(d["a1"][i] / truth[i] - 1)),
                      "bias_over_std_at_peak": float(abs(d["a1"][i] - truth[i]) / dn.std["a1"][i]),
                      "max_bias_over_std": float(np.max(np.abs(d["a1"] - truth) / dn.std["a1"]))}
    return out


def seconds_per_recording(repeats=3):
    """Median seconds of `discover(estimate_frf(rec))` on 120 s recordings at 2 kHz, in this process.

    Null recordings, and recordings with one hidden effect (an extra mode, a time delay, k1 off by 3 %):
    discovery then searches the vocabulary, which costs more than the estimate and the nominal fit.
    """
    from satmd import discover, effect
    from satmd.io import estimate_frf, simulate_recording

    hidden = [effect("extra_mode", f_hz=72.0, zeta=0.01, mass_ratio=0.004), effect("time_delay", tau_s=2e-4),
              effect("parameter_offset:k1", value=194e3 * 1.03)]
    out = {}
    for label, cases in (("null", [[]] * repeats), ("hidden_effect", [[e] for e in hidden])):
        times = []
        for seed, effects in enumerate(cases):
            rec = simulate_recording(120.0, 2000.0, effects=effects, noise=0.02, seed=seed)
            t0 = time.perf_counter()
            discover(estimate_frf(rec))
            times.append(time.perf_counter() - t0)
        out[label] = {"median_s": float(np.median(times)), "max_s": float(max(times))}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nulls", type=int, default=200)
    ap.add_argument("--per-effect", type=int, default=8)
    ap.add_argument("--pairs", type=int, default=10)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="20 nulls, 2 per effect, 3 pairs")
    ap.add_argument("--timing-only", action="store_true",
                    help="rerun only the seconds-per-recording figures into an existing --out file")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "recordings.json"))
    a = ap.parse_args()
    if a.quick:
        a.nulls, a.per_effect, a.pairs = 20, 2, 3
    if a.timing_only:  # rerun only the timings (on a quiet machine) into an existing result file
        result = json.loads(Path(a.out).read_text())
        timing = seconds_per_recording()
        result.update({"seconds_per_120s_2kHz_recording": timing["null"]["median_s"], "timing_120s_2kHz": timing,
                       "timing_machine": machine_info(a.workers)})
        Path(a.out).write_text(json.dumps(result, indent=1))
        print(f"recordings timing: null {timing['null']['median_s']:.1f} s, hidden effect median "
              f"{timing['hidden_effect']['median_s']:.1f} s (max {timing['hidden_effect']['max_s']:.1f} s) "
              f"per 120 s recording at 2 kHz")
        return
    t_start = time.perf_counter()
    with ProcessPoolExecutor(a.workers) as pool:
        nulls = list(pool.map(run_null, range(a.nulls)))
        jobs = [([name], 100 * k + i) for k, name in enumerate(EFFECTS) for i in range(a.per_effect)]
        rng = np.random.default_rng(7)
        pairs = [sorted(rng.choice(EFFECTS, 2, replace=False).tolist()) for _ in range(a.pairs)]
        jobs += [(p, 9000 + i) for i, p in enumerate(pairs)]
        cases = list(pool.map(run_effect, jobs))
    timing = seconds_per_recording()  # after the pool: timed alone in this process
    singles = [c for c in cases if len(c["truth"]) == 1]
    doubles = [c for c in cases if len(c["truth"]) == 2]

    def rates(rows):
        detectable = [r for r in rows if r["frf_path_found"]]
        return {"n": len(rows), "frf_path_detects": len(detectable),
                "found": sum(r["found"] for r in detectable),
                "no_spurious": sum(not r["spurious"] for r in detectable),
                "found_rate": (sum(r["found"] for r in detectable) / len(detectable)) if detectable else None,
                "no_spurious_rate": (sum(not r["spurious"] for r in detectable) / len(detectable))
                if detectable else None}

    per_effect = {name: rates([c for c in singles if c["truth"] == [name]]) for name in EFFECTS}
    coverage = {p: float(np.mean([n["cover"][p] for n in nulls])) for p in PARAMS}
    result = {
        "what": "discovery and identification from lab-like recordings (random force, at rest, noise on all channels)",
        "machine": machine_info(a.workers),
        "nulls": {"n": len(nulls), "false_alarms": sum(n["alarm"] for n in nulls),
                  "false_alarm_rate": float(np.mean([n["alarm"] for n in nulls])),
                  "median_chi2_reduced": float(np.median([n["chi2_reduced"] for n in nulls])),
                  "measurement_findings": sorted({m for n in nulls for m in n["measurement"]})},
        "identify_coverage_95": coverage,
        "identify_z_std": {p: float(np.std([n["z"][p] for n in nulls])) for p in PARAMS},
        "single_effects": rates(singles), "per_effect": per_effect, "two_effects": rates(doubles),
        "estimator_bias": estimator_bias(),
        "seconds_per_120s_2kHz_recording": timing["null"]["median_s"],
        "timing_120s_2kHz": timing,
        "benchmark_seconds": time.perf_counter() - t_start,
        "cases": {"nulls": nulls, "effects": cases},
    }
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(result, indent=1))
    s, d, b = result["single_effects"], result["two_effects"], result["estimator_bias"]
    fmt = lambda x: "n/a" if x is None else f"{100 * x:.0f} %"  # noqa: E731
    print(f"recordings: false alarms {result['nulls']['false_alarms']}/{len(nulls)}; "
          f"coverage " + " ".join(f"{p} {coverage[p]:.2f}" for p in PARAMS) + "; "
          f"single effects found {fmt(s['found_rate'])}, no spurious {fmt(s['no_spurious_rate'])} "
          f"(of {s['frf_path_detects']} the FRF path detects); two effects {fmt(d['found_rate'])}; "
          f"peak bias/std LPM {b['lpm']['bias_over_std_at_peak']:.2f} vs Welch "
          f"{b['welch_h1_default']['bias_over_std_at_peak']:.1f}; "
          f"{timing['null']['median_s']:.1f} s per 120 s null recording at 2 kHz, "
          f"{timing['hidden_effect']['median_s']:.1f} s with a hidden effect")


if __name__ == "__main__":
    main()

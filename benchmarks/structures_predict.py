"""A structure's joint modelled and its unseen levels predicted (issue 47, SPEC §11): `satmd.structure.fit_structure`.

Two parts, each measured on levels the model was not fitted on:

- **Chains** (`tests/structure/chain.py`: Newton's law and Runge-Kutta, no satmd code): 4 to 6 masses, one
  joint of each law at a random place, 1 % noise on every channel; fitted on the levels 1 and 8 N RMS, then
  predicted at 3 N RMS (inside the fitted range) and at 12 N RMS (extrapolated). NRMSE per channel of the
  response simulated from the force, the joint's model against the linear model of the lowest level.
- **The F-16** ground vibration test (real, ../shared/data/real/f16): fitted on levels 1, 3 and 7, level 5
  held out; then fitted on all four (the model `discover --save-model` writes). For context, not a like-for-
  like comparison: the best published model on the benchmark's validation level 6 (a deep state-space
  network trained on every odd level and the sweeps) reaches NRMSE 0.134, 0.099, 0.237 on acc1, acc2, acc3.

    python benchmarks/structures_predict.py [--count 10] [--no-f16] [--out PATH]

Writes benchmarks/results/structures_predict.json and prints one line.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
from _machine import describe, load_after, machine  # noqa: E402
from satmd.structure import fit_structure  # noqa: E402
from structures_joint import law_of as _law  # noqa: E402  (the same laws, drawn the same way)
from tests.structure.chain import simulate_chain  # noqa: E402

FIT_LEVELS, HELD, BEYOND = (1.0, 8.0), 3.0, 12.0
KINDS = ("hardening", "softening", "friction", "quadratic_damping", "clearance")
F16_MAP = "force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]"
#: the laws' shapes whose force on a measured stroke might drive the F-16's response above the band (d, v the
#: stroke and its velocity, ds, vs their RMS at the top level)
HARMONIC_SHAPES = {
    "cubic d³": lambda d, v, ds, vs: d ** 3, "quadratic damping v|v|": lambda d, v, ds, vs: v * np.abs(v),
    "friction tanh(v/0.1σv)": lambda d, v, ds, vs: np.tanh(v / (0.1 * vs)),
    "softening tanh(d/0.3σd)": lambda d, v, ds, vs: np.tanh(d / (0.3 * ds)),
    "clearance at σd": lambda d, v, ds, vs: np.sign(d) * np.maximum(np.abs(d) - ds, 0.0),
    "d|d|": lambda d, v, ds, vs: d * np.abs(d), "v³": lambda d, v, ds, vs: v ** 3}
PUBLISHED_L6 = {"nrmse": [0.134, 0.099, 0.237], "model": "deep state-space network (nonlinearbenchmark.org results)"}


def chain(case: int, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 7))
    m, k = rng.uniform(0.5, 2.0, n), rng.uniform(2e4, 8e4, n)
    i = int(rng.integers(0, n - 1))
    kind = KINDS[case % len(KINDS)]
    law, name = _law(kind, rng)
    recs = simulate_chain(n=n, joint=(i, i + 1), law=law, levels=(*FIT_LEVELS, HELD, BEYOND), seed=seed, m=m, k=k)
    t0 = time.perf_counter()
    model = fit_structure(recs[:2])
    seconds = time.perf_counter() - t0
    held, beyond = model.predict(recs[2]), model.predict(recs[3])
    truth = [f"acc{i + 1}", f"acc{i + 2}"]
    return {"case": case, "seed": seed, "kind": kind, "truth_law": name, "truth_between": truth,
            "between": list(model.joint.between) if model.joint else None,
            "law": model.joint.law if model.joint else None, "fit_s": round(seconds, 1),
            "held": {"nrmse": held.nrmse, "linear_nrmse": held.linear_nrmse},
            "beyond": {"nrmse": beyond.nrmse, "linear_nrmse": beyond.linear_nrmse, "extrapolated": beyond.extrapolated}}


def f16() -> dict | None:
    from satmd.io import load_recording
    from satmd.io.shared import real_data

    if real_data("f16", "F16Data_FullMSine_Level7.mat") is None:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        recs = {lv: load_recording(real_data("f16", f"F16Data_FullMSine_Level{lv}.mat"), channel_map=F16_MAP)
                for lv in (1, 3, 5, 7)}
    t0 = time.perf_counter()
    held_out = fit_structure([recs[1], recs[3], recs[7]], files=["L1", "L3", "L7"])
    t1 = time.perf_counter()
    p5 = held_out.predict(recs[5], file="L5")
    whole = fit_structure([recs[lv] for lv in (1, 3, 5, 7)], files=["L1", "L3", "L5", "L7"])
    t2 = time.perf_counter()
    j = whole.joint
    return {"channels": list(whole.channels),
            "held_out": {"fitted_on": [1, 3, 7], "level": 5, "nrmse": p5.nrmse, "linear_nrmse": p5.linear_nrmse,
                         "band_top_hz": p5.band_top_hz, "above_band": p5.above_band,
                         "fit": held_out.fit, "between": list(held_out.joint.between), "law": held_out.joint.law,
                         "fit_s": round(t1 - t0, 1)},
            "all_levels": {"fit": whole.fit, "between": list(j.between), "law": j.law, "formula": j.formula(),
                           "units": j.units, "poles": int(whole.linear.poles.size), "fit_s": round(t2 - t1, 1)},
            "published_level6": PUBLISHED_L6,
            "harmonics": harmonics_source([recs[lv] for lv in (1, 3, 7)], list(whole.channels)),
            "bursts": harmonics_bursts([recs[lv] for lv in (1, 3, 5, 7)], list(whole.channels)),
            "one_source": harmonics_one_source({lv: recs[lv] for lv in (3, 5, 7)}, list(whole.channels))}


def harmonics_source(recordings, channels) -> dict:
    """Whether a joint's force on a measured stroke drives the F-16's response above the shaker's band: for every
    pair of sensors (and each to the ground) and each law's shape (`outside.harmonics_explained`, FNSI's
    question), the share of that response its force explains through 4 and 8 modes above the band, on the
    fitted levels. The stroke itself (a linear spring) is listed for scale: it holds the response it explains."""
    from itertools import combinations

    from satmd.structure.outside import harmonics_explained
    from satmd.structure.spectra import periodic_spectra

    spectra = [periodic_spectra(r) for r in recordings]
    top = max(spectra, key=lambda s: s.level)
    shapes = {**HARMONIC_SHAPES, "linear stroke d": lambda d, v, ds, vs: d}
    pairs = [*combinations(channels, 2), *((c, "ground") for c in channels)]
    rows = []
    for a, b in pairs:
        d, v = top.relative(a, b)
        ds, vs = float(np.std(d)) or 1.0, float(np.std(v)) or 1.0
        for name, g in shapes.items():
            rows.append({"between": [a, b], "law": name, "explained": [
                round(harmonics_explained(spectra, (a, b), lambda d, v, g=g: g(d, v, ds, vs), channels, k), 4)
                for k in (4, 8)]})
    laws = [r for r in rows if r["law"] != "linear stroke d"]
    best = max(laws, key=lambda r: max(r["explained"]))
    return {"rows": rows, "best_law": best, "modes_above": [4, 8]}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=10)
    p.add_argument("--no-f16", action="store_true")
    p.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "structures_predict.json"))
    args = p.parse_args(argv)
    result = {"machine": machine(threads=1), "fit_levels_n_rms": list(FIT_LEVELS), "held_n_rms": HELD,
              "beyond_n_rms": BEYOND}
    rows = [chain(c, 2000 + c) for c in range(args.count)]
    by_kind: dict = {}
    for r in rows:
        s = by_kind.setdefault(r["kind"], {"n": 0, "held": [], "held_linear": [], "beyond": [], "beyond_linear": []})
        s["n"] += 1
        s["held"].append(max(r["held"]["nrmse"]))
        s["held_linear"].append(max(r["held"]["linear_nrmse"]))
        s["beyond"].append(max(r["beyond"]["nrmse"]))
        s["beyond_linear"].append(max(r["beyond"]["linear_nrmse"]))
    summary = {k: {"n": s["n"], "ran_away": int(sum(not np.isfinite(x) for x in s["beyond"] + s["held"])),
                   **{key: float(np.median(v)) for key, v in s.items() if key != "n"}}  # inf (ran away) counts high
               for k, s in by_kind.items()}
    result.update({"rows": rows, "by_kind": summary,
                   "improved_held": sum(max(r["held"]["nrmse"]) < max(r["held"]["linear_nrmse"]) for r in rows),
                   "improved_beyond": sum(max(r["beyond"]["nrmse"]) < max(r["beyond"]["linear_nrmse"]) for r in rows)})
    result["f16"] = None if args.no_f16 else f16()
    result["machine"].update(load_after())
    Path(args.out).write_text(json.dumps(result, indent=1))
    line = (f"structures_predict: worst channel better than linear at the held-out level in "
            f"{result['improved_held']}/{len(rows)} chains, beyond the fitted range in {result['improved_beyond']}/{len(rows)}")
    if result["f16"]:
        h = result["f16"]["held_out"]
        line += (f"; F-16 level 5 held out: NRMSE {', '.join(f'{x:.3f}' for x in h['nrmse'])} "
                 f"(linear {', '.join(f'{x:.2f}' for x in h['linear_nrmse'])})")
    print(line + " | " + describe(result["machine"]))
    return 0


def _shown(nrmse: float) -> str:
    """An NRMSE as the table shows it: a simulation a thousand times the response ran away, whatever its size."""
    return f"{nrmse:.3f}" if np.isfinite(nrmse) and nrmse < 1e3 else "ran away"


def _above_band_transfer(inputs: dict, outputs: dict, fitted, held, window: int) -> float:
    """The share of ``outputs[held]`` (a spectrum at the lines above the band) that a transfer from ``inputs``
    predicts, the transfer fitted on the levels ``fitted`` by least squares: in each window of ``window`` lines a
    complex gain linear in frequency (a structure's FRF is smooth over a few lines; no poles to find)."""
    size = outputs[held].size
    predicted = np.zeros(size, complex)
    for i0 in range(0, size, window):
        cut = slice(i0, min(i0 + window, size))
        x = (np.arange(cut.start, cut.stop) - i0 - window / 2) / window
        X = np.vstack([np.column_stack([inputs[lv][cut], inputs[lv][cut] * x]) for lv in fitted])
        coef, *_ = np.linalg.lstsq(X, np.concatenate([outputs[lv][cut] for lv in fitted]), rcond=None)
        predicted[cut] = np.column_stack([inputs[held][cut], inputs[held][cut] * x]) @ coef
    return float(1 - np.sum(np.abs(outputs[held] - predicted) ** 2) / np.sum(np.abs(outputs[held]) ** 2))


def harmonics_one_source(recordings: dict, channels, fitted=(3, 7), held: int = 5, window_hz: float = 2.0) -> dict:
    """Whether the F-16's response above the band has one source, and whether that source is a law of a stroke:
    the same test for both, a smooth transfer fitted on the levels ``fitted`` and judged at ``held`` (FNSI's
    question without its poles, `_above_band_transfer`). From one channel's response above the band to another's:
    where one place drives them all, the transfer holds from level to level. From a law's force on a measured
    stroke (every pair and to the ground, the laws of `harmonics_source`, scaled at the top level so one law serves
    every level) to each channel's response. And how the waveform above the band keeps its shape from level to
    level beside the response in the band (the levels share one multisine, scaled)."""
    from itertools import combinations

    from satmd.structure.outside import TOP_SHARE
    from satmd.structure.spectra import periodic_spectra

    spectra = {lv: periodic_spectra(r) for lv, r in recordings.items()}
    s = spectra[held]
    n = s.period_samples
    lines = np.arange(max(int(sp.lines.max()) for sp in spectra.values()) + 1, int(TOP_SHARE * (n // 2)) + 1)
    window = max(4, int(round(window_hz * n / s.fs_hz)))
    above = {c: {lv: sp.whole[c][lines] for lv, sp in spectra.items()} for c in channels}
    from_channel = {f"{a}→{b}": round(_above_band_transfer(above[a], above[b], fitted, held, window), 3)
                    for a in channels for b in channels if a != b}
    top = spectra[max(spectra)]
    laws = []
    for a, b in [*combinations(channels, 2), *((c, "ground") for c in channels)]:
        d_top, v_top = top.relative(a, b)
        ds, vs = float(np.std(d_top)) or 1.0, float(np.std(v_top)) or 1.0
        for name, g in HARMONIC_SHAPES.items():
            forces = {lv: np.fft.rfft(g(*sp.relative(a, b), ds, vs), n)[lines] for lv, sp in spectra.items()}
            laws.append({"between": [a, b], "law": name, "explained": [
                round(_above_band_transfer(forces, above[c], fitted, held, window), 3) for c in channels]})
    best_law = max(laws, key=lambda r: max(r["explained"]))

    def waveform(lv, c, band: bool):
        X = np.zeros(n // 2 + 1, complex)
        if band:
            X[spectra[lv].lines] = spectra[lv].responses[c]
        else:
            X[lines] = above[c][lv]
        return np.fft.irfft(X, n)

    pairs = [(lo, hi) for lo, hi in combinations(sorted(spectra), 2)]
    shape = [{"levels": [lo, hi], "channel": c,
              "in_band": round(float(np.corrcoef(waveform(lo, c, True), waveform(hi, c, True))[0, 1]), 3),
              "above_band": round(float(np.corrcoef(waveform(lo, c, False), waveform(hi, c, False))[0, 1]), 3)}
             for lo, hi in pairs for c in channels]
    return {"fitted": list(fitted), "held": held, "window_hz": window_hz, "from_channel": from_channel,
            "best_law": best_law, "waveform": shape}


def harmonics_bursts(recordings, channels, fast: float = 1.5) -> dict:
    """What the F-16's response above the shaker's band is, level by level: its share of each channel's RMS; the
    share of its power that repeats period after period (a nonlinearity's harmonics do, noise does not: 1/periods
    of it would); how impulsive it is (kurtosis: 3 for many harmonics of random phase, far more for knocks); and,
    at the top level, between which sensors its bursts come. A contact that knocks does so when its two sides
    meet fast: for every pair of sensors and each to the ground, how much more often the pair's in-band relative
    velocity is beyond ``fast`` of its RMS at a burst than over the period (the bursts: the peaks of the top 1 %
    of the channels' summed, normalised power above the band)."""
    from itertools import combinations

    from satmd.numerics import force_level
    from satmd.signal.excitation import excitation_of, received
    from satmd.structure.outside import TOP_SHARE
    from satmd.structure.spectra import periodic_spectra

    levels, top = [], None
    for r in recordings:
        rec = received(r)
        exc = excitation_of(rec)
        n = exc.period_samples
        above = np.arange(max(exc.lines) + 1, int(TOP_SHARE * (n // 2)) + 1)  # below the anti-alias filter
        row = {"level_n_rms": round(force_level(rec["force"]), 1), "share": [], "periodic": [], "kurtosis": []}
        power = np.zeros(n)
        for c in channels:
            X = np.fft.rfft(np.asarray(rec[c], float)[: exc.periods * n].reshape(exc.periods, n)[list(exc.steady)],
                            axis=1)
            mean = X.mean(axis=0)
            kept = np.zeros_like(mean)
            kept[above] = mean[above]
            h = np.fft.irfft(kept, n)
            row["share"].append(round(float(np.std(h) / np.std(np.fft.irfft(mean, n))), 3))
            row["periodic"].append(round(float(np.sum(np.abs(mean[above]) ** 2)
                                               / np.sum(np.mean(np.abs(X[:, above]) ** 2, axis=0))), 3))
            row["kurtosis"].append(round(float(np.mean((h - h.mean()) ** 4) / np.var(h) ** 2), 1))
            power += (h / np.std(h)) ** 2
        levels.append(row)
        if top is None or row["level_n_rms"] > top[0]:
            top = (row["level_n_rms"], rec, power)
    _, rec, power = top
    cut = np.quantile(power, 0.99)
    inner = power[1:-1]
    bursts = np.flatnonzero((inner > cut) & (inner >= power[:-2]) & (inner >= power[2:])) + 1
    spectra = periodic_spectra(rec)
    pairs = []
    for a, b in [*combinations(channels, 2), *((c, "ground") for c in channels)]:
        v = np.abs(spectra.relative(a, b)[1])
        beyond = v > fast * np.sqrt(np.mean(v ** 2))
        pairs.append({"between": [a, b], "lift": round(float(np.mean(beyond[bursts]) / max(np.mean(beyond), 1e-12)), 2)})
    pairs.sort(key=lambda p: -p["lift"])
    return {"levels": levels, "bursts": int(bursts.size), "fast": fast, "pairs": pairs}


def readme_markdown(result: dict) -> str:
    """The results table (benchmarks/readme_tables.py renders the region ``structures_predict`` from it)."""
    lines = ["| joint law (chains, fitted at 1 and 8 N RMS) | structures | worst-channel NRMSE at 3 N RMS: linear → joint "
             "| at 12 N RMS (extrapolated): linear → joint |", "|---|---|---|---|"]
    for kind, s in sorted(result["by_kind"].items()):
        lines.append(f"| {kind} | {s['n']} | {_shown(s['held_linear'])} → {_shown(s['held'])} | "
                     f"{_shown(s['beyond_linear'])} → {_shown(s['beyond'])} |")
    lines.append("")
    away = sum(s.get("ran_away", 0) for s in result["by_kind"].values())
    lines.append("Medians over the structures of each law; 1 % noise on every channel is an NRMSE of 0.01. "
                 f"Worst channel better than the linear model at 3 N RMS in {result['improved_held']}/{len(result['rows'])} "
                 f"structures, at 12 N RMS in {result['improved_beyond']}/{len(result['rows'])}"
                 + (f"; {away} simulation(s) ran away (counted as inf)" if away else "") + ".")
    f = result.get("f16")
    if f:
        h, a = f["held_out"], f["all_levels"]
        names = f["channels"]
        lines.append("")
        lines.append(f"F-16, fitted on levels 1, 3, 7, level 5 held out ({h['law']} joint between "
                     f"{' and '.join(h['between'])}): NRMSE " + ", ".join(
                         f"{c} {x:.3f} (linear {y:.2f})" for c, x, y in zip(names, h["nrmse"], h["linear_nrmse"]))
                     + ". Fitted on all four levels: worst NRMSE per level "
                     + ", ".join(f"{lv} {max(r):.3f}" for lv, r in zip(a["fit"]["files"], a["fit"]["nonlinear"]))
                     + f" ({a['fit_s']:.0f} s). For context only: the best published model on the benchmark's "
                     f"level 6 (a deep state-space network, trained on every odd level and the sweeps) reaches "
                     + ", ".join(f"{x:.3f}" for x in f["published_level6"]["nrmse"]) + ".")
        if h.get("above_band") and f.get("harmonics"):
            best = f["harmonics"]["best_law"]
            lines.append("")
            lines.append(f"Where the F-16's level 5 is missed: above the shaker's band ({h['band_top_hz']:.0f} Hz) "
                         "the measured response is " + ", ".join(
                             f"{c} {x:.2f}" for c, x in zip(names, h["above_band"]["measured"]))
                         + " of each channel's RMS, and the model misses " + ", ".join(
                             f"{x:.2f}" for x in h["above_band"]["nrmse"]) + " of it: it predicts none. No law's force "
                         "on a measured stroke drives that response: over every pair of sensors and to the ground, "
                         f"the best ({best['law']} between {' and '.join(best['between'])}) explains "
                         f"{max(best['explained']):.0%} of it through up to 8 modes above the band.")
        if f.get("bursts"):
            lines.append("")
            lines.append(_bursts_text(f["bursts"], names))
        if f.get("one_source"):
            lines.append("")
            lines.append(_one_source_text(f["one_source"]))
    return "\n".join(lines)


def _bursts_text(b: dict, names: list) -> str:
    """What the F-16's response above the band is (`harmonics_bursts`), in words."""
    levels = b["levels"]
    loudest = int(np.argmax(levels[-1]["share"]))
    first, second = b["pairs"][0], b["pairs"][1]
    return (f"What that response is: the share of {names[loudest]}'s RMS above the band is "
            + ", ".join(f"{lv['share'][loudest]:.1%}" for lv in levels) + " at "
            + ", ".join(f"{lv['level_n_rms']:g}" for lv in levels) + " N RMS; "
            f"of its power {min(levels[-1]['periodic']):.0%} or more repeats period after period at the top level "
            f"(noise would repeat 1/periods of it), and it comes in bursts (kurtosis {levels[-1]['kurtosis'][loudest]:g} "
            f"on {names[loudest]}; harmonics of random phase give 3). The {b['bursts']} bursts of the top level come "
            f"when {' and '.join(first['between'])} move fastest against each other: their relative velocity is beyond "
            f"{b['fast']:g} RMS {first['lift']:.1f}× as often at a burst as over the period (the next, "
            f"{' and '.join(second['between'])}, {second['lift']:.1f}×). A contact between those two sensors that "
            "knocks: a law of the measured stroke does not time its knocks, and the model leaves them out.")


def _one_source_text(o: dict) -> str:
    """Whether one place drives the F-16's response above the band, and whether a law of a stroke does
    (`harmonics_one_source`), in words."""
    pairs = sorted(o["from_channel"].items(), key=lambda kv: -kv[1])
    (first, x), (second, y) = pairs[0], pairs[1]
    best = o["best_law"]
    top = [w for w in o["waveform"] if w["levels"] == sorted({lv for w in o["waveform"] for lv in w["levels"]})[-2:]]
    fitted = " and ".join(str(lv) for lv in o["fitted"])
    return (f"One place drives it, and not by a law of these strokes: through a transfer fitted on levels {fitted} "
            f"(a gain smooth over {o['window_hz']:g} Hz) and judged at level {o['held']}, {_said(first, x)} "
            f"({_said(second, y)}); by the same test the best law's force on any measured stroke "
            f"({best['law']} between {' and '.join(best['between'])}) predicts {max(best['explained']):.0%}. From level "
            f"{top[0]['levels'][0]} to level {top[0]['levels'][1]}, one multisine scaled, the response in the band keeps "
            f"its waveform (correlation {min(w['in_band'] for w in top):.2f}–{max(w['in_band'] for w in top):.2f}) and "
            f"the one above it does not ({min(w['above_band'] for w in top):.2f}–{max(w['above_band'] for w in top):.2f}).")


def _said(arrow: str, share: float) -> str:
    """An arrow ("acc1→acc3") and its share, in words."""
    a, b = arrow.split("→")
    return f"{a}'s response above the band predicts {share:.0%} of {b}'s"

if __name__ == "__main__":
    raise SystemExit(main())

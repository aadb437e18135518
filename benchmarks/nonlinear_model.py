"""Nonlinear model benchmark (issue 27): coefficient recovery and 95 % coverage per element, held-out
level prediction against the best linear model (error against the noisy recording, and against the
noise-free truth the benchmark knows), tuning across levels, integrator speed.

Recordings come from the INDEPENDENT simulator `benchmarks/_indep_nl_sim.py` (RK4, its own equations,
shares no code with satmd; run at 2x the rate and decimated, see UP), ``--duration`` s at 2048 Hz, random force spectra, white noise 1 % on the
accelerometers and 0.5 % on the force. Per element and seed: a rig drawn at random (m2, kp, R, L),
the element at a strength that moves its equivalent parameter by ~12 % (kp, k1, L) or ~3 N·s/m (cp)
at the top level (friction: ~3 N·s/m of cp at the LOW level, where it acts most), three levels: 1, 4 and
10 N RMS. Hold-out designs (`designs_for`), each fitted by
`satmd.identification.nonlinear.fit.fit_nonlinear` (element + m2, kp, R, L) on the first ``--seconds`` s
of its two training recordings:

- ``extrapolate`` (the headline): predict the level where the element acts at its stated strength from
  the two others: 10 N from 1 and 4 N for the hardening/softening elements, 1 N from 4 and 10 N for
  friction (its equivalent damping Fc/v falls with level). It is the engineer's question ("will the model
  hold at the drive levels the structure will see?"), and the one a linear model cannot answer: nothing
  in the training data shows it that level's equivalent stiffness, damping or inductance.
- ``interpolate``: fit on 1 and 10 N, predict 4 N (the easier case: the training levels bracket it).
- ``fading`` (friction only): fit on 1 and 4 N, predict 10 N, where friction has faded to ~1/10 of its
  strength and changes the response by about the sensor noise (the noise ceiling says how much any
  model could gain there).

The linear side is the best linear model (`compare_models`): m2, kp, R, L fitted in the time domain
to both training recordings together and to each alone, the one that predicts the held-out
recording best chosen on that recording (favours the linear model: the ratio is conservative).
Both models are driven by the same measured force, kept to its excited band, and judged the same
way: the headline error is where the measured response is excited (`predict`'s ``rel_error_excited``:
the bins within 20 dB of the response's in-band peak, its resonances and their flanks); elsewhere
the recording is mostly accelerometer noise that no model predicts, which caps any ratio at the
noise level. The ratios on the force's whole band (20-200 Hz here), broadband, and against the
noise-free truth (which the benchmark knows, on the same bins) are reported beside it. Coverage: the strength's 95 % interval from every
design's fit (one interval per rig and design).

Tuning: on one seed per element, `tune_nonlinear` on the fitted model over 1, 4, 10 N; its design is
simulated on the TRUE rig (satmd's integrator with the true element) and compared with the true
optimum, a 9 x 9 direct-simulation grid search on the true rig refined once; also the cost of the
low-level linear tuning on the true rig.

Usage: python benchmarks/nonlinear_model.py [--seeds 5] [--seconds 12] [--duration 16] [--elements a,b] [--no-tune]
                                           [--out PATH]
       python benchmarks/nonlinear_model.py --merge part1.json part2.json ... [--out PATH]
Writes benchmarks/results/nonlinear_model.json (or ``--out``) and prints one line of figures. A run on
some elements only should go to ``--out /tmp/...``; ``--merge`` joins such runs (one element each,
same settings) into one result, and refuses to write the results file with fewer than all elements.
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


def _strength(name, rig, rng, scale=1.0):
    """Element parameters moving the equivalent parameter by ~12 % (or ~3 N·s/m) at 10 N, times ``scale``."""
    from satmd.physics.nonlinear import response_rms

    rms = {k: float(v) for k, v in response_rms(rig, TUNE_BAND, LEVELS[-1]).items()}
    f = scale * rng.uniform(0.8, 1.25)
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
    """Error of the prediction against the noise-free truth, a1 and a2 together, judged as `predict` judges
    the recording (same samples): {"excited", "band", "broadband"}; the excited bins are the recording's."""
    from satmd.identification.nonlinear.fit import band_error, predict
    from satmd.identification.nonlinear.drive import excited_bins, valid

    p = predict(fit, rec, seconds)
    n = p["a1"].size
    k = valid(n, FS, 2.0)
    sim, ref = np.vstack([p["a1"], p["a2"]])[:, k], truth[:, :n][:, k]
    meas = np.vstack([np.asarray(rec["acc1"])[:n], np.asarray(rec["acc2"])[:n]])[:, k]
    broad = np.sqrt(np.sum((sim - ref) ** 2, axis=1) / np.sum(ref ** 2, axis=1))
    band = band_error(sim, ref, FS, p["band_hz"])
    keep = excited_bins(meas, FS, p["band_hz"])
    e = np.sum(np.abs(np.fft.rfft(sim - ref, axis=-1)) ** 2 * keep, axis=-1)
    m = np.sum(np.abs(np.fft.rfft(ref, axis=-1)) ** 2 * keep, axis=-1)
    excited = np.sqrt(e / m)
    return {k: float(np.sqrt(np.mean(v ** 2))) for k, v in (("excited", excited), ("band", band), ("broadband", broad))}


def _truth_error(rec, truth, seconds):
    """Error of the noise-free truth against the noisy recording, judged as `predict` judges a model: the
    noise floor of the comparison ({"excited", "band", "broadband"}); linear error / this is the best ratio
    any model could reach on that recording."""
    from satmd.identification.nonlinear.fit import band_error, prepare
    from satmd.identification.nonlinear.drive import excited_error, valid

    d = prepare(rec, seconds)
    n = d["acc"].shape[1]
    k = valid(n, FS, 2.0)
    ref, meas = truth[:, :n][:, k], d["acc"][:, k]
    broad = np.sqrt(np.sum((ref - meas) ** 2, axis=1) / np.sum(meas ** 2, axis=1))
    band = band_error(ref, meas, FS, d["band_hz"])
    excited = excited_error(ref, meas, FS, d["band_hz"])
    return {k: float(np.sqrt(np.mean(v ** 2))) for k, v in (("excited", excited), ("band", band), ("broadband", broad))}


def _design(name, rig, par, recs, seconds, clean, train, held):
    """One hold-out design: fit on the ``train`` levels, predict the ``held`` level."""
    from satmd.identification.nonlinear.compare import compare_models

    out = compare_models([recs[lv] for lv in train], [recs[held]], name, seconds=seconds)
    nl, lin = out.pop("fits")
    truth = {**{k: float(getattr(rig, k)) for k in ("m2", "kp", "R", "L")}, **par}
    row = [r for r in out["levels"] if r["held_out"]][0]
    lin_best = out.pop("linear_fits")[row["linear_model"]]  # the noise-free truth judges the same linear model
    vs_truth = {"linear": _clean_error(lin_best, recs[held], clean[held], seconds),
                "nonlinear": _clean_error(nl, recs[held], clean[held], seconds)}
    ratio_truth = {k: vs_truth["linear"][k] / max(vs_truth["nonlinear"][k], 1e-300) for k in ("excited", "band", "broadband")}
    # what a perfect model would score on the noisy recording: the noise-free truth itself, judged like `predict`
    noise_only = _truth_error(recs[held], clean[held], seconds)
    return {"train_levels": list(train), "held_out_level": held,
            "fitted": nl.values, "ci95": nl.ci95,
            "covered": {k: bool(nl.ci95[k][0] <= v <= nl.ci95[k][1]) for k, v in truth.items() if k in nl.ci95},
            "z": {k: float((nl.values[k] - v) / max(nl.std[k], 1e-300)) for k, v in truth.items() if k in nl.std},
            "rel_error": {k: float(nl.values[k] / v - 1) for k, v in truth.items() if k in nl.values},
            "held_out_linear_model": row["linear_model"], "band_hz": row["band_hz"],
            "held_out_td_error": row["td_error"], "held_out_ratio": row["td_ratio"],
            "held_out_td_error_band": row["td_error_band"], "held_out_ratio_band": row["td_ratio_band"],
            "held_out_td_error_broadband": row["td_error_broadband"], "held_out_ratio_broadband": row["td_ratio_broadband"],
            "held_out_error_vs_noise_free_truth": vs_truth, "held_out_ratio_vs_truth": ratio_truth,
            "held_out_error_of_the_truth": noise_only,
            "held_out_ratio_ceiling": row["td_error"]["linear"] / max(noise_only["excited"], 1e-300),
            "frf_residual": [{"level": r["level"], **r["frf_residual"]} for r in out["levels"]],
            "td_error": [{"level": r["level"], **r["td_error"]} for r in out["levels"]], "fit": nl, "compare": out}


DESIGNS = ("extrapolate", "interpolate", "fading")
FADING = ("absorber_friction",)  # equivalent damping Fc/v falls with level: the element acts most at the LOW level


def designs_for(name) -> dict:
    """{design: (training levels, held-out level)} for one element. ``extrapolate`` predicts the level where
    the element acts at its stated strength (the top level; friction's bottom one) from the two others;
    ``interpolate`` the middle level from the outer two; ``fading`` (friction only) the top level, where
    friction's effect has faded to ~1/10 of its strength, from the two lower ones."""
    strong = LEVELS[0] if name in FADING else LEVELS[-1]
    out = {"extrapolate": (tuple(lv for lv in LEVELS if lv != strong), strong),
           "interpolate": ((LEVELS[0], LEVELS[2]), LEVELS[1])}
    if name in FADING:
        out["fading"] = (LEVELS[:2], LEVELS[2])
    return out


def _fit_case(name, rig, par, recs, seconds, clean, designs=DESIGNS):
    t0 = time.perf_counter()
    out = {"truth": {**{k: float(getattr(rig, k)) for k in ("m2", "kp", "R", "L")}, **par}}
    for design, (train, held) in ((d, v) for d, v in designs_for(name).items() if d in designs):
        out[design] = _design(name, rig, par, recs, seconds, clean, train, held)
    out["seconds"] = time.perf_counter() - t0
    return out


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


RESULT = ROOT / "benchmarks" / "results" / "nonlinear_model.json"


def _dump(result, path):
    Path(path).write_text(json.dumps(result, indent=1, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o)))


def _summary(result):
    per = result["elements"]
    cov = ", ".join(f"{k} {100 * v['coverage']:.0f}%" for k, v in per.items())
    ratio = "; ".join(f"{d}: " + ", ".join(f"{k} {v[d]['held_out_ratio_min']:.1f}x ({v[d]['held_out_ratio_vs_truth_min']:.0f}x vs truth)"
                                             for k, v in per.items() if d in v) for d in DESIGNS)
    tune = ", ".join(f"{k} gap {v['tuning']['gap_to_true_optimum_db']:+.2f} dB cost {v['tuning']['cost_of_linear_tuning_db']:.2f} dB"
                     for k, v in per.items() if "tuning" in v)
    speed = result["speed"]
    print(f"coverage {cov} | held-out ratio (min) {ratio} | tuning {tune} | integrator 90 s at 2 kHz: "
          f"numba {speed.get('numba_s_90s_2048Hz', float('nan')):.2f} s, numpy {speed['numpy_s_90s_2048Hz']:.2f} s "
          f"| {result['seconds']:.0f} s | " + describe(result["machine"]))


def _figures(result, folder) -> list:
    """`satmd.report.fig_nonlinear.nonlinear_comparison_figure` for the first rig of each element (headline design)."""
    from satmd.report.fig_nonlinear import nonlinear_comparison_figure

    written = []
    for name, e in result["elements"].items():
        c = e["cases"][0]["extrapolate"]
        td = {round(r["level"], 3): r for r in c["td_error"]}
        rows = [{"level": r["level"], "held_out": abs(r["level"] - c["held_out_level"]) < 0.05 * c["held_out_level"],
                 "frf_residual": {"linear": r["linear"], "nonlinear": r["nonlinear"]},
                 "td_error": {k: td[round(r["level"], 3)][k] for k in ("linear", "nonlinear")}} for r in c["frf_residual"]]
        written.append(nonlinear_comparison_figure(rows, Path(folder) / f"nonlinear_model_{name}.png",
                                                   title=f"{name}: linear vs nonlinear model, first rig "
                                                         f"(fitted on {', '.join(f'{lv:g}' for lv in c['train_levels'])} N)"))
    return written


def _merge(paths, out):
    """One result from per-element runs: elements joined, settings checked equal, seconds summed."""
    parts = [json.loads(Path(p).read_text()) for p in paths]
    keys = ("seeds", "seconds", "duration", "no_tune", "strength")
    for p, part in zip(paths, parts):
        if any(part["settings"].get(k, 1.0) != parts[0]["settings"].get(k, 1.0) for k in keys):
            raise SystemExit(f"{p}: settings differ from {paths[0]} ({[part['settings'].get(k) for k in keys]})")
    result = {"machine": parts[0]["machine"], "settings": dict(parts[0]["settings"]), "levels": parts[0]["levels"],
              "speed": parts[0]["speed"], "elements": {}, "merged_from": [str(p) for p in paths],
              "machine_per_part": [part["machine"] for part in parts]}
    for part in parts:
        for name, e in part["elements"].items():
            if name in result["elements"]:
                raise SystemExit(f"{name} appears in more than one part")
            result["elements"][name] = e
    result["elements"] = {n: result["elements"][n] for n in indep.ELEMENTS if n in result["elements"]}  # fixed order
    result["settings"]["elements"] = ",".join(result["elements"])
    result["seconds"] = float(sum(part["seconds"] for part in parts))
    missing = [e for e in indep.ELEMENTS if e not in result["elements"]]
    if missing and Path(out).resolve() == RESULT.resolve():
        raise SystemExit(f"refusing to write {RESULT} without {missing} (a partial result): use --out")
    _dump(result, out)
    if Path(out).resolve() == RESULT.resolve():
        _figures(result, RESULT.parent)
    _summary(result)


def readme_markdown(result) -> str:
    """The README region ``nonlinear_model`` (benchmarks/readme_tables.py), from the result and silverbox.json."""
    per = result["elements"]
    st = result["settings"]
    interp = any("interpolate" in e for e in per.values())
    rows = ["| element | coefficient | rigs (intervals) | coefficient in its 95 % interval | median abs. error "
            "| held-out level where the element acts at its strength (10 N; friction 1 N) predicted from the other two: "
            "linear / nonlinear error, min (median) | a perfect model's ratio (noise ceiling), "
            "min (median) | vs noise-free truth, min | on the whole force band, min "
            + ("| held-out 4 N (interpolated), min (noise ceiling, min) " if interp else "")
            + "| tuning: gap to true optimum | cost of low-level linear tuning |",
            "|---|---|---|---|---|---|---|---|---|" + ("---|" if interp else "") + "---|---|"]
    for name, e in per.items():
        x, i = e["extrapolate"], e.get("interpolate")
        covered = sum(bool(c[d]["covered"][e["strength_parameter"]]) for c in e["cases"] for d in DESIGNS if d in c)
        n_int = sum(d in c for c in e["cases"] for d in DESIGNS)
        t = e.get("tuning")
        rows.append(
            f"| `{name}` | {e['strength_parameter']} | {len(e['cases'])} ({n_int}) | {covered}/{n_int} "
            f"({100 * covered / n_int:.0f} %) | {100 * x['median_abs_rel_error']:.2g} % "
            f"| {x['held_out_ratio_min']:.1f}× ({x['held_out_ratio_median']:.1f}×) "
            + (f"| {x['held_out_ratio_ceiling_min']:.1f}× ({x['held_out_ratio_ceiling_median']:.1f}×) "
               if "held_out_ratio_ceiling_min" in x else "| — ")
            + f"| {x['held_out_ratio_vs_truth_min']:.1f}× | {x['held_out_ratio_band_min']:.1f}× "
            + ((f"| {i['held_out_ratio_min']:.1f}× (ceiling {i['held_out_ratio_ceiling_min']:.1f}×) " if i else "| — ")
               if interp else "")
            + (f"| {t['gap_to_true_optimum_db']:+.2f} dB | {t['cost_of_linear_tuning_db']:.2f} dB |" if t else "| — | — |"))
    speed = result["speed"]
    lines = ["\n".join(rows), "",
             f"({len(next(iter(per.values()))['cases'])} rigs per element drawn at random, m2, kp, R, L and force spectrum; "
             f"{st['duration']:g} s at 2048 Hz from the independent simulator, 1 % noise on the accelerometers and "
             f"0.5 % on the force; levels {', '.join(f'{lv:g}' for lv in result['levels'])} N RMS; each fit uses the "
             f"first {st['seconds']:g} s of its two training recordings. Errors: relative RMS of predicted − measured "
             "where the measured response is excited (within 20 dB of its in-band peak), a1 and a2 together; "
             "the best linear model is the best of three linear fits (both training levels, each alone) chosen "
             "on the held-out recording itself. The noise ceiling: the linear model's error over that of the noise-free "
             "truth itself, the best ratio any model could reach on that recording (a bound: every model is driven by the "
             "measured force and carries its noise, which the noise-free truth does not). Tuning: first rig per element, "
             "R and L from the model of the headline hold-out, worst-case |U1| peak over the three levels simulated on the "
             "true rig, against a direct-simulation grid search on the true rig (9 × 9, refined once); cost: the "
             "low-level linear tuning's worst case minus the nonlinear tuning's, on the true rig.)", ""]
    fading = {n: e["fading"] for n, e in per.items() if "fading" in e}
    for name, x in fading.items():
        lines.append(f"- `{name}` at the top level, where it has faded to ~1/10 of its strength (fitted on the two lower "
                     f"levels): linear / nonlinear error {x['held_out_ratio_min']:.1f}× min "
                     f"({x['held_out_ratio_median']:.1f}× median), noise ceiling {x['held_out_ratio_ceiling_min']:.1f}× "
                     f"min, {x['held_out_ratio_vs_truth_min']:.1f}× against the noise-free truth: there the element "
                     "changes the response by about the sensor noise, and no model can show a 3× gain on that recording.")
    weak_path = RESULT.parent / "nonlinear_model_weak.json"
    if weak_path.exists():
        weak = json.loads(weak_path.read_text())
        w = weak["elements"]
        lines.append(f"- Weaker elements (strength × {weak['settings']['strength']:g}: ~5 % on kp, k1 or L, ~1.4 N·s/m on "
                     f"cp; `--strength {weak['settings']['strength']:g} --out benchmarks/results/nonlinear_model_weak.json`, "
                     f"{len(next(iter(w.values()))['cases'])} rigs per element, headline hold-out): "
                     + ", ".join(f"`{n}` {e['extrapolate']['held_out_ratio_min']:.1f}× min "
                                 f"({100 * e['coverage']:.0f} % covered)" for n, e in w.items()) + ".")
    lines.append(f"- Integrator, 90 s at 2048 Hz with a cubic spring: {speed.get('numba_s_90s_2048Hz', float('nan')):.2f} s "
                 f"compiled (numba), {speed['numpy_s_90s_2048Hz']:.2f} s numpy; whole benchmark {result['seconds'] / 60:.0f} min "
                 f"({describe(result['machine'])}).")
    sb = ROOT / "benchmarks" / "results" / "silverbox.json"
    if sb.exists():
        m = json.loads(sb.read_text())["models"]
        a = m["cubic"]["errors"]["arrow_full"]
        lag = m["cubic_lag"]["errors"]["arrow_full"]
        lines.append(f"- Silverbox arrow (`benchmarks/silverbox.py`, `silverbox.json`): linear {a['linear']['rms_mV']:.2f} mV "
                     f"({a['linear']['pct']:.1f} % of the output RMS), cubic {a['nonlinear']['rms_mV']:.3f} mV "
                     f"({a['nonlinear']['pct']:.2f} %, {a['ratio']:.0f}× lower), cubic with lag {lag['nonlinear']['rms_mV']:.3f} mV "
                     f"({lag['nonlinear']['pct']:.2f} %, {lag['ratio']:.0f}× lower); anchor: freq-statespace 13.2 % and 0.44 % "
                     "on its estimation data.")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--seconds", type=float, default=30.0, help="seconds of each recording used by the fits")
    ap.add_argument("--duration", type=float, default=40.0, help="recording length")
    ap.add_argument("--elements", default=",".join(indep.ELEMENTS))
    ap.add_argument("--no-tune", action="store_true")
    ap.add_argument("--strength", type=float, default=1.0,
                    help="scale of every element's strength (1: ~12 %% on kp, k1 or L, ~3 N·s/m on cp)")
    ap.add_argument("--designs", default=",".join(DESIGNS), help="hold-out designs, of " + ", ".join(DESIGNS))
    ap.add_argument("--out", default=str(RESULT), help="where the JSON goes (a partial run: somewhere in /tmp)")
    ap.add_argument("--merge", nargs="+", metavar="JSON", help="join per-element runs into --out and stop")
    args = ap.parse_args(argv)
    if args.merge:
        return _merge(args.merge, args.out)
    names = args.elements.split(",")
    designs = tuple(args.designs.split(","))
    if any(d not in DESIGNS for d in designs):
        raise SystemExit(f"--designs: of {', '.join(DESIGNS)}")
    if Path(args.out).resolve() == RESULT.resolve() and set(names) != set(indep.ELEMENTS):
        raise SystemExit(f"a run on {names} only would overwrite {RESULT} with a partial result: give --out")
    warnings.simplefilter("ignore")
    from satmd.physics import Rig

    result = {"machine": machine(device="cpu", threads=1), "settings": vars(args), "levels": LEVELS}
    t_all = time.perf_counter()
    result["speed"] = _speed()
    per = {}
    for name in names:
        e_i = indep.ELEMENTS.index(name)  # seeds by element, not by position: a subset reproduces the full run
        rng = np.random.default_rng(1000 + e_i)
        rigs = [Rig(m2=rng.uniform(0.4, 0.7), kp=rng.uniform(8e4, 1.5e5), R=rng.uniform(10, 60),
                    L=rng.uniform(0.04, 0.2)) for _ in range(args.seeds)]
        params = [_strength(name, r, rng, args.strength) for r in rigs]
        t0 = time.perf_counter()
        recs, clean = _recordings(name, rigs, params, args.duration, 2000 + e_i)
        sim_s = time.perf_counter() - t0
        cases = []
        for i, (rig, par) in enumerate(zip(rigs, params)):
            case = _fit_case(name, rig, par, {lv: recs[(i, lv)] for lv in LEVELS}, args.seconds,
                             {lv: clean[(i, lv)] for lv in LEVELS}, designs)
            if i == 0 and not args.no_tune:
                case["tuning"] = _tune_case(name, rig, par, case[next(d for d in designs if d in case)]["fit"])
            for design in [d for d in designs if d in case]:
                case[design].pop("fit")
                case[design].pop("compare")
                c = case[design]
                print(name, i, design, {k: round(v, 4) for k, v in c["rel_error"].items()},
                      {k: round(v, 2) for k, v in c["z"].items()},
                      "ratio excited %.1f (ceiling %.1f) band %.1f broadband %.1f (vs truth %.1f, band %.1f) [%s]" % (
                          c["held_out_ratio"], c["held_out_ratio_ceiling"], c["held_out_ratio_band"], c["held_out_ratio_broadband"],
                          c["held_out_ratio_vs_truth"]["excited"], c["held_out_ratio_vs_truth"]["band"],
                          c["held_out_linear_model"]), flush=True)
            print(name, i, "%.0f s" % case["seconds"], flush=True)
            cases.append(case)
        strength = [k for k in params[0] if k != "v0"][0]
        per[name] = {"strength_parameter": strength, "simulation_s": sim_s, "cases": cases, "n_rigs": len(cases),
                     "n_intervals": sum(d in c for c in cases for d in designs)}
        for design in [d for d in designs if d in cases[0]]:
            cs = [c[design] for c in cases]
            per[name][design] = {
                "coverage": float(np.mean([c["covered"][strength] for c in cs])),
                "coverage_all_parameters": float(np.mean([v for c in cs for v in c["covered"].values()])),
                "median_abs_rel_error": float(np.median([abs(c["rel_error"][strength]) for c in cs])),
                "z_strength": [c["z"][strength] for c in cs],
                "held_out_ratio_min": float(min(c["held_out_ratio"] for c in cs)),
                "held_out_ratio_median": float(np.median([c["held_out_ratio"] for c in cs])),
                "held_out_ratio_band_min": float(min(c["held_out_ratio_band"] for c in cs)),
                "held_out_ratio_broadband_min": float(min(c["held_out_ratio_broadband"] for c in cs)),
                "held_out_ratio_vs_truth_min": float(min(c["held_out_ratio_vs_truth"]["excited"] for c in cs)),
                "held_out_ratio_vs_truth_band_min": float(min(c["held_out_ratio_vs_truth"]["band"] for c in cs)),
                "held_out_ratio_ceiling_min": float(min(c["held_out_ratio_ceiling"] for c in cs)),
                "held_out_ratio_ceiling_median": float(np.median([c["held_out_ratio_ceiling"] for c in cs])),
                "held_out_ratio_vs_truth_broadband_min": float(min(c["held_out_ratio_vs_truth"]["broadband"] for c in cs))}
        per[name]["coverage"] = float(np.mean([c[d]["covered"][strength] for c in cases for d in designs if d in c]))
        if "tuning" in cases[0]:
            per[name]["tuning"] = cases[0]["tuning"]
            print(name, "tuning", {k: v for k, v in cases[0]["tuning"].items() if "design" not in k}, flush=True)
        result["elements"] = per
        if Path(args.out).resolve() != RESULT.resolve():
            _dump(result, args.out)  # a partial run keeps what it measured, never in the results file
    result["elements"] = per
    result["seconds"] = time.perf_counter() - t_all
    result["machine"].update(load_after())
    _dump(result, args.out)
    _summary(result)


if __name__ == "__main__":
    main()

"""Recordings benchmark: discovery and identification from lab-like time recordings, two simulators.

Recordings come from two simulators that share nothing: satmd's own
(`satmd.simulation.simulate_recording` with `satmd.simulation.conditions.lab_conditions`) and an
independent one (`benchmarks/_indep_sim.py`: SPEC §2 as ODEs integrated with
scipy.signal, its own shaker force and sensor noise). Conditions are drawn per
recording: force flat or rolled off (Butterworth order 2–8), white or pink, a
shaker resonance, excited from 5–15 Hz up to 200–500 Hz (at most 0.4 fs); sensor
noise white (0.3–10 % of RMS: low and high SNR) plus pink noise, drift and
50/60 Hz hum with harmonics; fs 1–10 kHz; 30–180 s (at most 600 000 samples);
rig anywhere in the SPEC §9 ranges. Each recording
goes through what `satmd discover REC` does (LPM estimate, discovery), less the
one-recording nonlinear test (measured by benchmarks/nonlinear.py).

1. Null recordings (nothing missing from the physics): false alarms (any physics
   effect named); hum, drift and a noise-like significant residual may only be
   `measurement` notes (the significant ones are counted apart); and how many are
   wrongly called `model_adequate` false (an in-model rig).
2. LPM std calibration: RMS of (estimate − truth)/std near each resonance
   (within 5 % of a peak of |a1| or |a2|, lowest first), near any, and
   elsewhere, per simulator and per family of conditions (`FAMILIES`); and on a targeted
   population (``--part resonant``, ``--resonant`` per simulator): null rigs drawn until they have
   three or more resonances in band (a few % of random rigs), estimate and calibration only.
3. Force-noise floor: estimated / true within a factor 1.5, or no correction.
4. The nulls → identification: coverage of the 95 % intervals per parameter.
5. Concealed single effects, per effect and simulator: found, no spurious
   effect, over the cases where the effect is detectable *at the same
   information*: on the true model on the estimate's grid with the estimate's
   std as Gaussian noise and the same noise degrees of freedom, the nominal
   model fails discover's mismatch test and the effect lowers BIC by more than
   discover's threshold (`detectable`: every case a whole FRF-path discover
   would find, and more).
6. Estimator bias at the first resonance and seconds per recording (as before).

Writes benchmarks/results/recordings.json and prints one line of figures.
Usage: python benchmarks/recordings.py [--nulls 160] [--per-effect 4] [--workers 2] [--quick]
       [--part nulls|effects|resonant] [--resonant 150] [--seed-offset N] [--out PART.json]; then
       python benchmarks/recordings.py --merge PART1.json PART2.json ... (the statistics over all parts).
Each worker runs one BLAS thread: on a shared 2-core machine multi-threaded BLAS made every small SVD of
the least-squares fits 15-40x slower (measured: 2 ms single-threaded, 30-80 ms with 2 threads under load).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before numpy: see the docstring
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))  # _indep_sim

OFFSETS = [f"parameter_offset:{p}" for p in ("m1", "k1", "c1", "cp", "e", "Cp")]
EFFECTS = ["extra_mode", "time_delay", "structural_damping", "sensor_gain", "dielectric_loss",
           "shunt_capacitance", *OFFSETS]
# what the independent ODE simulator can express exactly (hysteretic losses have no causal time-domain form)
INDEP_EFFECTS = ["extra_mode", "time_delay", "sensor_gain", "shunt_capacitance", *OFFSETS]
PARAMS = ("m2", "kp", "R", "L")
MAX_SAMPLES = 600_000


def machine_info(workers):
    import os

    from _machine import provenance

    return {"python": platform.python_version(), "platform": platform.platform(),
            "processor": platform.processor() or platform.machine(), "workers": workers,
            "load_average_1min": os.getloadavg()[0], **provenance()}


def draw_settings(rng):
    """fs, duration, SNR and lab conditions of one recording (both simulators draw the same way)."""
    from satmd.simulation.conditions import lab_conditions

    fs = float(rng.choice([1000, 2000, 2500, 4000, 5000, 8000, 10000]))
    seconds = min(float(rng.uniform(30, 180)), MAX_SAMPLES / fs)
    cond = lab_conditions(int(rng.integers(1 << 30)))
    cond["noise"] = float(np.exp(rng.uniform(np.log(0.003), np.log(0.1))))  # low and high SNR
    cond["band"] = (float(rng.uniform(5.0, 15.0)), min(float(rng.uniform(200.0, 500.0)), 0.4 * fs))
    return fs, seconds, cond


def describe(fs, seconds, cond, band):
    f, n = cond["force_spectrum"], cond["sensor_noise"]
    return {"fs_hz": fs, "duration_s": seconds, "band_hz": list(band), "noise": cond["noise"], "force_noise": cond["force_noise"],
            "rolloff_order": f.rolloff_order, "pink_force": f.colour > 0, "shaker_resonance": f.resonance_hz is not None,
            "pink": n.pink > 0, "drift": n.drift > 0, "hum": n.hum > 0}


def make_recording(sim, rng, rig, effects, seed):
    """(Recording, true FRF function, true per-bin force-noise power, conditions) from one simulator."""
    from satmd.io import Recording
    from satmd.simulation import simulate_recording
    from satmd.physics import frf

    fs, seconds, cond = draw_settings(rng)
    band = cond.pop("band")
    if sim == "satmd":
        rec = simulate_recording(seconds, fs, rig, effects, band_hz=band, seed=seed, **cond)
        floor = rec.n_samples * cond["force_noise"] ** 2  # force RMS 1 N

        def truth(freq):
            r = frf(freq, rig, effects, outputs=("a1", "a2"))
            return {"a1": r.a1, "a2": r.a2}
    else:
        import _indep_sim as ind

        p = {k: float(getattr(rig, k)) for k in ind.NOMINAL}
        eff = None if not effects else (effects[0].name, dict(effects[0].params))
        f, n = cond["force_spectrum"], cond["sensor_noise"]
        force = dict(lo=band[0], hi=band[1], rolloff=f.rolloff_order or 24, highpass=f.highpass_order or 8,
                     pink=f.colour > 0, resonance=(f.resonance_hz, 5.0, f.resonance_gain) if f.resonance_hz else None)
        noise = dict(white_acc=cond["noise"], white_force=cond["force_noise"], pink=n.pink, drift=n.drift,
                     hum=n.hum, mains=n.mains_hz)
        chans, t = ind.record(p, seconds, fs, rng, effect=eff, force=force, noise=noise)
        rec = Recording(fs, chans, {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}, {"generator": "indep"})
        clean_rms = np.std(chans["force"]) / np.sqrt(1 + cond["force_noise"] ** 2)
        floor = rec.n_samples * (cond["force_noise"] * clean_rms) ** 2

        def truth(freq):
            return ind.true_frf(freq, t["p"], t["mode"], t["Cs"], t["gains"], t["tau"])
    return rec, truth, floor, describe(fs, seconds, cond, band)


#: Families of conditions (one README table each): condition -> which null recordings it covers.
FAMILIES = {
    "force spectrum": {
        "cut sharply at the band edges": lambda r: r["rolloff_order"] == 0,
        "rolled off (Butterworth 2–8)": lambda r: r["rolloff_order"] > 0,
        "pink force": lambda r: r["pink_force"],
        "shaker resonance": lambda r: r["shaker_resonance"],
    },
    "sensor noise": {
        "white only": lambda r: not (r["pink"] or r["drift"] or r["hum"]),
        "pink": lambda r: r["pink"],
        "drift": lambda r: r["drift"],
        "mains hum 50/60 Hz + harmonics": lambda r: r["hum"],
    },
    "record": {
        "30–60 s": lambda r: r["duration_s"] < 60,
        "60–120 s": lambda r: 60 <= r["duration_s"] < 120,
        "120–180 s": lambda r: r["duration_s"] >= 120,
        "fs 1–2.5 kHz": lambda r: r["fs_hz"] <= 2500,
        "fs 4–10 kHz": lambda r: r["fs_hz"] > 2500,
    },
    "signal-to-noise": {
        "sensor noise < 1 % (high SNR)": lambda r: r["noise"] < 0.01,
        "1–5 %": lambda r: 0.01 <= r["noise"] <= 0.05,
        "> 5 % (low SNR)": lambda r: r["noise"] > 0.05,
    },
}


def calibration(data, truth):
    """Sums of |error/std|² / 2 and counts near each resonance (within 5 % of it) and elsewhere.

    Resonances are the peaks of |a1| and |a2| above a fifth of the channel's largest, peaks within 5 % of
    one another merged; ``near`` pools them, ``resonance_1``, ``resonance_2``, ... are each one (lowest
    first), ``elsewhere`` is every other point.
    """
    true = truth(data.freq_hz)
    f = data.freq_hz
    peaks = []
    for c in ("a1", "a2"):
        m = np.abs(true[c])
        peaks += [f[i] for i in range(1, m.size - 1) if m[i] >= m[i - 1] and m[i] >= m[i + 1] and m[i] > 0.2 * m.max()]
    groups = []
    for p in sorted(peaks):
        if groups and p <= 1.05 * groups[-1][-1]:
            groups[-1].append(p)
        else:
            groups.append([p])
    near = np.zeros(f.size, bool)
    masks = {}
    for j, g in enumerate(groups, start=1):
        sel = np.zeros(f.size, bool)
        for p in g:
            sel |= np.abs(f - p) <= 0.05 * p
        masks[f"resonance_{j}"] = sel & ~near  # a point near two resonances counts for the lower one
        near |= sel
    masks.update({"near": near, "elsewhere": ~near})
    out = {k: [0.0, 0] for k in masks}
    for c in data.channels:
        z2 = np.abs(data[c] - true[c]) ** 2 / (2 * data.std[c] ** 2)
        for key, sel in masks.items():
            out[key][0] += float(z2[sel].sum())
            out[key][1] += int(sel.sum())
    return out


def resonance_groups(rig, band):
    """The resonances `calibration` would see in ``band`` (|a1|, |a2| peaks above a fifth of the largest,
    merged within 5 %), on a fine grid of the true FRF: [Hz, ...]."""
    from satmd.physics import frf

    f = np.linspace(band[0], band[1], 4000)
    r = frf(f, rig, [], outputs=("a1", "a2"))
    peaks = []
    for m in (np.abs(r.a1), np.abs(r.a2)):
        peaks += [f[i] for i in range(1, m.size - 1) if m[i] >= m[i - 1] and m[i] >= m[i + 1] and m[i] > 0.2 * m.max()]
    groups: list = []
    for p in sorted(peaks):
        if groups and p <= 1.05 * groups[-1][-1]:
            groups[-1].append(p)
        else:
            groups.append([p])
    return [float(np.mean(g)) for g in groups]


def run_resonant(job):
    """A null recording of a rig with three resonances in its band (the seed is skipped otherwise: None):
    the LPM estimate's std calibration only (a few % of random rigs have a third resonance in band, too few
    points in the null population to tell a bias near it from scatter)."""
    from satmd.discovery.scenarios import random_rig
    from satmd.signal import estimate_frf

    sim, seed = job
    rng = np.random.default_rng(1000 + seed)
    rig = random_rig(rng)
    band = draw_settings(rng)[2]["band"]
    if len(resonance_groups(rig, band)) < 3:
        return None
    rng = np.random.default_rng(1000 + seed)  # the same draws again, as run_null makes them
    rig = random_rig(rng)
    rec, truth, _, cond = make_recording(sim, rng, rig, [], seed)
    return {"sim": sim, "seed": seed, **cond, "resonances_hz": resonance_groups(rig, cond["band_hz"]),
            "calibration": calibration(estimate_frf(rec), truth)}


def run_null(job):
    from satmd import discover
    from satmd.discovery.scenarios import random_rig
    from satmd.signal import estimate_frf
    from satmd.signal.lpm import excited_band

    sim, seed = job
    rng = np.random.default_rng(1000 + seed)
    rig = random_rig(rng)
    rec, truth, floor_true, cond = make_recording(sim, rng, rig, [], seed)
    t0 = time.perf_counter()
    data = estimate_frf(rec)
    rep = discover(data)
    seconds = time.perf_counter() - t0
    fit = rep.nominal_fit
    floor = excited_band(rec["force"], rec.fs_hz)[2]
    return {"sim": sim, "seed": seed, **cond, "alarm": bool(rep.effects), "significant": bool(rep.significant_mismatch),
            "adequate": bool(rep.model_adequate),
            "effects": rep.effect_names, "measurement": [m["name"] for m in rep.measurement],
            "cover": {p: bool(abs(fit.values[p] - getattr(rig, p)) <= 1.96 * fit.std[p]) for p in PARAMS},
            "chi2_reduced": rep.fit_before["chi2_reduced"], "calibration": calibration(data, truth),
            "floor_ratio": None if floor is None else floor / floor_true, "seconds": seconds}


def names_with_equivalents(report):
    return [{e.name, *getattr(e, "equivalent", [])} for e in report.effects]


def score(report, truth):
    """(all truth effects found, any spurious effect reported)."""
    found_sets = names_with_equivalents(report)
    found = all(any(t in s for s in found_sets) for t in truth)
    spurious = any(not (s & set(truth)) for s in found_sets)
    return found, spurious


def run_effect(job):
    from satmd import discover
    from satmd.discovery.scenarios import random_effect, random_rig
    from satmd.io import FRFData
    from satmd.signal import estimate_frf

    sim, name, seed = job
    rng = np.random.default_rng(5000 + seed)
    rig = random_rig(rng)
    effects = [random_effect(name, rng, np.array([40.0, 180.0]))]
    rec, truth, _, cond = make_recording(sim, rng, rig, effects, seed)
    t0 = time.perf_counter()
    data = estimate_frf(rec)
    rep = discover(data)
    seconds = time.perf_counter() - t0
    # the FRF path at the same information: true model + Gaussian noise of the estimate's std and dof
    true = truth(data.freq_hz)
    noisy = {c: true[c] + data.std[c] * (rng.standard_normal(len(data)) + 1j * rng.standard_normal(len(data)))
             for c in data.channels}
    ref = FRFData(data.freq_hz, noisy, dict(data.std), estimator={"noise_dof": data.estimator["noise_dof"]})
    found, spurious = score(rep, [name])
    return {"sim": sim, "seed": seed, "truth": [name], **cond, "found": found, "spurious": spurious,
            "reported": rep.effect_names, "measurement": [m["name"] for m in rep.measurement],
            "frf_path_found": detectable(ref, name), "seconds": seconds}


def detectable(ref, name, alpha=1e-3):
    """Whether effect ``name`` is detectable in the FRF data ``ref``: the nominal model (free m2, kp, R, L)
    fails the mismatch test that `discover` uses, and adding the effect lowers BIC by more than discover's
    threshold. Cheaper than a whole `discover` on ``ref`` and no easier: every case that discover would
    find on ``ref`` passes it, and so do cases where discover might stumble."""
    from satmd.conventions import DEFAULT_FREE
    from satmd.discovery.locate import test_mismatch
    from satmd.discovery.select import MIN_DELTA_BIC, Model, Search
    from satmd.identification import identify
    from satmd.physics import Rig

    rig, free, channels = Rig(), tuple(DEFAULT_FREE), tuple(ref.channels)
    nominal = identify(ref, rig, free, channels, warn=False)
    if not test_mismatch(nominal, alpha, ref.estimator.get("noise_dof")).significant:
        return False
    child = Search(ref, rig, free, channels, (name,)).add(Model((), [], nominal), name)
    return bool(nominal.bic - child.bic > MIN_DELTA_BIC)


def _progress(results, label):
    out = []
    for r in results:
        out.append(r)
        flag = r.get("alarm", r.get("spurious"))
        print(f"{label} {len(out)}: {r['sim']} seed {r['seed']} {'FLAG ' if flag else ''}{r.get('effects', r.get('reported'))} "
              f"{r['measurement']} {r['seconds']:.0f} s", file=sys.stderr, flush=True)
    return out


def estimator_bias():
    """Relative error at the first resonance of noise-free estimates, against a 2 %-noise std."""
    from satmd.signal import estimate_frf
    from satmd.simulation import simulate_recording
    from satmd.physics import Rig, frf

    clean = simulate_recording(120.0, 1000.0, noise=0.0, force_noise=0.0, seed=1)
    noisy = simulate_recording(120.0, 1000.0, noise=0.02, seed=1)
    out = {}
    for label, opts in (("lpm", {}), ("welch_h1_default", {"estimator": "H1"})):
        d, dn = estimate_frf(clean, **opts), estimate_frf(noisy, **opts)
        both = np.isin(d.freq_hz, dn.freq_hz)  # grids may differ by windows one estimate left out
        f, h = d.freq_hz[both], d["a1"][both]
        std = dn.std["a1"][np.isin(dn.freq_hz, f)]
        truth = frf(f, Rig(), outputs=("a1",)).a1
        i = int(np.argmax(np.abs(truth)))
        out[label] = {"freq_hz": float(f[i]), "rel_error_at_peak": float(abs(h[i] / truth[i] - 1)),
                      "bias_over_std_at_peak": float(abs(h[i] - truth[i]) / std[i]),
                      "max_bias_over_std": float(np.max(np.abs(h - truth) / std))}
    return out


def seconds_per_recording(repeats=3):
    """Median seconds of `discover(estimate_frf(rec))` on 120 s recordings at 2 kHz, in this process.

    Null recordings, and recordings with one hidden effect (an extra mode, a time delay, k1 off by 3 %):
    discovery then searches the vocabulary, which costs more than the estimate and the nominal fit.
    """
    from satmd import discover, effect
    from satmd.signal import estimate_frf
    from satmd.simulation import simulate_recording

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
    ap.add_argument("--nulls", type=int, default=160, help="null recordings per simulator")
    ap.add_argument("--per-effect", type=int, default=4, help="recordings per effect and simulator")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="10 nulls per simulator, 1 per effect, no timing")
    ap.add_argument("--timing-only", action="store_true",
                    help="rerun only the seconds-per-recording figures into an existing --out file")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "recordings.json"))
    ap.add_argument("--part", choices=("all", "nulls", "effects", "resonant"), default="all", help="run only these cases")
    ap.add_argument("--resonant", type=int, default=150,
                    help="null recordings per simulator of rigs with three resonances in band (calibration only)")
    ap.add_argument("--seed-offset", type=int, default=0, help="first seed (parts run apart do not overlap)")
    ap.add_argument("--merge", nargs="+", metavar="PART",
                    help="merge part files (their cases) into --out; a case of a later part replaces the same case "
                         "(simulator, seed, truth) of an earlier one (a rerun after a fix)")
    ap.add_argument("--effects", nargs="+", metavar="NAME", help="run only these effects")
    ap.add_argument("--sims", nargs="+", choices=("satmd", "independent"), default=["satmd", "independent"],
                    help="run only these simulators' effect cases")
    a = ap.parse_args()
    if a.quick:
        a.nulls, a.per_effect, a.resonant = 10, 1, 4
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
    if a.merge:  # the statistics over parts run separately (each with its own --seed-offset)
        parts = [json.loads(Path(f).read_text()) for f in a.merge]
        def latest(kind):
            out = {}
            for p in parts:
                for r in p["cases"].get(kind, []):
                    out[(r["sim"], r["seed"], tuple(r.get("truth", ())))] = r
            return list(out.values())

        nulls, cases, resonant = latest("nulls"), latest("effects"), latest("resonant")
        timing = next((p["timing_120s_2kHz"] for p in parts if p["timing_120s_2kHz"]["null"]["median_s"]),
                      {"null": {"median_s": None}, "hidden_effect": {"median_s": None}})
        summarise(nulls, cases, timing, a, sum(p["benchmark_seconds"] for p in parts), parts=list(a.merge),
                  resonant=resonant)
        return
    t_start = time.perf_counter()
    sims = ("satmd", "independent")
    k0 = a.seed_offset
    nulls, cases, resonant = [], [], []
    with ProcessPoolExecutor(a.workers) as pool:
        if a.part in ("all", "resonant"):  # seeds drawn until each simulator has --resonant such rigs
            for sim in sims:
                got, seed = [], k0 + 100_000
                while len(got) < a.resonant:
                    batch = [(sim, seed + i) for i in range(400)]
                    got += [r for r in pool.map(run_resonant, batch) if r is not None]
                    seed += 400
                resonant += got[:a.resonant]
            print(f"resonant nulls: {len(resonant)}", flush=True)
        if a.part in ("all", "nulls"):
            nulls = _progress(pool.map(run_null, [(sim, k0 + i) for i in range(a.nulls) for sim in sims]), "nulls")
        if a.part in ("all", "effects"):
            jobs = [("satmd", name, 100 * k + k0 + i) for k, name in enumerate(EFFECTS) for i in range(a.per_effect)]
            jobs += [("independent", name, 100 * k + k0 + i) for k, name in enumerate(INDEP_EFFECTS)
                     for i in range(a.per_effect)]
            jobs = [j for j in jobs if j[0] in a.sims and (not a.effects or j[1] in a.effects)]
            cases = _progress(pool.map(run_effect, jobs), "effects")
    timing = seconds_per_recording() if not a.quick and a.per_effect and a.part == "all" else \
        {"null": {"median_s": None}, "hidden_effect": {"median_s": None}}
    summarise(nulls, cases, timing, a, time.perf_counter() - t_start, resonant=resonant)


def summarise(nulls, cases, timing, a, seconds, parts=None, resonant=()):
    """Statistics over the cases, written to ``a.out``, and the line of figures."""
    t_start = time.perf_counter() - seconds
    sims = ("satmd", "independent")

    def rates(rows):
        det = [r for r in rows if r["frf_path_found"]]
        return {"n": len(rows), "frf_path_detects": len(det),
                "found": sum(r["found"] for r in det),
                "no_spurious": sum(not r["spurious"] for r in det),
                "found_rate": (sum(r["found"] for r in det) / len(det)) if det else None,
                "no_spurious_rate": (sum(not r["spurious"] for r in det) / len(det))
                if det else None,
                "median_seconds": float(np.median([r["seconds"] for r in rows])) if rows else None,
                "missed_or_spurious": [{"seed": r["seed"], "reported": r["reported"]} for r in det
                                       if not r["found"] or r["spurious"]]}

    def null_stats(rows):
        cal = calibration_rms(rows)
        ratios = [r["floor_ratio"] for r in rows if r["floor_ratio"] is not None]
        return {"n": len(rows), "false_alarms": sum(r["alarm"] for r in rows),
                "significant": sum(r.get("significant", r["alarm"]) for r in rows),
                "called_inadequate": sum(not r.get("adequate", True) for r in rows),
                "false_alarm_rate": float(np.mean([r["alarm"] for r in rows])) if rows else None,
                "median_chi2_reduced": float(np.median([r["chi2_reduced"] for r in rows])) if rows else None,
                "measurement_findings": sorted({m for r in rows for m in r["measurement"]}),
                "std_calibration_rms": cal,
                "floor_corrected": len(ratios),
                "floor_within_1_5": int(sum(bool(1 / 1.5 <= x <= 1.5) for x in ratios)),
                "floor_ratio_range": [float(min(ratios)), float(max(ratios))] if ratios else None}

    def calibration_rms(rows, counts=False):
        keys = sorted({"near", "elsewhere"} | {k for r in rows for k in r["calibration"]},
                      key=lambda k: (k != "near", k != "elsewhere", k))
        n = {k: sum(r["calibration"].get(k, [0, 0])[1] for r in rows) for k in keys}
        rms = {k: float(np.sqrt(sum(r["calibration"].get(k, [0, 0])[0] for r in rows) / max(n[k], 1))) for k in keys}
        return (rms, n) if counts else rms

    resonant_stats = {}
    for sim in sims:
        rows = [r for r in resonant if r["sim"] == sim]
        if rows:
            rms, n = calibration_rms(rows, counts=True)
            resonant_stats[sim] = {"n": len(rows), "std_calibration_rms": rms, "points": n}
    per_family = {fam: {cond: {sim: null_stats([r for r in nulls if r["sim"] == sim and pick(r)]) for sim in sims}
                        for cond, pick in conds.items()} for fam, conds in FAMILIES.items()}
    coverage = {p: float(np.mean([n["cover"][p] for n in nulls])) for p in PARAMS}
    per_effect = {sim: {name: rates([c for c in cases if c["sim"] == sim and c["truth"] == [name]])
                        for name in (EFFECTS if sim == "satmd" else INDEP_EFFECTS)} for sim in sims}
    result = {
        "what": "discovery and identification from lab-like recordings of two independent simulators",
        "machine": machine_info(a.workers),
        "nulls": null_stats(nulls),
        "nulls_by_simulator": {sim: null_stats([r for r in nulls if r["sim"] == sim]) for sim in sims},
        "nulls_by_family": per_family,
        "nulls_three_resonances": resonant_stats,
        "identify_coverage_95": coverage,
        "single_effects": rates(cases),
        "single_effects_by_simulator": {sim: rates([c for c in cases if c["sim"] == sim]) for sim in sims},
        "per_effect": per_effect,
        "estimator_bias": estimator_bias(),
        "seconds_per_120s_2kHz_recording": timing["null"]["median_s"],
        "timing_120s_2kHz": timing,
        "benchmark_seconds": time.perf_counter() - t_start,
        "parts": parts,
        "cases": {"nulls": nulls, "effects": cases, "resonant": list(resonant)},
    }
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(json.dumps(result, indent=1, default=float))
    nu, s1, b = result["nulls"], result["single_effects"], result["estimator_bias"]
    fmt = lambda x: "n/a" if x is None else f"{100 * x:.0f} %"  # noqa: E731
    print(f"recordings: false alarms {nu['false_alarms']}/{nu['n']} (two simulators; significant but noise-like "
          f"{nu['significant']}); std calibration RMS "
          f"near resonances {nu['std_calibration_rms']['near']:.3f}, elsewhere {nu['std_calibration_rms']['elsewhere']:.3f}; "
          f"force-noise floor within x1.5 {nu['floor_within_1_5']}/{nu['floor_corrected']} corrected "
          f"({nu['n'] - nu['floor_corrected']} not corrected); coverage "
          + " ".join(f"{p} {coverage[p]:.2f}" for p in PARAMS) + "; "
          f"single effects found {fmt(s1['found_rate'])}, no spurious {fmt(s1['no_spurious_rate'])} "
          f"(of {s1['frf_path_detects']} the FRF path detects); peak bias/std LPM "
          f"{b['lpm']['bias_over_std_at_peak']:.2f}; {time.perf_counter() - t_start:.0f} s")

if __name__ == "__main__":
    main()

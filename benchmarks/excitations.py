"""The lab's other excitations (issue 34): detection, estimate and discovery per family, two simulators.

Families (forces from `benchmarks/_indep_excitations.py`, numpy/scipy.signal only, no satmd code):
random-phase multisine (odd or full), pseudo-random (filtered noise repeated), periodic chirp, slow
single sweep, fast single sweep, hammer hits in one file, one hit per file (several files judged
together with ``satmd.discover([...])``). Per case a seeded RNG draws the rig (SPEC §9 ranges), the
sample rate (1–10 kHz), the band (lo 5–15 Hz, hi 200–500 Hz ≤ 0.4 fs), the noise (white, 0.3–5 % of
RMS on each accelerometer, 0.2–2 % on the force) and the lengths; the rig starts at rest.

Simulators. ``satmd``: the force goes through satmd's own from-rest linear convolution
(`satmd.physics.timemodel.LinearRig`, the time model of `satmd.simulate_recording`), or, for a logarithmic
upward slow sweep, `satmd.simulate_recording(excitation="sweep")` itself makes the force; truth
`satmd.physics.frf`. ``independent``: `benchmarks/_indep_sim.py` (ODEs integrated with scipy on a
grid 8x finer, its own anti-aliasing and decimation) with the same force function evaluated on its
fine grid; truth `_indep_sim.true_frf`.

Per case: the excitation kind satmd reports (``estimator.excitation.kind``; should match the family),
physics named (``report.effect_names`` non-empty), nonlinearity flagged (``report.nonlinear.detected``),
``model_adequate``, the std calibration sums Σ|err/std|²/2 and point counts near the resonances (within
``NEAR_WIDTHS`` half-power widths 2ζf of each pole with ζ < 0.1 in band) and elsewhere
(err = estimate − true FRF, std per real and imaginary part), and wall seconds. A crash is recorded
with its message, never hidden.

Concealed single effects (``--effects N`` per family and simulator): one vocabulary effect drawn as
`benchmarks/recordings.py` draws them (`satmd.discovery.scenarios.random_effect`), scored as there:
found (named or equivalent) with no spurious effect, over the cases where the effect is detectable at
the same information (`recordings.detectable`: the true model on the estimate's grid with the
estimate's std as Gaussian noise fails discover's mismatch test and the effect gains BIC > 10).

Runs in parts never overwrite each other: each run writes its own ``--out`` (rewritten after every
case, so an interrupted run keeps what it did); ``--merge PART ...`` joins parts (a case of a later
part replaces the same case — family, simulator, seed, truth — of an earlier one) into ``--out``.

Usage: python benchmarks/excitations.py [--n 3] [--effects 0] [--families ...] [--sims ...]
           [--seed-offset 0] [--budget-s S] --out benchmarks/results/excitations_partK.json
       python benchmarks/excitations.py --merge PART1.json PART2.json ... [--out benchmarks/results/excitations.json]
One process, one BLAS thread (a shared 2-core machine).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
import traceback
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # one BLAS thread
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import _indep_excitations as ex  # noqa: E402

FAMILIES = ex.FAMILIES
SIMS = ("satmd", "independent")
RESULT = ROOT / "benchmarks" / "results" / "excitations.json"
FS_CHOICES = (1000, 2000, 2500, 4000, 5000, 8000, 10000)
MAX_SAMPLES = 600_000  # per file
NEAR_WIDTHS = 3.0  # "near a resonance": within this many half-power widths of its pole
SHARP_ZETA = 0.1  # poles damped more than this make no sharp peak (their widths would cover the band)
RING_DB = 60.0  # ring-down: the slowest mode decays by this much


def rig_poles(p):
    """(f_d Hz, ζ) of the rig's modes (independent simulator's state space; the same model satmd uses)."""
    import _indep_sim as ind

    lam = np.linalg.eigvals(ind.state_space(p)[0])
    lam = lam[lam.imag > 0]
    return lam.imag / (2 * np.pi), -lam.real / np.abs(lam)


def ring_down_s(p):
    import _indep_sim as ind

    lam = np.linalg.eigvals(ind.state_space(p)[0])
    return float(RING_DB / 20 * np.log(10) / np.min(-lam.real))


def draw(family, rng, p):
    """The design of one case: fs, band, noise and the files, each (seconds, force function, info)."""
    ring = ring_down_s(p)
    if family == "slow_sweep":
        fs = float(rng.choice([1000, 2000, 2500]))
    else:
        fs = float(rng.choice(FS_CHOICES))
    band = (float(rng.uniform(5.0, 15.0)), float(min(rng.uniform(200.0, 500.0), 0.4 * fs)))
    noise = {"acc1": float(np.exp(rng.uniform(np.log(0.003), np.log(0.05)))),
             "force": float(np.exp(rng.uniform(np.log(0.002), np.log(0.02))))}
    noise["acc2"] = noise["acc1"]  # one level for both accelerometers (the independent simulator draws one)
    cap = MAX_SAMPLES / fs
    info = {"ring_down_s": ring}
    if family in ("multisine", "pseudo_random", "periodic_chirp"):
        period = float(rng.choice([1.0, 2.0, 4.0]))
        periods = int(rng.integers(6, 17))
        periods = max(4, min(periods, int(cap // period)))
        if family == "multisine":
            force, extra = ex.multisine(fs, period, band, rng, odd=bool(rng.random() < 0.5))
        elif family == "pseudo_random":
            force, extra = ex.pseudo_random(fs, period, band, rng, order=int(rng.choice([2, 4, 6])))
        else:
            force, extra = ex.periodic_chirp(fs, period, band, rng,
                                             law=str(rng.choice(["linear", "logarithmic"])))
        files = [(period * periods, force)]
        info |= {"period_s": period, "periods": periods, **extra}
    elif family in ("slow_sweep", "fast_sweep"):
        law = str(rng.choice(["linear", "logarithmic"]))
        direction = "up" if rng.random() < 0.75 else "down"
        tail = float(rng.uniform(0.5, 1.5) * ring)
        dur = float(rng.uniform(100.0, 240.0) if family == "slow_sweep" else rng.uniform(2.0, 15.0))
        dur = min(dur, cap - tail)
        force, extra = ex.sweep(dur, band, law, direction, taper_cycles=int(rng.integers(2, 10)), tail_s=tail)
        files = [(dur + tail, force)]
        f, z = rig_poles(p)
        sharp = (z < SHARP_ZETA) & (f > band[0]) & (f < band[1])
        iso = [ex.sweep_rate_at(extra, band, fr) / (0.9 * fr ** 2 * zr ** 2) for fr, zr in zip(f[sharp], z[sharp])]
        info |= {**extra, "iso7626_rate_ratio": float(max(iso)) if iso else None}
    elif family == "hits":
        count = int(rng.integers(5, 11))
        width = float(rng.uniform(max(1e-3, 5.0 / fs), 5e-3))
        shape = str(rng.choice(["half_sine", "haversine"]))
        lead = float(rng.uniform(0.2, 1.0))
        gaps = ring * rng.uniform(1.0, 1.5, count)
        times = lead + np.concatenate(([0.0], np.cumsum(gaps[:-1])))
        seconds = float(times[-1] + gaps[-1])
        heights = rng.uniform(0.7, 1.3, count)
        force, extra = ex.hits(times, heights, shape, width)
        files = [(seconds, force)]
        info |= extra
    else:  # hit_per_file
        count = int(rng.integers(3, 7))
        width = float(rng.uniform(max(1e-3, 5.0 / fs), 5e-3))
        shape = str(rng.choice(["half_sine", "haversine"]))
        # a triggered acquisition: every file the same length with the same pre-trigger
        lead = float(rng.uniform(0.05, 0.5))
        seconds = lead + float(ring * rng.uniform(1.0, 1.5))
        files, heights = [], rng.uniform(0.7, 1.3, count)
        for h in heights:
            force, extra = ex.hits([lead], [h], shape, width)
            files.append((seconds, force))
        info |= {"files": count, "shape": shape, "width_ms": 1e3 * width, "pretrigger_s": lead,
                 "file_s": seconds, "heights": [round(float(h), 4) for h in heights]}
    return fs, band, noise, files, info


def simulate(sim, family, fs, band, noise, files, info, rig, p, effects, rng, seed):
    """(list of Recording, truth function, how the force was made)."""
    from satmd.io import Recording

    units = {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}
    recs = []
    if sim == "satmd":
        from satmd.simulation import simulate_recording
        from satmd.physics.timemodel import LinearRig
        from satmd.physics import frf

        made = "convolve"
        for seconds, force in files:
            n = int(round(seconds * fs))
            if family == "slow_sweep" and info["law"] == "logarithmic" and info["direction"] == "up":
                made = "simulate_recording"  # satmd makes this force itself (log sweep over the whole record)
                info.update(sweep_s=seconds, tail_s=0.0, rate_octaves_per_s=np.log2(band[1] / band[0]) / seconds)
                f, z = rig_poles(p)
                sharp = (z < SHARP_ZETA) & (f > band[0]) & (f < band[1])
                iso = [ex.sweep_rate_at(info, band, fr) / (0.9 * fr ** 2 * zr ** 2) for fr, zr in zip(f[sharp], z[sharp])]
                info["iso7626_rate_ratio"] = float(max(iso)) if iso else None
                rec = simulate_recording(seconds, fs, rig, effects, band_hz=band, noise=noise["acc1"],
                                         force_noise=noise["force"], seed=seed, excitation="sweep")
                recs.append(rec)
                continue
            out = LinearRig(rig, effects, band[1]).respond(force(n, fs), fs)
            chans = ex.add_noise({k: out[k] for k in ("force", "acc1", "acc2")}, noise, rng)
            recs.append(Recording(fs, chans, units, {"generator": "satmd convolve"}))

        def truth(freq):
            r = frf(freq, rig, effects, outputs=("a1", "a2"))
            return {"a1": r.a1, "a2": r.a2}
        return recs, truth, made
    import _indep_sim as ind

    eff = None if not effects else (effects[0].name, dict(effects[0].params))
    saved = ind.shaker_force
    t = None
    try:
        for seconds, force in files:
            ind.shaker_force = lambda m, rate, rng_, _f=force, **_: _f(m, rate)
            chans, t = ind.record(p, seconds, fs, rng, effect=eff, force={},
                                  noise={"white_acc": noise["acc1"], "white_force": noise["force"]})
            recs.append(Recording(fs, chans, units, {"generator": "indep"}))
    finally:
        ind.shaker_force = saved

    def truth(freq):
        return ind.true_frf(freq, t["p"], t["mode"], t["Cs"], t["gains"], t["tau"])
    return recs, truth, "independent ODE"


def calibration(data, truth, p):
    """Σ|err/std|²/2 and point counts near the resonances and elsewhere (against H(iω + 1/τ) where an exponential
    window τ was applied: what the estimate says it is)."""
    f = data.freq_hz
    decay_s = (data.estimator or {}).get("window_decay_s")
    true = truth(f - 1j / (2 * np.pi * decay_s) if decay_s else f)
    fd, z = rig_poles(p)
    near = np.zeros(f.size, bool)
    for fr, zr in zip(fd, z):
        if zr < SHARP_ZETA:
            width = 2 * zr * fr / np.sqrt(1 - zr ** 2)
            near |= np.abs(f - fr) <= NEAR_WIDTHS * width
    out = {"near": [0.0, 0], "elsewhere": [0.0, 0]}
    for c in data.channels:
        z2 = np.abs(data[c] - true[c]) ** 2 / (2 * data.std[c] ** 2)
        for key, sel in (("near", near), ("elsewhere", ~near)):
            out[key][0] += float(z2[sel].sum())
            out[key][1] += int(sel.sum())
    return out


def build(job):
    """The recordings of one case: (rng, row, rig parameters, recordings, truth function); recordings None
    (and ``row["error"]`` said) when a simulator failed. Reproduces any case from its (family, sim, seed, name)."""
    from satmd.discovery.scenarios import random_effect, random_rig
    import _indep_sim as ind

    family, sim, seed, name = job
    rng = np.random.default_rng([34, FAMILIES.index(family), SIMS.index(sim), seed, 0 if name is None else 1])
    rig = random_rig(rng)
    p = {k: float(getattr(rig, k)) for k in ind.NOMINAL}
    effects = [random_effect(name, rng, np.array([40.0, 180.0]))] if name else []
    fs, band, noise, files, info = draw(family, rng, p)
    row = {"family": family, "sim": sim, "seed": seed, "truth": [name] if name else [], "fs_hz": fs,
           "band_hz": list(band), "noise": noise, "files": len(files),
           "seconds_recorded": float(sum(s for s, _ in files)), "design": info, "error": None}
    if effects:
        row["effect_params"] = {k: float(v) for k, v in effects[0].params.items()}
    t0 = time.perf_counter()
    try:
        recs, truth, made = simulate(sim, family, fs, band, noise, files, info, rig, p, effects, rng, seed)
    except Exception as exc:  # noqa: BLE001 - a crash of the simulators is recorded, not hidden
        row.update(error=f"simulation: {type(exc).__name__}: {exc}", traceback=traceback.format_exc()[-2000:])
        return rng, row, p, None, None
    row["force_made_by"] = made
    row["sim_seconds"] = time.perf_counter() - t0
    return rng, row, p, recs, truth


def run_case(job):
    """One case: (family, sim, seed, effect name or None) -> its row."""
    from satmd import discover
    from satmd.io import FRFData
    from satmd.signal import estimate_frf
    from satmd.signal.excitation import detect_excitation

    family, sim, seed, name = job
    rng, row, p, recs, truth = build(job)
    if recs is None:
        return row
    expected = ex.EXPECTED_KIND[family]
    t0 = time.perf_counter()
    try:
        file_kinds = [detect_excitation(r).kind for r in recs]
        rep = discover(recs if len(recs) > 1 else recs[0])
        row["seconds"] = time.perf_counter() - t0
    except Exception as exc:  # noqa: BLE001 - a crash of satmd is a result
        row.update(error=f"discover: {type(exc).__name__}: {exc}", traceback=traceback.format_exc()[-2000:],
                   seconds=time.perf_counter() - t0)
        return row
    exc_info = (rep.estimator or {}).get("excitation", {})
    nl = rep.nonlinear
    row.update(file_kinds=file_kinds, kind=exc_info.get("kind"), kind_ok=exc_info.get("kind") == expected,
               excitation=exc_info, method=(rep.estimator or {}).get("method"),
               effects=rep.effect_names, physics_named=bool(rep.effect_names),
               nonlinear=bool(nl is not None and nl.detected),
               nonlinear_tested=nl is not None and any(not t.not_run for t in nl.tests),
               nonlinear_tests=[t.to_dict() for t in nl.tests] if nl is not None and nl.detected else [],
               set_aside=list(nl.set_aside) if nl is not None else [],
               noise_dof=(rep.estimator or {}).get("noise_dof"),
               model_adequate=bool(rep.model_adequate), significant=bool(rep.significant_mismatch),
               measurement=[m["name"] for m in rep.measurement],
               chi2_reduced=float(rep.fit_before["chi2_reduced"]))
    data = rep.nominal_fit.data if rep.nominal_fit is not None else estimate_frf(recs[0])
    row["points"] = int(len(data))
    row["calibration"] = calibration(data, truth, p)
    if name:
        import recordings

        true = truth(data.freq_hz)
        noisy = {c: true[c] + data.std[c] * (rng.standard_normal(len(data)) + 1j * rng.standard_normal(len(data)))
                 for c in data.channels}
        ref = FRFData(data.freq_hz, noisy, dict(data.std), estimator={"noise_dof": data.estimator["noise_dof"]})
        found, spurious = recordings.score(rep, [name])
        row.update(found=bool(found), spurious=bool(spurious), frf_path_found=bool(recordings.detectable(ref, name)))
    return row


# --- statistics ---------------------------------------------------------------------------------------
def _rms(rows, key):
    s = sum(r["calibration"][key][0] for r in rows if r.get("calibration"))
    n = sum(r["calibration"][key][1] for r in rows if r.get("calibration"))
    return (float(np.sqrt(s / n)) if n else None), int(n)


def _case_rms(r):
    """(near, elsewhere) RMS of err/std of one case (None where it has no point)."""
    return tuple(float(np.sqrt(r["calibration"][k][0] / r["calibration"][k][1])) if r["calibration"][k][1] else None
                 for k in ("near", "elsewhere"))


def _median_case(rows):
    out = []
    for j in range(2):
        v = [_case_rms(r)[j] for r in rows]
        v = [x for x in v if x is not None]
        out.append(float(np.median(v)) if v else None)
    return out


def null_stats(rows):
    ok = [r for r in rows if not r["error"]]
    near, n_near = _rms(ok, "near")
    else_, n_else = _rms(ok, "elsewhere")
    return {"n": len(rows), "crashed": len(rows) - len(ok),
            "kind_right": sum(r["kind_ok"] for r in ok),
            "kinds_seen": sorted({str(r["kind"]) for r in ok}),
            "physics_named": sum(r["physics_named"] for r in ok),
            "unexplained": sum("unexplained" in r["effects"] for r in ok),
            "named": sorted({e for r in ok for e in r["effects"]}),
            "nonlinear_flagged": sum(r["nonlinear"] for r in ok),
            "nonlinear_tested": sum(r.get("nonlinear_tested", False) for r in ok),
            "called_inadequate": sum(not r["model_adequate"] for r in ok),
            "calibration_near": near, "points_near": n_near, "calibration_elsewhere": else_, "points_elsewhere": n_else,
            "median_case_calibration": _median_case(ok),
            "cases_calibration_over_2": sum(any(v is not None and v > 2 for v in _case_rms(r)) for r in ok),
            "median_seconds": float(np.median([r["seconds"] for r in ok])) if ok else None,
            "failures": [{k: r.get(k) for k in ("sim", "seed", "kind", "effects", "nonlinear", "model_adequate",
                                                 "error")}
                         for r in rows if r["error"] or not r["kind_ok"] or r["physics_named"] or r["nonlinear"]
                         or not r["model_adequate"]]}


def effect_stats(rows):
    ok = [r for r in rows if not r["error"]]
    det = [r for r in ok if r["frf_path_found"]]
    return {"n": len(rows), "crashed": len(rows) - len(ok), "kind_right": sum(r["kind_ok"] for r in ok),
            "detectable": len(det), "found": sum(r["found"] for r in det),
            "no_spurious": sum(r["found"] and not r["spurious"] for r in det),
            "nonlinear_flagged": sum(r["nonlinear"] for r in ok),
            "set_aside_for_nonlinearity": sum(r["truth"][0] in r.get("set_aside", []) for r in det),
            "misses": [{"sim": r["sim"], "seed": r["seed"], "truth": r["truth"], "reported": r["effects"],
                        "set_aside": r.get("set_aside", []), "nonlinear": r["nonlinear"]} for r in det if not r["found"] or r["spurious"]]}


def summarise(cases, settings, seconds, parts=None, machine_info=None):
    from _machine import load_after, machine

    nulls = [c for c in cases if not c["truth"]]
    eff = [c for c in cases if c["truth"]]
    result = {
        "what": "issue 34: detection, estimate and discovery per lab excitation, two simulators",
        "machine": (machine_info or machine(device="cpu", threads=1)) | load_after(),
        "settings": settings, "parts": parts,
        "by_family": {f: null_stats([c for c in nulls if c["family"] == f]) for f in FAMILIES},
        "by_family_and_simulator": {f: {s: null_stats([c for c in nulls if c["family"] == f and c["sim"] == s])
                                        for s in SIMS} for f in FAMILIES},
        "effects_by_family": {f: effect_stats([c for c in eff if c["family"] == f]) for f in FAMILIES},
        "nulls": null_stats(nulls), "effects": effect_stats(eff),
        "benchmark_seconds": seconds, "cases": cases,
    }
    return result


def line(result):
    parts = []
    for f, x in result["by_family"].items():
        if not x["n"] and not result["effects_by_family"][f]["n"]:
            continue
        cal = "/".join("—" if v is None else f"{v:.2f}" for v in (x["calibration_near"], x["calibration_elsewhere"]))
        e = result["effects_by_family"][f]
        eff = f", effects {e['no_spurious']}/{e['detectable']}" if e["n"] else ""
        parts.append(f"{f} n={x['n']} kind {x['kind_right']} physics {x['physics_named']} nl {x['nonlinear_flagged']} "
                     f"cal {cal}{eff}" + (f" CRASH {x['crashed']}" if x["crashed"] else ""))
    return "excitations: " + "; ".join(parts) + f" | {result['benchmark_seconds']:.0f} s"


def readme_markdown(result) -> str:
    """The region ``excitations`` (benchmarks/readme_tables.py, docs/results.md): the earlier probe (single and
    repeated sweeps, burst random; independent simulator, 8 null rigs each), kept as it ran. The families'
    table is the region ``excitation-families`` (`readme_tables.excitation_families`)."""
    probe = result.get("probe")
    if not probe:
        return "_The probe's results were superseded: see the table below._"
    rows = ["| excitation (independent simulator, null rigs; earlier probe) | recordings | physics named | "
            "`unexplained` | called inadequate |", "|---|---|---|---|---|"]
    for kind, x in probe["by_excitation"].items():
        named = f" ({', '.join(e for e in x['named'] if e != 'unexplained')})" if x["physics_named"] else ""
        rows.append(f"| {kind.replace('_', ' ')} | {x['n']} | {x['physics_named']}{named} | {x['unexplained']} "
                    f"| {x['called_inadequate']} |")
    return "\n".join(rows)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=3, help="null cases per family and simulator")
    ap.add_argument("--effects", type=int, default=0, help="concealed-effect cases per family and simulator")
    ap.add_argument("--families", nargs="+", choices=FAMILIES, default=list(FAMILIES))
    ap.add_argument("--sims", nargs="+", choices=SIMS, default=list(SIMS))
    ap.add_argument("--seed-offset", type=int, default=0, help="first seed (parts run apart do not overlap)")
    ap.add_argument("--budget-s", type=float, default=None, help="start no case after this many seconds")
    ap.add_argument("--out", default=None, help="result file (required unless --merge: parts never overwrite)")
    ap.add_argument("--merge", nargs="+", metavar="PART", help="join part files into --out (default the results file)")
    a = ap.parse_args(argv)
    if a.merge:
        parts = [json.loads(Path(f).read_text()) for f in a.merge]
        cases, names, seconds, probe = {}, [], 0.0, None
        for f, part in zip(a.merge, parts):
            for c in part["cases"]:
                cases[(c["family"], c["sim"], c["seed"], tuple(c["truth"]))] = c
            names += part.get("parts") or [Path(f).name]
            seconds += part.get("benchmark_seconds", 0.0)
            probe = part.get("probe") or probe
        runs = [part["machine"] for part in parts if part.get("cases") and part.get("machine")]
        result = summarise(list(cases.values()), {"merged": True}, seconds, parts=names,
                           machine_info=dict(runs[0]) if runs else None)
        result["part_machines"] = runs
        if probe:
            result["probe"] = probe
        out = Path(a.out or RESULT)
        out.write_text(json.dumps(result, indent=1, default=float))
        print(line(result))
        return
    if not a.out:
        ap.error("give --out (a part file); join parts with --merge")
    jobs = []
    for i in range(a.n + a.effects):
        seed = a.seed_offset + i
        for fam in a.families:
            for sim in a.sims:
                if i < a.n:
                    jobs.append((fam, sim, seed, None))
                else:
                    from recordings import EFFECTS, INDEP_EFFECTS

                    pool = EFFECTS if sim == "satmd" else INDEP_EFFECTS
                    k = (seed * len(FAMILIES) + FAMILIES.index(fam)) % len(pool)
                    jobs.append((fam, sim, seed, pool[k]))
    from _machine import machine

    m0 = machine(device="cpu", threads=1)
    t_start = time.perf_counter()
    cases = []
    settings = {k: v for k, v in vars(a).items() if k != "merge"}
    for job in jobs:
        if a.budget_s is not None and time.perf_counter() - t_start > a.budget_s:
            print(f"budget reached: {len(cases)}/{len(jobs)} cases run", file=sys.stderr)
            break
        row = run_case(job)
        cases.append(row)
        flag = "" if row["error"] is None else f" ERROR {row['error'][:200]}"
        if not row["error"]:
            bad = [w for w, b in (("KIND " + str(row["kind"]), not row["kind_ok"]), ("PHYSICS", row["physics_named"]),
                                  ("NONLINEAR", row["nonlinear"]), ("INADEQUATE", not row["model_adequate"])) if b]
            flag = " ".join(bad)
            cal = row["calibration"]
            flag += (f" cal {np.sqrt(cal['near'][0] / max(cal['near'][1], 1)):.2f}/"
                     f"{np.sqrt(cal['elsewhere'][0] / max(cal['elsewhere'][1], 1)):.2f}")
            if row["truth"]:
                flag += f" truth {row['truth']} reported {row['effects']} detectable {row['frf_path_found']}"
        print(f"{len(cases)}/{len(jobs)} {job[0]} {job[1]} seed {job[2]}: {row.get('effects')}{flag} "
              f"{row.get('sim_seconds', 0):.1f}+{row.get('seconds', 0):.1f} s", file=sys.stderr, flush=True)
        result = summarise(cases, settings, time.perf_counter() - t_start, machine_info=m0)
        Path(a.out).write_text(json.dumps(result, indent=1, default=float))
    print(line(result))


if __name__ == "__main__":
    main()

"""Nonlinear benchmark (issue 26): detection, false alarms, naming, Silverbox verdicts, seconds.

Recordings come from TWO simulators: satmd's own (`satmd.simulate(time=True, nonlinear=[...])`) and
an independent one written for this benchmark (`benchmarks/_indep_nl_sim.py`, RK4, shares no code
with satmd), so the tool is not only tested on its own assumptions.

1. Linear nulls: random force spectra (flat, rising, falling, notched; band edges drawn), noise
   white / pink / brown at 1–4 %, lengths drawn; judged alone (one recording) and as two levels
   20 dB apart. Reported: fraction flagged nonlinear (target ≤ 1 %).
2. Elements (SPEC §8b), each at a strength that changes its equivalent linear parameter by 5 % and
   10 % at the higher of two levels 20 dB apart (kp, k1, L relative; cp relative to its 4 N·s/m):
   detected and named from the two levels; detected from the higher level alone.
3. A few full `discover([lo, hi])` runs: no linear physics effect stands in for the nonlinearity
   (no ``parameter_offset`` of the moving parameter, no ``unexplained``), and seconds for two
   90 s recordings at 2048 Hz.
4. Silverbox (real data, /work/shared; skipped when absent): the 5-level ladder and SNLS80mV.

Writes benchmarks/results/nonlinear.json and prints one line of figures.
Usage: python benchmarks/nonlinear.py [--nulls 200] [--seeds 10] [--duration 30] [--quick]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import _indep_nl_sim as indep  # noqa: E402
from _machine import load_after, machine  # noqa: E402

FS = 2048.0
ELEMENTS = indep.ELEMENTS
SILVERBOX = Path("/work/shared/data/real/silverbox")


def _recording(force, a1, a2, noise, colour, rng):
    from satmd.io.recdata import Recording

    chans = {}
    for name, x, rel in (("force", force, noise / 2), ("acc1", a1, noise), ("acc2", a2, noise)):
        chans[name] = x + rel * np.sqrt(np.mean(x * x)) * indep.coloured_noise(x.size, rng, colour)
    return Recording(FS, chans, {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"})


def _verdict(recs, tests=None):
    from satmd.discovery.nonlinear_findings import analyse_recordings

    rep = analyse_recordings(recs)
    name = rep.findings[0]["name"] if rep.findings else None
    if tests is not None:
        tests.extend((t.name, float(t.p_value)) for t in rep.tests)
    return bool(rep.detected), name


# --- 1. nulls ----------------------------------------------------------------------------------------------
def nulls(n, seed):
    """Linear recordings from both simulators; flagged alone and as level pairs."""
    from satmd import simulate

    rng = np.random.default_rng(seed)
    out = {"single": [], "pair": []}
    half = n // 2
    # independent simulator: one batch of forces (pairs: low and high level of one rig)
    lengths = rng.choice([20, 30, 60, 90], size=half)
    for T in sorted(set(lengths.tolist())):
        idx = np.flatnonzero(lengths == T)
        n_s = int(T * FS)
        forces, meta = [], []
        for _ in idx:
            shape = str(rng.choice(["flat", "up", "down", "notch"]))
            lo, hi = float(rng.uniform(15, 30)), float(rng.uniform(160, 260))
            forces.append(indep.random_force(n_s, FS, rng, (lo, hi), shape))
            forces.append(0.1 * indep.random_force(n_s, FS, rng, (lo, hi), shape))
            meta.append((shape, lo, hi))
        a1, a2, _ = indep.simulate(np.stack(forces), FS)
        for j, (shape, lo, hi) in enumerate(meta):
            colour = str(rng.choice(["white", "pink", "brown"]))
            noise = float(rng.uniform(0.01, 0.04))
            hi_rec = _recording(forces[2 * j], a1[2 * j], a2[2 * j], noise, colour, rng)
            lo_rec = _recording(forces[2 * j + 1], a1[2 * j + 1], a2[2 * j + 1], noise, colour, rng)
            case = {"sim": "independent", "T": int(T), "shape": shape, "colour": colour, "noise": noise, "band": [lo, hi]}
            t1, t2 = [], []
            out["single"].append(case | {"flagged": _verdict([hi_rec], t1)[0], "tests": t1})
            out["pair"].append(case | {"flagged": _verdict([lo_rec, hi_rec], t2)[0], "tests": t2})
            _show(out)
    # satmd's simulator (linear): its own force and white noise, then extra coloured noise
    for k in range(n - half):
        T = float(rng.choice([20, 30, 60, 90]))
        colour = str(rng.choice(["white", "pink", "brown"]))
        noise = float(rng.uniform(0.01, 0.04))
        band = (float(rng.uniform(15, 30)), float(rng.uniform(160, 260)))
        recs = []
        for level in (0.1, 1.0):
            r = simulate(time=True, level=level, duration_s=T, fs_hz=FS, band_hz=band, noise=0.0,
                         seed=int(rng.integers(1 << 30)))
            recs.append(_recording(r["force"], r["acc1"], r["acc2"], noise, colour, rng))
        case = {"sim": "satmd", "T": T, "colour": colour, "noise": noise, "band": list(band)}
        t1, t2 = [], []
        out["single"].append(case | {"flagged": _verdict([recs[1]], t1)[0], "tests": t1})
        out["pair"].append(case | {"flagged": _verdict(recs, t2)[0], "tests": t2})
        _show(out)
    return out


def _show(out):
    """Print a flagged null as it happens (the false alarms are what one wants to read)."""
    for kind in ("single", "pair"):
        c = out[kind][-1]
        if c["flagged"]:
            print(f"  null flagged ({kind}): {json.dumps(c)}", flush=True)


# --- 2. elements -------------------------------------------------------------------------------------------
def _satmd_element(kind, target, level_rms):
    """A satmd element at a strength changing its parameter by ``target`` at the signals' RMS."""
    from satmd.physics.nonlinear import element

    states = np.array([[level_rms[k] for k in ("d", "u1", "v", "i")]])
    par = indep.strength_for(kind, target, _as_states(states))
    if kind == "absorber_friction":
        return element(kind, Fc=float(par[0]), v0=float(par[1]))
    name = {"cubic_absorber_spring": "k3", "cubic_host_spring": "k3", "quadratic_damping": "c2",
            "inductor_saturation": "isat"}[kind]
    return element(kind, **{name: float(par)})


def _as_states(rms_row):
    """Fake (n, 4) samples with the given standard deviations (for `strength_for`)."""
    return np.array([rms_row[0], -rms_row[0]])


def elements(seeds, targets, duration, seed, kinds=ELEMENTS):
    """Detection and naming per element, strength and simulator."""
    from satmd import simulate
    from satmd.physics import Rig
    from satmd.physics.nonlinear import response_rms

    n_s = int(duration * FS)
    rows = []
    rms_hi = response_rms(Rig(), band_hz=(20.0, 200.0), force_rms=1.0)
    for kind in kinds:
        rng = np.random.default_rng([seed, ELEMENTS.index(kind)])  # each element its own forces, run alone or not
        # independent simulator: all seeds and targets of this element in one batch
        forces, cases = [], []
        for target in targets:
            for s in range(seeds):
                f_hi = indep.random_force(n_s, FS, rng, (20.0, 200.0), "flat")
                f_lo = 0.1 * indep.random_force(n_s, FS, rng, (20.0, 200.0), "flat")
                forces += [f_lo, f_hi]
                cases.append((target, s))
        lin = indep.simulate(np.stack(forces[1::2][:1]), FS)[2][0]
        pars = {t: indep.strength_for(kind, t, lin) for t in targets}
        par_rows = [pars[t] for t, _ in cases for _ in (0, 1)]
        a1, a2, _ = _batch_by_param(kind, np.stack(forces), par_rows)
        for j, (target, s) in enumerate(cases):
            colour = str(rng.choice(["white", "pink", "brown"]))
            recs = [_recording(forces[2 * j + i], a1[2 * j + i], a2[2 * j + i], 0.02, colour, rng) for i in (0, 1)]
            det2, name2 = _verdict(recs)
            p1 = []
            det1, _ = _verdict([recs[1]], p1)
            det1_lo, _ = _verdict([recs[0]])
            rows.append({"sim": "independent", "element": kind, "target": target, "seed": s, "T": duration,
                         "colour": colour, "detected_two": det2, "named": name2, "detected_one_high": det1,
                         "p_one_high": min(p for _, p in p1), "detected_one_low": det1_lo})
        # satmd's simulator: fewer seeds (it is the tool's own model)
        for target in targets:
            el = _satmd_element(kind, target, {k: float(v) for k, v in rms_hi.items()})
            for s in range(max(1, seeds // 2)):  # satmd's integrator is slower: half the seeds
                recs = [simulate(time=True, nonlinear=[el], level=level, duration_s=duration, fs_hz=FS, noise=0.02,
                                 seed=int(rng.integers(1 << 30))) for level in (0.1, 1.0)]
                det2, name2 = _verdict(recs)
                p1 = []
                det1, _ = _verdict([recs[1]], p1)
                det1_lo, _ = _verdict([recs[0]])
                rows.append({"sim": "satmd", "element": kind, "target": target, "seed": s, "T": duration,
                             "detected_two": det2, "named": name2, "detected_one_high": det1,
                             "p_one_high": min(p for _, p in p1), "detected_one_low": det1_lo})
        print(f"  {kind}: done", flush=True)
    return rows


def _batch_by_param(kind, forces, par_rows):
    """The independent simulator with a per-run element parameter."""
    if kind == "absorber_friction":
        par = (np.array([p[0] for p in par_rows]), np.array([p[1] for p in par_rows]))
    else:
        par = np.array(par_rows, float)
    return indep.simulate(forces, FS, kind, par)


# --- 3. full discover ----------------------------------------------------------------------------------------
def full_discover(duration, seed, kinds=(None,) + ELEMENTS):
    """discover([lo, hi]) end to end per element (independent simulator): effects, nonlinear block, seconds."""
    from satmd import discover

    rng = np.random.default_rng(seed)
    n_s = int(duration * FS)
    out = []
    for kind in kinds:
        f_hi = indep.random_force(n_s, FS, rng, (20.0, 200.0), "flat")
        f_lo = 0.1 * indep.random_force(n_s, FS, rng, (20.0, 200.0), "flat")
        par = None
        if kind:
            lin = indep.simulate(f_hi[None, : int(10 * FS)], FS)[2][0]
            par = indep.strength_for(kind, 0.10, lin)
        a1, a2, _ = indep.simulate(np.stack([f_lo, f_hi]), FS, kind, par)
        recs = [_recording([f_lo, f_hi][i], a1[i], a2[i], 0.02, "white", rng) for i in (0, 1)]
        t0 = time.perf_counter()
        rep = discover(recs)
        sec = time.perf_counter() - t0
        nl = rep.nonlinear
        out.append({"element": kind, "seconds": sec, "duration_s": duration, "effects": rep.effect_names, "detected": nl.detected,
                    "named": nl.findings[0]["name"] if nl.findings else None,
                    "set_aside": list(nl.set_aside)})
        print(f"  discover {kind}: {sec:.1f} s, effects {rep.effect_names}, named {out[-1]['named']}", flush=True)
    return out


# --- 4. Silverbox ---------------------------------------------------------------------------------------------
def silverbox():
    """The verdicts on the real Silverbox data (None when /work/shared is absent)."""
    if not SILVERBOX.exists():
        return None
    from satmd.discovery.nonlinear_silverbox import silverbox_verdicts

    t0 = time.perf_counter()
    out = silverbox_verdicts(SILVERBOX)
    out["seconds"] = time.perf_counter() - t0
    return out


def _save(path, result):
    """Write what is measured so far (a long run keeps its finished parts)."""
    path.write_text(json.dumps(result, indent=1, default=float))


def _rate(rows, key, **where):
    sel = [r for r in rows if all(r[k] == v for k, v in where.items())]
    return (sum(bool(r[key]) for r in sel) / len(sel)) if sel else float("nan"), len(sel)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nulls", type=int, default=200)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--duration", type=float, default=30.0)
    ap.add_argument("--discover-duration", type=float, default=90.0)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--elements", default=",".join(ELEMENTS), help="elements of part 2 (comma-separated)")
    ap.add_argument("--parts", default="silverbox,nulls,elements,discover,timing")
    args = ap.parse_args(argv)
    if args.quick:
        args.nulls, args.seeds, args.duration, args.discover_duration = 20, 2, 20.0, 30.0
    parts = set(args.parts.split(","))
    path = ROOT / "benchmarks" / "results" / "nonlinear.json"
    result = json.loads(path.read_text()) if path.exists() else {}
    result["machine"] = machine(device="cpu", threads=1)
    t0 = time.perf_counter()
    if "silverbox" in parts:
        result["silverbox"] = silverbox()
        print("silverbox:", (result["silverbox"] or {}).get("summary"), flush=True)
        _save(path, result)
    if "nulls" in parts:
        nl = nulls(args.nulls, 1)
        result["nulls"] = {"n": len(nl["single"]),
                           "single_rate": float(np.mean([c["flagged"] for c in nl["single"]])),
                           "pair_rate": float(np.mean([c["flagged"] for c in nl["pair"]])), "cases": nl}
        print(f"nulls: {result['nulls']['single_rate']:.3f} alone, {result['nulls']['pair_rate']:.3f} pairs", flush=True)
        _save(path, result)
    if "elements" in parts:
        targets = (0.05, 0.10)
        kinds = tuple(args.elements.split(","))
        key = "elements" if args.duration == 30 else f"elements_{args.duration:g}s"
        rows = elements(args.seeds, targets, args.duration, 2, kinds)
        # a run of some elements keeps the rows of the others (long tables are run in parts)
        rows = [r for r in (result.get(key) or {}).get("rows", []) if r["element"] not in kinds] + rows
        kinds = tuple(k for k in ELEMENTS if any(r["element"] == k for r in rows))
        table = []
        for kind in kinds:
            for target in targets:
                for sim in ("independent", "satmd"):
                    det, n = _rate(rows, "detected_two", element=kind, target=target, sim=sim)
                    sel = [r for r in rows if r["element"] == kind and r["target"] == target and r["sim"] == sim]
                    named = sum(r["named"] == kind for r in sel) / max(len(sel), 1)
                    one, _ = _rate(rows, "detected_one_high", element=kind, target=target, sim=sim)
                    one_lo, _ = _rate(rows, "detected_one_low", element=kind, target=target, sim=sim)
                    table.append({"element": kind, "target": target, "sim": sim, "n": n, "detected_two": det,
                                  "named": named, "detected_one_high": one, "detected_one_low": one_lo,
                                  "T": args.duration})
        result[key] = {"table": table, "rows": rows, "duration_s": args.duration}
        print("elements:", *(f"{r['element'][:12]}@{r['target']:.2f}/{r['sim'][:3]} det {r['detected_two']:.2f} "
                             f"named {r['named']:.2f} one {r['detected_one_high']:.2f}" for r in table), sep="\n  ")
        _save(path, result)
    if "discover" in parts:
        result["discover"] = {"duration_s": args.duration, "cases": full_discover(args.duration, 3)}
        _save(path, result)
    if "timing" in parts:  # the figure: two 90 s recordings at 2 kHz
        result["timing"] = {"duration_s": args.discover_duration,
                            "cases": full_discover(args.discover_duration, 4, (None, "cubic_absorber_spring"))}
    result["benchmark_seconds"] = time.perf_counter() - t0
    result["machine"].update(load_after())
    path.write_text(json.dumps(result, indent=1, default=float))
    print(f"wrote {path} in {result['benchmark_seconds']:.0f} s")


def readme_markdown(result) -> str:
    """README region ``nonlinear`` from benchmarks/results/nonlinear.json."""
    lines = []
    nl = result.get("nulls")
    if nl:
        lengths = sorted({c["T"] for c in nl["cases"]["single"]})
        lines.append(f"- Linear nulls ({nl['n']} rigs, half from each simulator; random force spectra and band "
                     f"edges, white/pink/brown noise at 1–4 %, {', '.join(f'{t:g}' for t in lengths)} s at 2048 Hz): "
                     f"flagged nonlinear {100 * nl['single_rate']:.1f} % judged alone, {100 * nl['pair_rate']:.1f} % "
                     f"as two levels 20 dB apart (target ≤ 1 %).")
    for key in sorted(k for k in result if k.startswith("elements")):
        el = result[key]
        lines += ["", "| element | change at the higher level | simulator | n | detected (2 levels) | named | "
                  "detected (higher level alone) | (lower level alone) |", "|---|---|---|---|---|---|---|---|"]
        for r in el["table"]:
            lines.append(f"| `{r['element']}` | {100 * r['target']:.0f} % | {r['sim']} | {r['n']} | "
                         f"{100 * r['detected_two']:.0f} % | {100 * r['named']:.0f} % | "
                         f"{100 * r['detected_one_high']:.0f} % | {100 * r['detected_one_low']:.0f} % |")
        lines.append(f"\n({el['duration_s']:g} s per recording at 2048 Hz, 2 % noise, white or pink; the change is "
                     "the element's equivalent linear value at the higher level, relative to kp, k1, L, and to "
                     "cp = 4 N·s/m for the dampers; the lower level is 20 dB down.)\n")
    dc = result.get("discover")
    if dc:
        bad = [c for c in dc["cases"] if c["element"] and (c["named"] != c["element"] or any(
            e == "unexplained" or e.startswith("parameter_offset") for e in c["effects"]))]
        lines.append(f"- `discover([low, high])` end to end, independent simulator, two {dc['duration_s']:g} s "
                     f"recordings per element at 10 %: linear `effects` "
                     + "; ".join(f"{c['element'] or 'linear rig'}: {c['effects'] or 'none'}" for c in dc["cases"])
                     + f"; wrong names or linear effects standing in for the nonlinearity: {len(bad)} of "
                     f"{sum(1 for c in dc['cases'] if c['element'])}.")
    tm = result.get("timing")
    if tm:
        m = result.get("machine", {})
        lines.append(f"- Seconds for `discover([low, high])` on two {tm['duration_s']:g} s recordings at 2048 Hz: "
                     + ", ".join(f"{c['seconds']:.1f} s ({c['element'] or 'linear rig'})" for c in tm["cases"])
                     + f" (one process; load average {(m.get('load_average_1_5_15_before') or [float('nan')])[0]:.1f} "
                     f"on {m.get('cpu_count', '?')} cores when the run started).")
    sb = result.get("silverbox")
    if sb:
        lines.append(f"- Silverbox (measured): {sb['summary']}")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()

"""Benchmark: how resonances move with level on structures the SATMD model cannot describe (issue 35).

Recordings come from an independent simulator (`benchmarks/_indep_structures.py`, numpy/scipy only, no
code shared with satmd): chains of 2–6 masses, beams and plates (first 4 modes, modal superposition) with one
nonlinear joint, simulated in time from rest (RK4 at 8× the sample rate, anti-alias filter, decimation,
noise on every channel), measured at 2, 3 or 5 force levels spanning 20 dB, under a random
(non-periodic) or a periodic multisine force. Each rig's recordings go through
`satmd.discover([rec_1, ..., rec_L])` as a user's would.

Scored: the ``nonlinear_unexplained`` finding's ``modes`` entry of the mode the joint moves most (the
in-band mode with the largest relative stiffness sensitivity (w·φ)²/ω² to the joint, mass-normalised
shapes; matched by its frequency at the lowest level, within 4 % and nearer to it than to any other mode):

- ``trend`` (frequency, lowest → highest level). The lowest level is 20 dB below the highest, where
  every joint acts as its small-amplitude linearisation (the cubic term is 1 % of its top-level effect,
  the gap stays open: its clearance is ≥ 8 RMS of δ there, the friction joint sticks: δ's RMS is
  ≤ 0.12 of the slip displacement); at the highest level the joint's equivalent stiffness has moved:
  ``hardening`` cubic (k3 > 0) → ``hardening``; ``softening`` cubic (k3 < 0, tangent stiffness positive
  over the whole record) → ``softening``; ``gap`` (clearance 0.8–1.3 RMS of δ at the top level: the
  contact spring engages part of the time, so the equivalent stiffness only grows) → ``hardening``;
  ``friction`` (a Jenkins element: joint stiffness in series with a slider, in parallel with the linear
  spring; δ's RMS at the top level 0.5–1.2 of the slip displacement) → ``softening``: the slider slips,
  and the joint's stiffness is lost part of each cycle.
- ``damping_trend``, where the joint type fixes it: ``friction`` → ``rising`` (stuck, the joint
  dissipates nothing; slipping, every loop dissipates ∝ F_s (a − x_s), which at the top level's amplitudes
  (below ~2 slip displacements, where a Jenkins element's loss factor peaks) outweighs the frequency's
  rise of c/2mω by far; from the lowest to the highest level the equivalent damping can only rise). The
  elastic joints (cubic, gap) add no dissipation: their modal viscous damping ratio falls with the
  frequency's rise (c/2mω, a few %), while the spread of amplitudes of a random or multisine response
  widens the best linear approximation's resonance; which wins is not fixed by the joint type, so their
  damping trend is reported and not scored.
- no SATMD element named (no finding but ``nonlinear_unexplained``, no linear effect).

Nulls: the same structures, seeds and forces with the joint replaced by its small-amplitude stiffness:
no resonance may be reported as moving, and no SATMD element named.

The force band is 8–64 Hz, a ratio of 8: on a multisine spanning more than about a decade (5–100 Hz was
tried first) satmd's excited-line detection (`satmd.signal.excitation.excited_lines`, its lone-line filter
on relative gaps) leaves out the lowest excited lines, which the distortion test then reads as
detection lines full of response: linear nulls were flagged nonlinear. Reported as a defect; the band
keeps the benchmark on what issue 35 measures.

Issue targets: trends right in ≥ 95 % of ≥ 100 rigs; nulls: no resonance moving in ≥ 99 %.
Writes benchmarks/results/structures_levels.json (``--out``; parts with ``--seed0`` then ``--merge``)
and prints one line of figures.

Usage: python benchmarks/structures_levels.py [--rigs 30] [--seed0 0] [--out PATH]
       python benchmarks/structures_levels.py --merge part1.json part2.json [--out PATH]
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

import _indep_structures as sim  # noqa: E402
from _machine import describe, load_after, machine  # noqa: E402

OUT = ROOT / "benchmarks" / "results" / "structures_levels.json"
LEVEL_COUNTS = (2, 3, 5)
EXCITATIONS = ("random", "periodic")
UNEXPLAINED = "nonlinear_unexplained"
MATCH = 0.04


def plan(n_per_joint: int, seed0: int, excitations=EXCITATIONS) -> list:
    """(seed, joint, excitation, levels) per rig: excitations alternate, level counts cycle; a part (``seed0``
    a multiple of 100) continues the cycle where the part before it, of as many rigs, left it, so that parts of
    3 rigs still meet every (force, level count) pair: periodic forces at 2 and 5 levels, random ones at 3."""
    out = []
    for a, joint in enumerate(sim.JOINTS):
        for i in range(n_per_joint):
            k = i + n_per_joint * (seed0 // 100)
            out.append((seed0 + 1000 * (a + 1) + i, joint, excitations[k % len(excitations)], LEVEL_COUNTS[k % 3]))
    return out


def recordings(levels):
    from satmd.io.recording import Recording

    return [Recording(sim.FS, {k: np.asarray(v) for k, v in lv.items()},
                      {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}, {"generator": "indep_structures"})
            for lv in levels]


def judge(rig, recs) -> dict:
    """`satmd.discover` on the rig's levels, read against the truth."""
    import satmd

    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            rep = satmd.discover(recs)
        except Exception as exc:  # noqa: BLE001 - a crash is a result to report
            return {"error": f"{type(exc).__name__}: {exc}", "seconds": time.perf_counter() - t0}
    seconds = time.perf_counter() - t0
    nl = rep.nonlinear
    findings = list(nl.findings) if nl is not None else []
    names = [f["name"] for f in findings]
    modes = [m for f in findings for m in (f.get("modes") or [])]
    named = [n for n in names if n not in (UNEXPLAINED, "joint")] + list(rep.effect_names)  # a joint is no SATMD element
    res = {"seconds": seconds, "model_adequate": bool(rep.model_adequate),
           "detected": bool(nl.detected) if nl is not None else False, "findings": names, "named": named,
           "moving": [{"f_hz": [round(x, 4) for x in m["f_hz"]], "zeta": [round(x, 5) for x in m["zeta"]],
                       "trend": m["trend"], "damping_trend": m["damping_trend"]} for m in modes]}
    if rig.joint is None:
        res["clean"] = not modes and not named
        return res
    lo = int(np.argmin(rig.levels))
    ft = rig.f_target
    others = np.delete(rig.f_modes, rig.target)
    room = min(MATCH, 0.5 * float(np.min(np.abs(others / ft - 1)))) if others.size else MATCH
    near = [m for m in modes if abs(m["f_hz"][lo] / ft - 1) <= room]
    hit = min(near, key=lambda m: abs(m["f_hz"][lo] / ft - 1)) if near else None
    got_t = hit["trend"] if hit else "none"
    got_d = hit["damping_trend"] if hit else "none"
    want_d = rig.expected.get("damping_trend")
    res.update({"trend": got_t, "damping_trend": got_d, "matched": hit is not None,
                "trend_right": got_t == rig.expected["trend"],
                "damping_right": None if want_d is None else got_d == want_d,
                "others_moving": len(modes) - (hit is not None)})
    res["right"] = res["trend_right"] and res["damping_right"] is not False and not named
    return res


def run(n_per_joint: int, seed0: int, duration_s: float, batch_rows: int = 96, log=print,
        excitations=EXCITATIONS) -> list:
    """Every rig of the plan and its null: simulated in batches, judged one by one."""
    rigs = []
    for seed, joint, exc, nl in plan(n_per_joint, seed0, excitations):
        rigs.append(sim.make_rig(seed, joint, exc, nl, duration_s))
        rigs.append(sim.make_rig(seed, None, exc, nl, duration_s, like=joint))
    cases = []
    by_dur: dict = {}
    for r in rigs:
        by_dur.setdefault(r.duration_s, []).append(r)
    for group in by_dur.values():
        start = 0
        while start < len(group):
            batch, rows = [], 0
            while start < len(group) and (not batch or rows + len(group[start].levels) <= batch_rows):
                batch.append(group[start])
                rows += len(group[start].levels)
                start += 1
            t0 = time.perf_counter()
            records, info = simulate_stable(batch)
            log(f"  simulated {len(batch)} rigs ({rows} records) in {time.perf_counter() - t0:.0f} s")
            for rig, recs, inf in zip(batch, records, info):
                res = judge(rig, recordings(recs))
                cases.append({"rig": rig.describe(), "sim": inf, "result": res})
                log(f"  {rig.joint or 'null(' + rig.expected['like'] + ')':>16} {rig.name:>10} {rig.excitation:>8} "
                    f"L{len(rig.levels)} f_t {rig.f_target:6.2f}: "
                    + (f"trend {res.get('trend')}/{res.get('damping_trend')} right={res.get('right')}"
                       if rig.joint else f"clean={res.get('clean')} detected={res.get('detected')}")
                    + f" named={res.get('named')} moving={len(res.get('moving', []))} {res['seconds']:.1f} s"
                    + (f" ERROR {res['error']}" if "error" in res else ""))
    return cases


def simulate_stable(batch):
    """Simulate; softening rigs whose joint lost its tangent stiffness are simulated again with k3 halved."""
    scale = [1.0] * len(batch)
    records, info = sim.simulate(batch)
    for _ in range(3):
        redo = [i for i, inf in enumerate(info) if not (inf["stable"] and inf["finite"])]
        if not redo:
            break
        for i in redo:
            scale[i] *= 0.5
            batch[i].par["k3"] *= 0.5
        sub_rec, sub_info = sim.simulate([batch[i] for i in redo])
        for j, i in enumerate(redo):
            records[i], info[i] = sub_rec[j], dict(sub_info[j], k3_halved=int(round(-np.log2(scale[i]))))
    return records, info


def summarise(cases) -> dict:
    """Rates per joint, per excitation and per level count; nulls."""
    joint = [c for c in cases if c["rig"]["joint"]]
    nulls = [c for c in cases if not c["rig"]["joint"]]
    kinds = [e for e in ("random", "periodic", "sweep") if any(c["rig"]["excitation"] == e for c in cases)]
    structures = [k for k in ("chain", "beam", "plate") if any(_structure(c) == k for c in joint)]

    def rates(sel):
        n = len(sel)
        res = [c["result"] for c in sel]
        scored_d = [r for r in res if r.get("damping_right") is not None]
        return {"n": n, "trend_right": sum(bool(r.get("trend_right")) for r in res),
                "damping_scored": len(scored_d), "damping_right": sum(bool(r["damping_right"]) for r in scored_d),
                "right": sum(bool(r.get("right")) for r in res), "named": sum(bool(r.get("named")) for r in res),
                "errors": sum("error" in r for r in res),
                "damping_seen": {k: sum(r.get("damping_trend") == k for r in res)
                                 for k in ("rising", "falling", "none")}}

    def null_rates(sel):
        res = [c["result"] for c in sel]
        return {"n": len(res), "clean": sum(bool(r.get("clean")) for r in res),
                "detected": sum(bool(r.get("detected")) for r in res), "named": sum(bool(r.get("named")) for r in res),
                "errors": sum("error" in r for r in res)}

    out = {"joints": rates(joint), "nulls": null_rates(nulls),
           "per_joint": {j: rates([c for c in joint if c["rig"]["joint"] == j]) for j in sim.JOINTS},
           "per_excitation": {e: rates([c for c in joint if c["rig"]["excitation"] == e]) for e in kinds},
           "per_levels": {str(k): rates([c for c in joint if len(c["rig"]["levels_n_rms"]) == k])
                          for k in LEVEL_COUNTS},
           "nulls_per_excitation": {e: null_rates([c for c in nulls if c["rig"]["excitation"] == e])
                                    for e in kinds},
           "per_structure": {k: rates([c for c in joint if _structure(c) == k]) for k in structures},
           "nulls_per_levels": {str(k): null_rates([c for c in nulls if len(c["rig"]["levels_n_rms"]) == k])
                                for k in LEVEL_COUNTS},
           "seconds_per_discover_median": float(np.median([c["result"]["seconds"] for c in cases])) if cases else None}
    return out


def _structure(case) -> str:
    """chain, beam or plate, from the rig's name (chain4, beam-ss, plate)."""
    name = case["rig"]["name"]
    return "chain" if name.startswith("chain") else "beam" if name.startswith("beam") else name


def _commit() -> str | None:
    """The satmd commit the benchmark runs (None outside a git checkout)."""
    import subprocess

    try:
        out = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None


def merge(paths, out: Path) -> None:
    """Join partial runs (their cases, by seed and joint) into ``out``."""
    cases, runs = {}, []
    for p in paths:
        part = json.loads(Path(p).read_text())
        for c in part["cases"]:
            cases[(c["rig"]["seed"], c["rig"]["joint"], c["rig"]["expected"].get("like"))] = c
        runs.append({"file": Path(p).name, "seconds": part.get("benchmark_seconds"), "machine": part.get("machine"),
                     "settings": part.get("settings")})
    allc = sorted(cases.values(), key=lambda c: (c["rig"]["joint"] or "~", c["rig"]["seed"]))
    result = {"summary": summarise(allc), "cases": allc, "runs": runs,
              "benchmark_seconds": float(sum(r["seconds"] or 0.0 for r in runs)),
              "machine": runs[-1]["machine"], "settings": runs[-1]["settings"]}
    out.write_text(json.dumps(result, indent=1))
    print(line(result) + f" -> {out}")


def line(result) -> str:
    s = result["summary"]
    j, n = s["joints"], s["nulls"]
    per = ", ".join(f"{k} {v['right']}/{v['n']}" for k, v in s["per_joint"].items())
    return (f"structures_levels: joints right {j['right']}/{j['n']} (frequency trend {j['trend_right']}/{j['n']}, "
            f"damping {j['damping_right']}/{j['damping_scored']}; {per}); SATMD element named {j['named']}; "
            f"nulls clean {n['clean']}/{n['n']} (detected {n['detected']}, named {n['named']}); "
            f"{result['benchmark_seconds']:.0f} s")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rigs", type=int, default=30, help="rigs per joint (each with its null)")
    ap.add_argument("--seed0", type=int, default=0)
    ap.add_argument("--duration", type=float, default=64.0, help="record length [s] (periodic: whole periods)")
    ap.add_argument("--out", type=Path, default=OUT)
    ap.add_argument("--merge", nargs="+", default=None, help="merge these partial results into --out and stop")
    ap.add_argument("--excitations", default=",".join(EXCITATIONS),
                    help="forces the rigs cycle through: random, periodic, sweep (default random,periodic)")
    args = ap.parse_args(argv)
    excitations = tuple(e.strip() for e in args.excitations.split(",") if e.strip())
    if args.merge:
        merge(args.merge, args.out)
        return 0
    info = machine(device="cpu", threads=1)
    t0 = time.perf_counter()
    cases = run(args.rigs, args.seed0, args.duration, excitations=excitations)
    info.update(load_after())
    result = {"summary": summarise(cases), "cases": cases, "benchmark_seconds": time.perf_counter() - t0,
              "machine": info, "settings": {"rigs_per_joint": args.rigs, "seed0": args.seed0,
                                            "duration_s": args.duration, "fs_hz": sim.FS, "oversampling": sim.OVER,
                                            "band_hz": list(sim.BAND), "level_span": sim.SPAN,
                                            "excitations": list(excitations), "satmd_commit": _commit()}}
    args.out.write_text(json.dumps(result, indent=1))
    print(line(result) + f" {describe(info)} -> {args.out}")
    return 0


def _pct(a, b) -> str:
    return f"{a}/{b} ({100 * a / b:.0f} %)" if b else "—"


def readme_markdown(result: dict) -> str:
    """README region ``structures_levels``: per joint, the trends read right; the nulls."""
    s = result["summary"]
    rows = ["| joint | expected (lowest → highest level) | rigs | frequency trend right | damping trend right "
            "| all right, no SATMD element | damping trend seen (rising/none/falling) |",
            "|---|---|---|---|---|---|---|"]
    want = {"hardening": "stiffens", "softening": "softens", "friction": "softens, damping rises",
            "gap": "stiffens (the gap closes)"}
    for j, r in s["per_joint"].items():
        d = r["damping_seen"]
        rows.append(f"| {j} | {want[j]} | {r['n']} | {_pct(r['trend_right'], r['n'])} | "
                    f"{_pct(r['damping_right'], r['damping_scored']) if r['damping_scored'] else 'not scored'} | "
                    f"{_pct(r['right'], r['n'])} | {d['rising']}/{d['none']}/{d['falling']} |")
    a = s["joints"]
    rows.append(f"| **all** | | {a['n']} | {_pct(a['trend_right'], a['n'])} | "
                f"{_pct(a['damping_right'], a['damping_scored'])} | {_pct(a['right'], a['n'])} | |")
    n = s["nulls"]
    rows.append(f"| none (nulls) | no resonance moves | {n['n']} | | | {_pct(n['clean'], n['n'])} clean | |")
    pe = ", ".join(f"{e} {_pct(v['right'], v['n'])}" for e, v in s["per_excitation"].items())
    ps = ", ".join(f"{k} {_pct(v['right'], v['n'])}" for k, v in s.get("per_structure", {}).items())
    pl = ", ".join(f"{k} levels {_pct(v['right'], v['n'])}" for k, v in s["per_levels"].items())
    st = result["settings"]
    errs = (f"`discover` raised an error on {a['errors']} joint rig(s) and {n['errors']} null(s), counted as wrong. "
            if a["errors"] or n["errors"] else "")
    commits: dict = {}
    for r in result.get("runs", []):
        c = (r.get("settings") or {}).get("satmd_commit")
        if c:
            commits.setdefault(c, []).append(r["file"])
    code = ("Parts ran at satmd " + "; ".join(f"{c} ({', '.join(sorted(f))})" for c, f in commits.items()) + ". "
            if len(commits) > 1 else "")
    rows += ["", f"All right by force: {pe}; by structure: {ps}; by number of levels: {pl}. {errs}{code}"
             f"Nulls flagged nonlinear: {n['detected']}, "
             f"SATMD element named on nulls: {n['named']}, on joints: {a['named']}. "
             f"({st['duration_s']:.0f} s records at {st['fs_hz']:.0f} Hz, force {st['band_hz'][0]:.0f}–"
             f"{st['band_hz'][1]:.0f} Hz, levels spanning {20 * np.log10(st['level_span']):.0f} dB; median "
             f"{s['seconds_per_discover_median']:.1f} s per `discover`; {result['benchmark_seconds'] / 60:.0f} min.)"]
    return "\n".join(rows)


if __name__ == "__main__":
    sys.exit(main())

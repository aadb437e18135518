"""Do the coefficients `discover` reports for a named nonlinear element cover the truth? (issue 36 item 7)

Recordings from the INDEPENDENT simulator (`benchmarks/_indep_nl_sim.py`, no code shared with satmd), the
rigs and strengths of `benchmarks/nonlinear_model.py` (a rig drawn at random, the element moving its
equivalent parameter by ~12 % or ~3 N·s/m), two levels 1 and 10 N RMS, ``--duration`` s at 2048 Hz,
1 % noise on the accelerometers and 0.5 % on the force. Each pair goes through `satmd.discover([lo, hi])`
as a user would; counted per element: named right, and the truth inside the reported 95 % interval of
every coefficient (friction: Fc; v0 is a regularisation, reported but not scored).

Writes benchmarks/results/discover_intervals.json (``--out``; ``--merge`` joins parts) and prints one
line of figures.
Usage: python benchmarks/discover_intervals.py [--seeds 10] [--seed-offset 0] [--elements a,b] [--duration 30]
           [--out PART.json]   (rewritten after every case)
       python benchmarks/discover_intervals.py --merge PART1.json PART2.json ... [--out ...]
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
import nonlinear_model as nm  # noqa: E402
from _machine import machine  # noqa: E402

SCORED = {"cubic_absorber_spring": ("k3",), "cubic_host_spring": ("k3",), "quadratic_damping": ("c2",),
          "absorber_friction": ("Fc",), "inductor_saturation": ("isat",)}


def run(name, seeds, duration, offset=0, done=None):
    """``seeds`` rigs of element ``name``, drawn from the part's own stream (``offset`` 0 is the first part's);
    ``done(cases)`` is called after each case (a run stopped early keeps what it did)."""
    from satmd.discovery import discover
    from satmd.physics import Rig

    e_i = indep.ELEMENTS.index(name)
    rng = np.random.default_rng(7000 + e_i if offset == 0 else [7000 + e_i, offset])
    rigs = [Rig(m2=rng.uniform(0.4, 0.7), kp=rng.uniform(8e4, 1.5e5), R=rng.uniform(10, 60),
                L=rng.uniform(0.04, 0.2)) for _ in range(seeds)]
    params = [nm._strength(name, r, rng) for r in rigs]
    recs, _ = nm._recordings(name, rigs, params, duration, 8000 + e_i if offset == 0 else [8000 + e_i, offset])
    cases = []
    for i, par in enumerate(params):
        t0 = time.perf_counter()
        rep = discover([recs[(i, 1.0)], recs[(i, 10.0)]])
        sec = time.perf_counter() - t0
        found = rep.nonlinear.findings[0] if rep.nonlinear is not None and rep.nonlinear.findings else {}
        case = {"seed": offset + i, "truth": par, "named": found.get("name"), "parameters": found.get("parameters", {}),
                "ci95": found.get("ci95", {}), "seconds": sec}
        case["covered"] = {k: bool(k in case["ci95"] and case["ci95"][k][0] <= par[k] <= case["ci95"][k][1])
                           for k in SCORED[name]}
        cases.append(case)
        if done is not None:
            done(cases)
        print(f"  {name} #{offset + i}: {case['named']}, covered {case['covered']}, {sec:.1f} s", flush=True)
    return cases


def summary(result) -> str:
    parts = []
    for name, cases in result["elements"].items():
        named = sum(c["named"] == name for c in cases)
        covered = sum(all(c["covered"].values()) for c in cases if c["named"] == name)
        parts.append(f"{name}: named {named}/{len(cases)}, covered {covered}/{named}")
    return "; ".join(parts)


def readme_markdown(result) -> str:
    """Region ``discover_intervals`` of the results page: per element, named right, the truth inside the 95 %
    interval, and the mean / RMS of (estimate − truth)/σ with σ the interval's half-width / 1.96."""
    lines = ["| element | named right | truth inside the 95 % interval | mean / RMS of (estimate − truth)/σ |",
             "|---|---|---|---|"]
    for name, cases in result["elements"].items():
        key = SCORED[name][0]
        named = [c for c in cases if c["named"] == name]
        covered = sum(all(c["covered"].values()) for c in named)
        z = np.array([(c["parameters"][key] - c["truth"][key]) / ((c["ci95"][key][1] - c["ci95"][key][0]) / 2 / 1.96)
                      for c in named if key in c["ci95"] and c["ci95"][key][1] > c["ci95"][key][0]])
        share = f" ({100 * covered / len(named):.0f} %)" if named and covered < len(named) else ""
        stats = f"{z.mean():+.2f} / {np.sqrt(np.mean(z ** 2)):.2f}".replace("-", "−") if z.size else "—"
        lines.append(f"| `{name}` ({key}) | {len(named)}/{len(cases)} | {covered}/{len(named)}{share} | {stats} |")
    m = result.get("machine") or {}
    lines.append("")
    lines.append(f"{len(next(iter(result['elements'].values())))} rigs per element, measured at {m.get('commit', '?')} "
                 f"({str(m.get('date', '?'))[:10]}).")
    return "\n".join(lines) + "\n"


def _commit():
    import subprocess

    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                              timeout=10).stdout.strip() or None
    except OSError:
        return None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--seed-offset", type=int, default=0, help="the part's first seed: parts run apart draw other rigs")
    ap.add_argument("--duration", type=float, default=30.0)
    ap.add_argument("--elements", default=",".join(SCORED))
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "discover_intervals.json")
    ap.add_argument("--merge", nargs="+", type=Path, default=None, help="join parts' cases (per element) into --out")
    args = ap.parse_args(argv)
    if args.merge:
        result = {"elements": {}, "parts": []}
        for p in args.merge:
            part = json.loads(p.read_text())
            for name, cases in part["elements"].items():
                have = {c["seed"]: c for c in result["elements"].get(name, [])}
                have.update({c["seed"]: c for c in cases})  # a later part's case replaces the same seed
                result["elements"][name] = [have[k] for k in sorted(have)]
            result["parts"].append({"file": p.name, "machine": part.get("machine"),
                                    "satmd_commit": part.get("satmd_commit"), "duration_s": part.get("duration_s")})
        # the oldest part's machine: its commit is the one the merged figures are no newer than
        dated = [q for q in result["parts"] if q["machine"]]
        result["machine"] = min(dated, key=lambda q: q["machine"].get("date") or "")["machine"] if dated else None
    else:
        result = {"machine": machine(), "duration_s": args.duration, "satmd_commit": _commit(), "elements": {}}
        for name in args.elements.split(","):
            def done(cases, name=name):
                result["elements"][name] = cases
                args.out.write_text(json.dumps(result, indent=1, default=float))

            result["elements"][name] = run(name, args.seeds, args.duration, args.seed_offset, done)
    args.out.write_text(json.dumps(result, indent=1, default=float))
    print(summary(result))


if __name__ == "__main__":
    main()

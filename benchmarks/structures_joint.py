"""Where a structure's joint acts (issue 47): `satmd.structure.locate_joint` on an independent test bed.

The test bed (`tests/structure/chain.py`, Newton's law and Runge-Kutta, no satmd code) is a chain of 4 to 7
masses on springs (masses and stiffnesses drawn per structure), the first held to the ground, a multisine
force on the first mass, every mass's acceleration recorded with 1 % noise on every channel, three levels
(1, 2.8, 8 N RMS). One joint per structure, at a random place (between two neighbours or one mass and the
ground) and of a random law (a hardening cubic spring, a softening (saturating) one, Coulomb friction, quadratic damping, a
clearance); and structures with no joint (nulls). Scored: the joint placed between the right two sensors,
its law named, nulls with no joint.

The F-16 ground vibration test (real, ../shared/data/real/f16, levels 1, 3, 5, 7) is located too: its
nonlinear interface joins the wing (acc2) and the payload (acc3).

    python benchmarks/structures_joint.py [--count 40] [--nulls 10] [--out PATH]
    python benchmarks/structures_joint.py --f16-only      # the F-16 part, into the existing JSON

Writes benchmarks/results/structures_joint.json and prints one line.
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
from _machine import describe, load_after, machine  # noqa: E402
from satmd.structure import locate_joint  # noqa: E402
from tests.structure.chain import simulate_chain  # noqa: E402

LEVELS = (1.0, 2.8, 8.0)


def law_of(kind, rng):
    """(force law g(d, v), its SPEC §11 name); strengths set so the top level changes the response by 5-30 %."""
    if kind == "hardening":
        return (lambda d, v, a=rng.uniform(1e9, 6e9): a * d ** 3), "cubic"
    if kind == "softening":  # a spring of stiffness ks that saturates beyond g0 (a mount that gives way)
        return (lambda d, v, ks=rng.uniform(1e4, 3e4), g0=rng.uniform(1e-4, 3e-4):
                ks * g0 * np.tanh(d / g0)), "softening"
    if kind == "friction":
        return (lambda d, v, f=rng.uniform(0.2, 0.6): f * np.tanh(v / 1e-3)), "friction"
    if kind == "quadratic_damping":
        return (lambda d, v, c=rng.uniform(200.0, 800.0): c * v * np.abs(v)), "quadratic_damping"
    return (lambda d, v, g=rng.uniform(1e-4, 3e-4), kc=rng.uniform(2e4, 5e4):
            kc * np.where(np.abs(d) > g, d - np.sign(d) * g, 0.0)), "clearance"


def one(case: int, seed: int, null: bool) -> dict:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 8))
    m = rng.uniform(0.5, 2.0, n)
    k = rng.uniform(2e4, 8e4, n)
    i = int(rng.integers(0, n))
    joint = (i, None) if rng.random() < 0.25 or i == n - 1 else (i, i + 1)
    kind = str(rng.choice(["hardening", "softening", "friction", "quadratic_damping", "clearance"]))
    law, name = law_of(kind, rng)
    if null:
        law, name = (lambda d, v: 0.0 * d), None
    t0 = time.perf_counter()
    recs = simulate_chain(n=n, joint=joint, law=law, levels=LEVELS, seed=seed, m=m, k=k)
    t1 = time.perf_counter()
    loc = locate_joint(recs)
    truth = (f"acc{joint[0] + 1}", "ground" if joint[1] is None else f"acc{joint[1] + 1}")
    return {"case": case, "seed": seed, "masses": n, "truth_between": None if null else list(truth),
            "truth_law": name, "kind": "null" if null else kind, "detected": loc.detected,
            "evidence": round(loc.evidence, 1), "between": list(loc.between), "law": loc.law,
            "placed": (not null) and loc.detected and tuple(loc.between) == truth,
            "named": (not null) and loc.detected and loc.law == name,
            "next_delta_bic": loc.location[1]["delta_bic"] if len(loc.location) > 1 else None,
            "simulate_s": round(t1 - t0, 2), "locate_s": round(time.perf_counter() - t1, 2)}


def f16() -> dict | None:
    """locate_joint on the F-16's four levels (None when ../shared is absent)."""
    import warnings

    from satmd.io import load_recording
    from satmd.io.shared import real_data

    if real_data("f16", "F16Data_FullMSine_Level7.mat") is None:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        recs = [load_recording(real_data("f16", f"F16Data_FullMSine_Level{level}.mat"),
                               channel_map="force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]")
                for level in (1, 3, 5, 7)]
    t0 = time.perf_counter()
    loc = locate_joint(recs, band_hz=(2.5, 14.5))
    return {"between": list(loc.between), "truth": ["acc2", "acc3"], "location": loc.location, "law": loc.law,
            "laws": loc.laws, "evidence": round(loc.evidence, 1), "seconds": round(time.perf_counter() - t0, 2)}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=40)
    p.add_argument("--nulls", type=int, default=10)
    p.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "structures_joint.json"))
    p.add_argument("--f16-only", action="store_true", help="run the F-16 part alone, into the existing JSON")
    args = p.parse_args(argv)
    if args.f16_only:
        result = json.loads(Path(args.out).read_text())
        result["f16"] = f16()
        Path(args.out).write_text(json.dumps(result, indent=1))
        print(f"structures_joint (F-16): joint between {' and '.join(result['f16']['between'])}")
        return 0
    result = {"machine": machine(threads=1), "levels_n_rms": list(LEVELS)}
    rows = [one(c, 1000 + c, False) for c in range(args.count)] + \
           [one(args.count + c, 5000 + c, True) for c in range(args.nulls)]
    joints = [r for r in rows if r["kind"] != "null"]
    nulls = [r for r in rows if r["kind"] == "null"]
    by_kind = {}
    for r in joints:
        s = by_kind.setdefault(r["kind"], {"n": 0, "placed": 0, "named": 0})
        s["n"] += 1
        s["placed"] += r["placed"]
        s["named"] += r["named"]
    result.update({"rows": rows, "by_kind": by_kind, "placed": sum(r["placed"] for r in joints),
                   "named": sum(r["named"] for r in joints), "joints": len(joints),
                   "nulls": len(nulls), "nulls_clean": sum(not r["detected"] for r in nulls),
                   "locate_s_median": float(np.median([r["locate_s"] for r in rows]))})
    result["f16"] = f16()
    result["machine"].update(load_after())
    Path(args.out).write_text(json.dumps(result, indent=1))
    line = (f"structures_joint: placed {result['placed']}/{len(joints)}, law named {result['named']}/{len(joints)}, "
            f"nulls clean {result['nulls_clean']}/{len(nulls)}, locate {result['locate_s_median']:.2f} s median")
    print(line + " | " + describe(result["machine"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


def readme_markdown(result: dict) -> str:
    """The results table (benchmarks/readme_tables.py renders the region ``structures_joint`` from it)."""
    lines = ["| joint law (simulated chains, 3 levels) | structures | placed between the right two sensors | law named |",
             "|---|---|---|---|"]
    for kind, s in sorted(result["by_kind"].items()):
        lines.append(f"| {kind} | {s['n']} | {s['placed']}/{s['n']} | {s['named']}/{s['n']} |")
    lines.append(f"| **all** | {result['joints']} | {result['placed']}/{result['joints']} | "
                 f"{result['named']}/{result['joints']} |")
    lines.append("")
    lines.append(f"No joint (linear chains): {result['nulls_clean']}/{result['nulls']} get no joint. "
                 f"Median time of `locate_joint`: {result['locate_s_median']:.2f} s.")
    f = result.get("f16")
    if f:
        nxt = f["location"][1]
        lines.append(f"F-16, levels 1, 3, 5, 7: the joint between {f['between'][0]} and {f['between'][1]} "
                     f"(the benchmark's nonlinear interface joins acc2 and acc3); next place "
                     f"{' and '.join(nxt['between'])}, ΔBIC {nxt['delta_bic']:.0f}; law at that place: {f['law']} "
                     f"({f['seconds']:.1f} s).")
    return "\n".join(lines)

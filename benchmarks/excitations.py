"""Null recordings under lab excitations the recordings benchmark does not draw: a probe, not a target.

The independent simulator (`benchmarks/_indep_sim.py`) records a rig drawn anywhere in the SPEC §9
ranges, nothing missing from the physics, driven by one of:

- ``linear_sweep`` / ``log_sweep``: ONE swept sine 5 → 400 Hz over the whole record (40–120 s), ending
  at full amplitude at the top frequency;
- ``repeated_log_sweeps``: six log sweeps back to back;
- ``burst_random``: band-limited random noise on for 60 % of every 4 s frame, off otherwise.

1 % white noise on the force, 0.3–5 % on the accelerometers, fs 2–4 kHz. Each recording goes through
`satmd discover`'s path (LPM estimate, discovery). Counted per excitation: physics named (a false alarm),
``unexplained``, called `model_adequate` false (an in-model rig: a wrong verdict).

What it shows (see the README): repeated sweeps and burst random are as clean as random excitation; a
single sweep that crosses a sharp resonance faster than it rings distorts the estimate, which the local
polynomial method does not model, so discovery may see a mismatch there.

Writes benchmarks/results/excitations.json and prints one line of figures.
Usage: python benchmarks/excitations.py [--n 8] [--workers 2]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # one BLAS thread per worker
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

KINDS = ("linear_sweep", "log_sweep", "repeated_log_sweeps", "burst_random")
BAND = (5.0, 400.0)
RESULT = ROOT / "benchmarks" / "results" / "excitations.json"


def excitation(kind, rng):
    """A replacement for `_indep_sim.shaker_force` (same signature) making ``kind``, unit RMS."""
    from scipy import signal as sg

    def force(n, fs, rng_, **_):
        t = np.arange(n) / fs
        lo, hi = BAND
        if kind == "linear_sweep":
            x = sg.chirp(t, lo, t[-1], hi, method="linear")
        elif kind == "log_sweep":
            x = sg.chirp(t, lo, t[-1], hi, method="logarithmic")
        elif kind == "repeated_log_sweeps":
            span = t[-1] / 6
            x = sg.chirp(t % span, lo, span, hi, method="logarithmic")
        else:  # burst_random
            x = sg.sosfilt(sg.butter(4, [lo, hi], btype="band", fs=fs, output="sos"), rng.standard_normal(n))
            x = x * ((t % 4.0) < 2.4)
        return x / np.std(x)
    return force


def run_one(job):
    import _indep_sim as ind

    from satmd import discover
    from satmd.discovery.scenarios import random_rig
    from satmd.io import Recording, estimate_frf

    kind, seed = job
    rng = np.random.default_rng(777 + seed)
    rig = random_rig(rng)
    p = {k: float(getattr(rig, k)) for k in ind.NOMINAL}
    ind.shaker_force = excitation(kind, rng)  # this worker's own copy of the module
    fs = float(rng.choice([2000, 2500, 4000]))
    seconds = float(rng.uniform(40, 120))
    noise = dict(white_acc=float(np.exp(rng.uniform(np.log(0.003), np.log(0.05)))), white_force=0.01)
    chans, _ = ind.record(p, seconds, fs, rng, force={}, noise=noise)
    rec = Recording(fs, chans, {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}, {"generator": "indep"})
    t0 = time.perf_counter()
    rep = discover(estimate_frf(rec))
    return {"kind": kind, "seed": seed, "fs_hz": fs, "duration_s": seconds, "noise": noise["white_acc"],
            "effects": rep.effect_names, "model_adequate": bool(rep.model_adequate),
            "significant": bool(rep.significant_mismatch), "measurement": [m["name"] for m in rep.measurement],
            "chi2_reduced": float(rep.fit_before["chi2_reduced"]), "noise_dof": rep.estimator.get("noise_dof"),
            "seconds": time.perf_counter() - t0}


def summary(rows) -> dict:
    out = {}
    for kind in KINDS:
        r = [x for x in rows if x["kind"] == kind]
        out[kind] = {"n": len(r),
                     "physics_named": sum(any(e != "unexplained" for e in x["effects"]) for x in r),
                     "unexplained": sum("unexplained" in x["effects"] for x in r),
                     "called_inadequate": sum(not x["model_adequate"] for x in r),
                     "named": sorted({e for x in r for e in x["effects"]})}
    return out


def readme_markdown(result) -> str:
    """The README region ``excitations`` (benchmarks/readme_tables.py)."""
    rows = ["| excitation (independent simulator, null rigs) | recordings | physics named | `unexplained` "
            "| called inadequate |", "|---|---|---|---|---|"]
    for kind, x in result["by_excitation"].items():
        named = f" ({', '.join(e for e in x['named'] if e != 'unexplained')})" if x["physics_named"] else ""
        rows.append(f"| {kind.replace('_', ' ')} | {x['n']} | {x['physics_named']}{named} | {x['unexplained']} "
                    f"| {x['called_inadequate']} |")
    return "\n".join(rows)


def main(argv=None):
    from _machine import describe, load_after, machine

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=8, help="recordings per excitation")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=str(RESULT))
    a = ap.parse_args(argv)
    result = {"machine": machine(device="cpu", threads=a.workers), "settings": vars(a)}
    t0 = time.perf_counter()
    with ProcessPoolExecutor(a.workers) as pool:
        rows = list(pool.map(run_one, [(k, s) for k in KINDS for s in range(a.n)]))
    result.update(by_excitation=summary(rows), cases=rows, seconds=time.perf_counter() - t0)
    result["machine"].update(load_after())
    Path(a.out).write_text(json.dumps(result, indent=1))
    print("excitations: " + "; ".join(f"{k} physics {x['physics_named']}/{x['n']}, unexplained {x['unexplained']}, "
                                      f"inadequate {x['called_inadequate']}" for k, x in result["by_excitation"].items())
          + f" | {result['seconds']:.0f} s | " + describe(result["machine"]))


if __name__ == "__main__":
    main()

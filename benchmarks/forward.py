"""Forward-model throughput: satmd's closed-form batched solver against
dense batched solves of the full 3x3 dynamic stiffness, plus the cost of
the analytic 4-parameter Jacobian.

    python benchmarks/forward.py [--sets 10000] [--repeats 15] [--out benchmarks/results/forward.json]
    python benchmarks/forward.py --quick     # 2000 sets, 3 repeats, prints only (for development)

10^4 random parameter sets (m2, kp, R, L uniform in the SPEC §9 ranges) on
the paper grid (60 points, 40..130 Hz). Every timing is the best of N
repeats after one warm-up call; "points" are (parameter set, frequency)
pairs. The dense baselines assemble Z from the SPEC §2 formulas inside the
timed region (satmd's time includes its own assembly too); solve-only times
are recorded as well. satmd's calls and numpy's assembly and solve take turns
in the same rounds, so both sides of the ratio see the same load on the
machine. Each call's results are dropped before the next, so satmd reuses
their memory (`satmd.physics.buffers.OUTPUTS`); a second pair of timings
holds every result (no reuse: all 48 MB of results faulted in afresh), as a
caller keeping them all would see. Writes a JSON file and prints one line.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from _machine import describe, load_after, machine

from satmd.physics import PAPER_GRID_HZ, Rig, frf
from satmd.physics.buffers import OUTPUTS
from satmd.physics.model import default_threads

TARGETS = {"satmd_pts_per_s": 2e7, "speedup_vs_numpy_solve": 12.0, "jacobian4_over_frf_a1a2": 3.0}
WRT = ("m2", "kp", "R", "L")


def best_of(fns: dict, repeats, clock=time.perf_counter, rounds: dict | None = None):
    """Best (and median) wall time of each function, round-robin after one warm-up call each.

    Interleaving keeps the ratios fair when the machine's load changes during the run. ``rounds``, when
    given, receives every round's times (for ratios taken round by round).
    """
    for fn in fns.values():
        fn()
    times = {k: [] for k in fns}
    for _ in range(repeats):
        for k, fn in fns.items():
            t0 = clock()
            fn()
            times[k].append(clock() - t0)
    if rounds is not None:
        rounds.update(times)
    return {k: min(v) for k, v in times.items()}, {k: float(np.median(v)) for k, v in times.items()}


def random_sets(n, seed=0):
    rng = np.random.default_rng(seed)
    return dict(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n),
                R=rng.uniform(5.0, 100.0, n), L=rng.uniform(0.02, 0.5, n))


def numpy_Z(params, freq):
    """Stacked (n*F, 3, 3) complex128 Z of SPEC §2, written out explicitly."""
    r = Rig()
    w = 2 * np.pi * freq[None, :]
    m2, kp, R, L = (params[k][:, None] for k in ("m2", "kp", "R", "L"))
    n = m2.shape[0]
    Z = np.empty((n, freq.size, 3, 3), dtype=np.complex128)
    Z[..., 0, 0] = r.k1 + kp - r.m1 * w**2 + 1j * w * (r.c1 + r.cp)
    Z[..., 0, 1] = Z[..., 1, 0] = -kp - 1j * w * r.cp
    Z[..., 1, 1] = kp - m2 * w**2 + 1j * w * r.cp
    Z[..., 0, 2] = Z[..., 2, 0] = r.e / r.Cp
    Z[..., 1, 2] = Z[..., 2, 1] = -r.e / r.Cp
    Z[..., 2, 2] = 1.0 / r.Cp - L * w**2 + 1j * w * R
    return Z.reshape(-1, 3, 3)


def torch_Z(torch, params, freq, dtype):
    """The same Z as torch tensors (complex64 as in the paper's code)."""
    r = Rig()
    real = torch.float32 if dtype == torch.complex64 else torch.float64
    w = 2 * torch.pi * torch.as_tensor(freq, dtype=real)[None, :]
    m2, kp, R, L = (torch.as_tensor(params[k], dtype=real)[:, None] for k in ("m2", "kp", "R", "L"))
    n = m2.shape[0]
    Z = torch.empty((n, freq.size, 3, 3), dtype=dtype)
    one_j = torch.tensor(1j, dtype=dtype)
    Z[..., 0, 0] = r.k1 + kp - r.m1 * w**2 + one_j * w * (r.c1 + r.cp)
    Z[..., 0, 1] = -kp - one_j * w * r.cp
    Z[..., 1, 0] = Z[..., 0, 1]
    Z[..., 1, 1] = kp - m2 * w**2 + one_j * w * r.cp
    Z[..., 0, 2] = r.e / r.Cp
    Z[..., 2, 0] = r.e / r.Cp
    Z[..., 1, 2] = -r.e / r.Cp
    Z[..., 2, 1] = -r.e / r.Cp
    Z[..., 2, 2] = 1.0 / r.Cp - L * w**2 + one_j * w * R
    return Z.reshape(-1, 3, 3)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sets", type=int, default=10_000)
    ap.add_argument("--repeats", type=int, default=15)
    ap.add_argument("--out", default=None, help="JSON path (default benchmarks/results/forward.json; "
                                                "--quick writes nothing unless given)")
    ap.add_argument("--quick", action="store_true", help="2000 sets, 3 repeats, no JSON: for development")
    args = ap.parse_args(argv)
    if args.quick:
        args.sets, args.repeats = min(args.sets, 2000), min(args.repeats, 3)
    elif args.out is None:
        args.out = str(Path(__file__).resolve().parent / "results" / "forward.json")

    # satmd's figures use its default threads (`default_threads`: all cores up to 8 on more than two, else
    # one) and one thread; the baselines run as they come
    info = machine(device="cpu", threads=default_threads(args.sets * PAPER_GRID_HZ.size))
    freq = PAPER_GRID_HZ
    params = random_sets(args.sets)
    rig = Rig(**params)
    n_pts = args.sets * freq.size
    result = {"schema": "satmd-benchmark-forward/1", "sets": args.sets, "n_freq": int(freq.size),
              "points": n_pts, "repeats": args.repeats, "timing": "best of repeats after one warm-up"}

    # ---- satmd, and numpy.linalg.solve on the stacked Z timed in the same rounds (round-robin): the
    # ratio's two sides see the same load on the machine
    rhs = np.zeros((n_pts, 3, 1), dtype=np.complex128)
    rhs[:, 0, 0] = 1.0

    def np_full():
        return np.linalg.solve(numpy_Z(params, freq), rhs)

    rounds: dict = {}
    best, median = best_of({
        "all": lambda: frf(freq, rig),
        "acc": lambda: frf(freq, rig, outputs=("a1", "a2")),
        "jac_acc": lambda: frf(freq, rig, wrt=WRT, outputs=("a1", "a2")),
        "jac_all": lambda: frf(freq, rig, wrt=WRT),
        "serial": lambda: frf(freq, rig, threads=1),
        "numpy_full": np_full,
    }, args.repeats, rounds=rounds)
    t_np = best.pop("numpy_full")
    median.pop("numpy_full")
    t_all, t_acc, t_jac_acc, t_jac_all, t_serial = (best[k] for k in ("all", "acc", "jac_acc", "jac_all", "serial"))
    # CPU time, one thread: the Jacobian's cost independent of other load on the machine
    cpu, _ = best_of({
        "acc": lambda: frf(freq, rig, outputs=("a1", "a2"), threads=1),
        "jac_acc": lambda: frf(freq, rig, wrt=WRT, outputs=("a1", "a2"), threads=1),
        "all": lambda: frf(freq, rig, threads=1),
        "jac_all": lambda: frf(freq, rig, wrt=WRT, threads=1),
    }, args.repeats, clock=time.process_time)
    # the same, with every result still held when the next call starts (as a caller that keeps them all):
    # no spare block to reuse, each call's 48 MB of results faulted in afresh, against numpy in the same rounds
    fresh_rounds: dict = {}
    kept_blocks, OUTPUTS.max_blocks = OUTPUTS.max_blocks, 0
    try:
        fresh, _ = best_of({"all": lambda: frf(freq, rig), "numpy_full": np_full}, args.repeats, rounds=fresh_rounds)
    finally:
        OUTPUTS.max_blocks = kept_blocks
    ref = frf(freq, rig)
    result["satmd_median_s"] = median
    result["satmd"] = {
        "all_channels_s": t_all, "all_channels_pts_per_s": n_pts / t_all,
        "all_channels_fresh_memory_s": fresh["all"], "all_channels_fresh_memory_pts_per_s": n_pts / fresh["all"],
        "all_channels_1thread_s": t_serial, "all_channels_1thread_pts_per_s": n_pts / t_serial,
        "a1a2_s": t_acc, "a1a2_pts_per_s": n_pts / t_acc,
        "jacobian4_a1a2_s": t_jac_acc, "jacobian4_all_channels_s": t_jac_all,
        "jacobian4_over_frf_a1a2": t_jac_acc / t_acc,
        "jacobian4_over_frf_all_channels": t_jac_all / t_all,
        "cpu_time_1thread_s": cpu,
        "jacobian4_over_frf_a1a2_cpu_1thread": cpu["jac_acc"] / cpu["acc"],
        "jacobian4_over_frf_all_channels_cpu_1thread": cpu["jac_all"] / cpu["all"],
    }

    # ---- numpy.linalg.solve on the stacked Z (assembly and solve timed above, beside satmd)
    Z = numpy_Z(params, freq)
    best, _ = best_of({"solve": lambda z=Z: np.linalg.solve(z, rhs)}, args.repeats)
    t_np_solve = best["solve"]
    x = np_full()[..., 0].reshape(args.sets, freq.size, 3)
    agree = max(float(np.max(np.abs(x[..., k] - getattr(ref, c))) / np.max(np.abs(getattr(ref, c))))
                for k, c in enumerate(("u1", "u2", "q")))
    result["numpy_linalg_solve"] = {
        "assemble_and_solve_s": t_np, "pts_per_s": n_pts / t_np,
        "solve_only_s": t_np_solve, "solve_only_pts_per_s": n_pts / t_np_solve,
        "max_rel_diff_vs_satmd": agree,
    }
    del Z

    # ---- torch.linalg.solve, complex64 (as the paper's code)
    try:
        import torch
    except ImportError:  # pragma: no cover
        torch = None
        result["torch_linalg_solve_c64"] = None
    if torch is not None:
        rhs_t = torch.zeros((n_pts, 3, 1), dtype=torch.complex64)
        rhs_t[:, 0, 0] = 1.0

        def torch_full():
            return torch.linalg.solve(torch_Z(torch, params, freq, torch.complex64), rhs_t)

        with torch.no_grad():
            Zt = torch_Z(torch, params, freq, torch.complex64)
            best, _ = best_of({"full": torch_full, "solve": lambda: torch.linalg.solve(Zt, rhs_t)}, args.repeats)
            t_t, t_t_solve = best["full"], best["solve"]
            xt = torch_full()[..., 0].numpy().astype(np.complex128).reshape(args.sets, freq.size, 3)
        agree_t = max(float(np.max(np.abs(xt[..., k] - getattr(ref, c)), axis=-1).max()
                            / np.max(np.abs(getattr(ref, c))))
                      for k, c in enumerate(("u1", "u2", "q")))
        result["torch_linalg_solve_c64"] = {
            "device": "cpu", "threads": torch.get_num_threads(),
            "assemble_and_solve_s": t_t, "pts_per_s": n_pts / t_t,
            "solve_only_s": t_t_solve, "solve_only_pts_per_s": n_pts / t_t_solve,
            "max_rel_diff_vs_satmd": agree_t,
        }
        del Zt

    s = result["satmd"]
    rate = s["all_channels_pts_per_s"]
    np_rate = result["numpy_linalg_solve"]["pts_per_s"]
    # on a shared virtual machine either side of the ratio may have a slow spell: the spread of the ratio
    # taken round by round (satmd and numpy back to back) says how far one run's figure can be trusted
    per_round = np.array(rounds["numpy_full"]) / np.array(rounds["all"])
    result["ratios"] = {"satmd_over_numpy_solve": rate / np_rate,
                        "satmd_over_numpy_solve_per_round_quartiles": np.percentile(per_round, [25, 50, 75]).tolist(),
                        "satmd_1thread_over_numpy_solve": s["all_channels_1thread_pts_per_s"] / np_rate,
                        "satmd_fresh_memory_over_numpy_solve": fresh["numpy_full"] / fresh["all"]}
    if result["torch_linalg_solve_c64"]:
        result["ratios"]["satmd_over_torch_solve_c64"] = rate / result["torch_linalg_solve_c64"]["pts_per_s"]
    result["targets"] = {
        "satmd_pts_per_s >= 2e7": {"value": rate, "pass": rate >= TARGETS["satmd_pts_per_s"]},
        "speedup_vs_numpy_solve >= 12": {"value": rate / np_rate,
                                         "pass": rate / np_rate >= TARGETS["speedup_vs_numpy_solve"]},
        "jacobian4_over_frf_a1a2 <= 3": {"value": s["jacobian4_over_frf_a1a2"],
                                          "pass": s["jacobian4_over_frf_a1a2"] <= TARGETS["jacobian4_over_frf_a1a2"]},
    }
    info.update(load_after())
    info["satmd_threads_default"] = info["threads"]
    info["timing"] = ("best-of-N wall clock (perf_counter) unless marked cpu (process_time); satmd at its "
                      "default threads and with threads=1, numpy.linalg.solve single-threaded; satmd and "
                      "numpy's assembly and solve timed in turn in the same rounds")
    result["machine"] = info
    if args.out:
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(result, indent=2) + "\n")

    q = result["ratios"]["satmd_over_numpy_solve_per_round_quartiles"]
    line = (f"forward: satmd {rate:.2g} pts/s | numpy.linalg.solve {np_rate:.2g} ({rate / np_rate:.3g}x; "
            f"round by round {q[0]:.3g}-{q[2]:.3g}x; results all held, no block reused: "
            f"{result['ratios']['satmd_fresh_memory_over_numpy_solve']:.3g}x)")
    if result["torch_linalg_solve_c64"]:
        tr = result["torch_linalg_solve_c64"]["pts_per_s"]
        line += f" | torch.linalg.solve c64 {tr:.2g} ({rate / tr:.3g}x)"
    line += (f" | jacobian(4) {s['jacobian4_over_frf_a1a2']:.2g}x one FRF (a1,a2),"
             f" {s['jacobian4_over_frf_all_channels']:.2g}x (all channels)"
             f" [1-thread CPU: {s['jacobian4_over_frf_a1a2_cpu_1thread']:.2g}x,"
             f" {s['jacobian4_over_frf_all_channels_cpu_1thread']:.2g}x]")
    failed = [k for k, v in result["targets"].items() if not v["pass"]]
    line += " | targets " + ("all met" if not failed else "MISSED: " + "; ".join(failed))
    line += " " + describe(info)
    print(line)
    return result


if __name__ == "__main__":
    main()

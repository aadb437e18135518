"""Inverse benchmark (use case II): Table 2, the ablation, the off-curve check, the loop speed-up.

In one run:
1. For each preset {paper, box} and input noise {0, 0.5, 1, 2 %}: train the
   `physics` and `supervised` deep ensembles with the defaults a user gets
   (`satmd inverse train`), then score physics, supervised, hybrid (physics
   nets + least-squares refinement) and optimization (repeated global least
   squares) on the six blind pairs and 8 neighbours of each (54 FRFs, noise
   at the training level, std given): MAE and mean relative error of R and L,
   relative FRF reconstruction error of the prediction, 2σ interval coverage,
   training time (wall and CPU) and inference time per FRF.
2. Table 2 (six blind pairs, noise-free) for physics and hybrid beside the paper.
3. Off-curve pairs (e.g. R = 10 Ω with L = 0.3 H) for the paper- and
   box-trained models, against their on-curve errors.
4. Seconds per physics-training epoch, vectorised vs a per-sample Python loop.

Writes benchmarks/results/inverse.json (+ inverse.md, the tables) and prints
one line of figures.

``--training`` times only the default paper-preset physics training
(`InverseModel(kind="physics", preset="paper").fit()`, issue 14) with its
Table 2 MAE and the MAE on the 246 blind FRFs, and appends the figures with
the device, torch version and thread count to
benchmarks/results/inverse_training.json.

``--once`` (issue 29: train the inverse once) fits the default paper-preset
physics model twice per job, back to back: the method before issue 29
(``calibration="holdout"``: train on 80 % of the pairs, calibrate, train again
from scratch on all; finite-difference Jacobian) and the new default
(``calibration="crossfit"``: one training, each validation pair held out from
one member, whose out-of-fold predictions calibrate the std; ``jacobian="mobius"``:
residuals and the exact Gauss-Newton step from a Möbius map of the shunt
impedance, no twin call per step, back-propagation by hand).
Jobs: every seed of ``--seeds`` at 1 torch thread and noise 0 (Table 2 MAE on
the six blind pairs, MAE on the 246 blind FRFs), the first seed at each of
``--thread-counts`` (wall and CPU seconds, ratio new/old in the same run), and
the first seed trained and scored at ``--coverage-noise`` (2σ coverage on the
246 blind FRFs at that noise). Records merge into
benchmarks/results/inverse_once.json by (method, seed, threads, noise), so a
long comparison can be split over several runs (``--seeds 0,1`` then
``--seeds 2,3,4 --thread-counts 1 --coverage-noise 0``); the summary is
recomputed from all records each time. It also times one training step of the
batched members three ways (stacked weights with ``baddbmm``, ``torch.func``
``vmap`` over ``functional_call``, a Python loop over members).
Usage: python benchmarks/inverse.py [--quick] [--threads N] [--noises 0,0.01] [--presets paper] [--training]
       python benchmarks/inverse.py --once [--seeds 0,1,2,3,4] [--thread-counts 1,2] [--coverage-noise 0.01]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
sys.path.insert(0, str(ROOT / "benchmarks"))
from _machine import provenance  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny training (smoke test; numbers not meaningful)")
    ap.add_argument("--threads", type=int, default=1,
                    help="torch CPU threads (default 1: on a shared 2-core machine more threads only spin)")
    ap.add_argument("--noises", default="0,0.005,0.01,0.02")
    ap.add_argument("--presets", default="paper,box")
    ap.add_argument("--out", default=str(RESULTS / "inverse.json"))
    ap.add_argument("--render", action="store_true", help="only rewrite inverse.md from an existing inverse.json")
    ap.add_argument("--training", action="store_true", help="only time the paper-preset physics training")
    ap.add_argument("--device", default=None, help="training device for --training (default: CUDA when present)")
    ap.add_argument("--label", default="", help="a note stored with the --training figures")
    ap.add_argument("--once", action="store_true", help="issue 29: old (hold-out + refit) vs new (cross-fit) training")
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from inverse_once import add_arguments, run_args

    add_arguments(ap.add_argument_group("--once (benchmarks/inverse_once.py takes the same options)"))
    args = ap.parse_args(argv)
    if args.once:
        return run_args(args)
    if args.training:
        return time_training(args.threads, args.device, args.label)
    out = Path(args.out)
    if args.render:
        res = json.loads(out.read_text(encoding="utf-8"))
        write_markdown(res, out)
        return

    import torch

    from satmd.inverse.ablation import run_ablation

    torch.set_num_threads(args.threads)
    noises = tuple(float(x) for x in args.noises.split(","))
    presets = tuple(p.strip() for p in args.presets.split(","))
    t0 = time.perf_counter()
    res = run_ablation(noises=noises, presets=presets, quick=args.quick,
                       log=lambda m: print(m, file=sys.stderr, flush=True))
    res["benchmark_wall_s"] = time.perf_counter() - t0
    res["date"] = time.strftime("%Y-%m-%d %H:%M:%S")
    res["machine"] = {**res.get("machine", {}), **provenance()}
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(res, indent=1, default=float), encoding="utf-8")
    write_markdown(res, out)


def time_training(threads: int, device=None, label: str = "") -> dict:
    """Wall and CPU seconds of the default paper-preset physics fit, with its accuracy (see the docstring)."""
    import os
    import platform

    import torch

    from satmd.inverse import BLIND_PAIRS, InverseModel, evaluate, pairs_dataset

    torch.set_num_threads(threads)
    model = InverseModel("physics", "paper", verbose=False, threads=threads, device=device)
    t0, c0 = time.perf_counter(), time.process_time()
    model.fit()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    t2 = evaluate(model)
    blind = evaluate(model, pairs_dataset(BLIND_PAIRS, per_pair=40, seed=1000))
    dev = model.fit_info_["device"]
    rec = {"date": time.strftime("%Y-%m-%d %H:%M:%S"), "label": label, "train_s": wall, "train_cpu_s": cpu,
           "table2_mae_R": t2["mae_R"], "table2_mae_L": t2["mae_L"], "blind_mae_R": blind["mae_R"],
           "blind_mae_L": blind["mae_L"], "blind_coverage": blind["coverage"],
           "device": torch.cuda.get_device_name(0) if dev.startswith("cuda") else f"cpu ({os.cpu_count()} cores)",
           "torch": torch.__version__, "torch_threads": threads, "platform": platform.platform(),
           "load_average": os.getloadavg(), "config": model.fit_info_["config"], **provenance()}
    path = RESULTS / "inverse_training.json"
    runs = json.loads(path.read_text(encoding="utf-8")) if path.is_file() else []
    runs.append(rec)
    path.write_text(json.dumps(runs, indent=1), encoding="utf-8")
    print(f"inverse training: {wall:.1f} s wall, {cpu:.1f} s CPU on {rec['device']} ({threads} thread(s), load "
          f"{rec['load_average'][0]:.1f}); Table 2 MAE R {t2['mae_R']:.4f} Ω, L {t2['mae_L']:.3g} H; blind set MAE "
          f"R {blind['mae_R']:.4f} Ω, L {blind['mae_L']:.3g} H")
    return rec


def write_markdown(res, out: Path):
    from satmd.inverse.ablation import ablation_markdown, headline, off_curve_markdown, table2_markdown

    md = ["## Table 2 (six blind pairs, noise-free)", "", table2_markdown(res), "",
          "## Ablation (blind pairs + neighbours, noise at the training level)", "", ablation_markdown(res), "",
          "## Off-curve check (noise-free)", "", off_curve_markdown(res), ""]
    if "plain_physics" in res:
        p = res["plain_physics"]
        md += [f"Physics without the Gauss-Newton preconditioner (paper, noise-free): blind test set MAE R "
               f"{p['mae_R']:.3g} Ω, L {p['mae_L']:.3g} H; Table 2 MAE R {p['table2']['mae_R']:.3g} Ω, "
               f"L {p['table2']['mae_L']:.3g} H.", ""]
    if "speedup" in res:
        s = res["speedup"]
        md += [f"Physics epoch ({s['n_train']} samples, {s['n_members']} members): "
               f"vectorised {s['vectorised_epoch_s']:.2f} s, per-sample loop {s['per_sample_epoch_s']:.1f} s: "
               f"x{s['speedup']:.0f}.", ""]
    out.with_suffix(".md").write_text("\n".join(md), encoding="utf-8")
    print(headline(res))


if __name__ == "__main__":
    main()

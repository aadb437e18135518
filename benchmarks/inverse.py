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
Usage: python benchmarks/inverse.py [--quick] [--threads N] [--noises 0,0.01] [--presets paper]
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="tiny training (smoke test; numbers not meaningful)")
    ap.add_argument("--threads", type=int, default=1,
                    help="torch CPU threads (default 1: on a shared 2-core machine more threads only spin)")
    ap.add_argument("--noises", default="0,0.005,0.01,0.02")
    ap.add_argument("--presets", default="paper,box")
    ap.add_argument("--out", default=str(RESULTS / "inverse.json"))
    ap.add_argument("--render", action="store_true", help="only rewrite inverse.md from an existing inverse.json")
    args = ap.parse_args(argv)
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
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(res, indent=1, default=float), encoding="utf-8")
    write_markdown(res, out)


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

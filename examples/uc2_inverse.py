"""Use case II of the paper: amortized inverse tuning, FRFs -> shunt R, L (Table 2).

Trains the physics-consistent deep ensemble on the paper preset (the defaults
of `satmd inverse train --kind physics --preset paper`), prints Table 2 for
the six blind pairs beside the paper's numbers, the hybrid refinement, the
off-curve check against a box-trained model, and a noisy prediction with its
calibrated standard deviation. Saves the model to out/uc2_physics_paper/.

    python examples/uc2_inverse.py [--quick]

The full ablation (4 kinds x 4 noise levels x 2 presets) is
`python benchmarks/inverse.py`.
"""
from __future__ import annotations

import sys


def main(quick: bool = False) -> int:
    import torch

    from satmd import Rig, simulate
    from satmd.inverse import BLIND_PAIRS, OFF_CURVE_PAIRS, PAPER_TABLE2, InverseModel, evaluate, pairs_dataset
    from satmd.inverse.ablation import _as_hybrid

    torch.set_num_threads(1)  # the machines this runs on are small and shared
    kw = {}
    if quick:  # a smoke run: tiny training, meaningless numbers
        kw = {"epochs": 4, "warm_start_epochs": 2, "n_members": 2, "samples_per_pair": 10, "n_samples": 400}
    print("Use case II: amortized inverse, six blind pairs (paper Table 2)\n")
    model = InverseModel("physics", "paper", **kw).fit()
    info = model.fit_info_
    print(f"physics ensemble trained in {info['train_s']:.0f} s ({info['train_cpu_s']:.0f} s CPU), "
          f"warm start {info['warm_start_epochs']} supervised epochs; "
          f"validation MAE R {info['val_mae'][0]:.3g} Ω, L {info['val_mae'][1]:.3g} H")
    model.save("out/uc2_physics_paper")

    blind = pairs_dataset(BLIND_PAIRS)
    phys = evaluate(model, blind)
    hyb = evaluate(_as_hybrid(model), blind)
    print(f"\n{'R':>5} {'L':>6} | {'paper R̂':>8} {'paper L̂':>8} | "
          f"{'physics R̂ ± σ':>18} {'physics L̂ ± σ':>20} | "
          f"{'hybrid R̂':>9} {'hybrid L̂':>9}")
    for i, (R, L) in enumerate(BLIND_PAIRS):
        print(f"{R:5.1f} {L:6.3f} | {PAPER_TABLE2[i, 2]:8.4f} {PAPER_TABLE2[i, 3]:8.5f} | "
              f"{phys['R'][i]:9.4f} ± {phys['R_std'][i]:<6.2g} {phys['L'][i]:9.5f} ± {phys['L_std'][i]:<8.2g} | "
              f"{hyb['R'][i]:9.5f} {hyb['L'][i]:9.6f}")
    print(f"\nMAE R / L: paper 0.0823 Ω / 5.72e-4 H;  physics {phys['mae_R']:.4f} Ω / {phys['mae_L']:.2e} H;  "
          f"hybrid {hyb['mae_R']:.1e} Ω / {hyb['mae_L']:.1e} H")
    print(f"inference: physics {1e3 * phys['infer_s_per_frf']:.2f} ms/FRF, "
          f"hybrid {1e3 * hyb['infer_s_per_frf']:.1f} ms/FRF")

    print("\nOff the paper's R-L line (noise-free):")
    off = pairs_dataset(OFF_CURVE_PAIRS)
    box = InverseModel("physics", "box", **kw).fit()
    for name, m in (("paper-trained", model), ("box-trained", box)):
        on, of = evaluate(m, blind), evaluate(m, off)
        print(f"  {name:14s} on-curve MAE R {on['mae_R']:.3g} Ω, L {on['mae_L']:.3g} H; "
              f"off-curve MAE R {of['mae_R']:.3g} Ω, L {of['mae_L']:.3g} H")

    data = simulate(rig=Rig(R=30.0, L=0.15), noise=0.01, seed=3)
    p = model.predict_one(data)
    print(f"\nOne noisy FRF (1 % noise, std given), truth R = 30 Ω, L = 0.15 H: "
          f"R = {p['R']:.3f} ± {p['R_std']:.3f} Ω, L = {p['L']:.5f} ± {p['L_std']:.5f} H")
    return 0


if __name__ == "__main__":
    sys.exit(main(quick="--quick" in sys.argv[1:]))

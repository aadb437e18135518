"""Use case I of the paper: identify m2, kp, R, L from the full state (Table 1, Figure 3).

The target is the full state [U1, U2, Q] of the true rig on the paper's grid
(60 points, 40-130 Hz). The fit starts from the paper's nominal values and
uses relative corrections θ = θ_nom (1 + δ) (eqs. 11-12). With the paper's
loss (eq. 13: mean squared error scaled by the global s = max|x*|, plus
λ_reg ‖δ‖², λ_reg = 1e-8) the exact minimiser sits at a relative FRF error
of 1.92e-6: the regulariser pulls the answer towards the start. Without it
the fit recovers the truth to machine precision.

    python examples/uc1_identification.py [FIGURE.png]
"""
from __future__ import annotations

import sys

from satmd import PAPER_GRID_HZ, Rig, simulate
from satmd.identification import identify
from satmd.plots import frf_figure, save

NAMES = ("m2", "kp", "R", "L")
START = {"m2": 0.300, "kp": 50000.0, "R": 20.0, "L": 0.050}
PAPER = {"m2": 0.517999, "kp": 110999.797, "R": 21.999981, "L": 0.064000}
PAPER_ERROR = 2.35e-6
STATE = ("u1", "u2", "q")


def main(figure_path: str = "out/uc1_figure3.png") -> int:
    truth = Rig()
    target = simulate(PAPER_GRID_HZ, truth, channels=STATE)
    common = dict(start=START, channels=STATE, scale="global", global_search=False)
    paper_loss = identify(target, reg=1e-8, **common)
    unbiased = identify(target, reg=0.0, **common)

    print("Use case I: identification from the full state [U1, U2, Q] (paper Table 1)\n")
    header = f"{'parameter':<10}{'start':>14}{'paper (Adam)':>16}{'satmd reg=1e-8':>18}{'satmd reg=0':>18}{'truth':>14}"
    print(header)
    print("-" * len(header))
    for n in NAMES:
        print(f"{n:<10}{START[n]:>14.6g}{PAPER[n]:>16.9g}{paper_loss.values[n]:>18.9g}"
              f"{unbiased.values[n]:>18.9g}{getattr(truth, n):>14.6g}")
    print(f"{'rel. error':<10}{'':>14}{PAPER_ERROR:>16.3g}{paper_loss.rel_error:>18.3e}{unbiased.rel_error:>18.3e}")
    print(f"{'time [s]':<10}{'':>14}{'':>16}{paper_loss.wall_time:>18.4f}{unbiased.wall_time:>18.4f}")
    print("\nWith λ_reg = 1e-8 the loss's exact minimiser has relative error "
          f"{paper_loss.rel_error:.3e}: that is the floor the regulariser sets\n"
          f"(the paper's Adam run stopped at {PAPER_ERROR:g}). Without it the truth is recovered exactly.")

    f = PAPER_GRID_HZ
    recon = paper_loss.prediction()
    fig = frf_figure(
        [("target (true rig)", f, target.channels, {"color": "k", "marker": "o", "ms": 3, "lw": 0}),
         ("reconstructed (identified, λ=1e-8)", f, recon.channels, {"color": "tab:red", "lw": 1.4})],
        list(STATE), title=f"Figure 3: target vs reconstructed FRFs (relative error {paper_loss.rel_error:.2e})",
        phase=False)
    print(f"\nFigure 3 written to {save(fig, figure_path)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:2]))

"""Report section: use case I, grey-box identification (paper Table 1, Figure 3)."""
from __future__ import annotations

import numpy as np

from ...conventions import DEFAULT_FREE, SPEC_RANGES

ORDER = 20
TITLE = "Use case I: identification (paper Table 1)"

NAMES = DEFAULT_FREE
START = {"m2": 0.300, "kp": 50000.0, "R": 20.0, "L": 0.050}
PAPER = {"m2": 0.517999, "kp": 110999.797, "R": 21.999981, "L": 0.064000}
PAPER_ERROR = 2.35e-6
STATE = ("u1", "u2", "q")
# SPEC §9: where the true values of a rig may lie
RANGES = SPEC_RANGES


def build(ctx) -> str:
    from ...identification import identify
    from ...physics import PAPER_GRID_HZ, PARAMETER_INFO, Rig
    from ...plots import frf_figure
    from ...simulation.frf import simulate

    truth = Rig()
    target = simulate(PAPER_GRID_HZ, truth, channels=STATE)
    common = dict(start=START, channels=STATE, scale="global", global_search=False)
    identify(target, warn=False, **common)  # warm-up, so that the times below are steady-state
    reg = identify(target, reg=1e-8, warn=False, **common)
    exact = identify(target, reg=0.0, warn=False, **common)

    lines = [
        "Target: the full state [U1, U2, Q] of the true rig on the paper's grid (60 points, 40–130 Hz). "
        "Start: the paper's nominal values; unknowns are relative corrections θ = θ_nom(1 + δ) (eqs. 11–12). "
        "satmd minimises the same loss as the paper (eq. 13 with the global scale s = max|x*|, mean over "
        "all complex entries, λ_reg = 1e-8) with SciPy's trust-region least squares and the analytic "
        "Jacobian instead of Adam in float32, and also without the regulariser.", "",
        "| parameter | unit | nominal (start) | paper identified | satmd, λ_reg = 1e-8 | satmd, no regulariser "
        "| truth |",
        "|---|---|---|---|---|---|---|",
    ]
    for n in NAMES:
        lines.append(f"| {n} | {PARAMETER_INFO[n][0]} | {START[n]:g} | {PAPER[n]:.9g} | {reg.values[n]:.9g} "
                     f"| {exact.values[n]:.9g} | {getattr(truth, n):g} |")
    lines += [
        f"| relative FRF error | | | {PAPER_ERROR:.3g} | {reg.rel_error:.3e} | {exact.rel_error:.1e} | 0 |",
        f"| time | | | (Adam, ~8000 epochs) | {reg.wall_time * 1e3:.1f} ms ({reg.nfev} evaluations) "
        f"| {exact.wall_time * 1e3:.1f} ms ({exact.nfev} evaluations) | |",
        "",
        f"**The regulariser sets a floor.** The relative error {reg.rel_error:.3e} is the exact minimiser of "
        "the paper's regularised loss, not an optimisation tolerance: the penalty λ_reg‖δ‖² pulls every "
        "parameter slightly back towards the start (each satmd value above lies between the truth and the "
        f"start), and no optimiser can go below it on that loss. The paper's Adam run stopped at "
        f"{PAPER_ERROR:g}, a little above the floor. Without the regulariser the same fit lands on the "
        f"truth to machine precision ({exact.rel_error:.1e}), which is why `identify` uses `reg=0` by default.",
        "",
    ]
    recon = reg.prediction()
    fig = frf_figure(
        [("target (true rig)", PAPER_GRID_HZ, target.channels, {"color": "k", "marker": "o", "ms": 3, "lw": 0}),
         ("reconstructed (λ_reg = 1e-8)", PAPER_GRID_HZ, recon.channels, {"color": "tab:red", "lw": 1.4})],
        list(STATE), title=f"Figure 3: target vs reconstructed (relative error {reg.rel_error:.2e})", phase=False)
    lines += [ctx.figure(fig, "identify_figure3.png"), ""]

    # --- global search: a truth anywhere in the SPEC §9 ranges, default start, no hints -------------
    rng = np.random.default_rng(20)
    hidden = {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in RANGES.items()}
    acc = simulate(PAPER_GRID_HZ, truth.replace(**hidden))
    glob = identify(acc, warn=False)
    lines += [
        "**No good start needed.** A rig drawn at random in the SPEC §9 ranges, noise-free accelerations A1, A2 "
        "on the paper grid, fitted from the default start with the default global search (a batched "
        "Sobol design of 4096 parameter sets, the best few refined by least squares):", "",
        "| parameter | hidden truth | identified | default start |", "|---|---|---|---|",
    ]
    lines += [f"| {n} | {hidden[n]:.6g} | {glob.values[n]:.6g} | {getattr(truth, n):g} |" for n in NAMES]
    lines += ["", f"Relative error {glob.rel_error:.1e} in {glob.wall_time:.3f} s ({glob.nfev} least-squares "
              "evaluations besides the batched search).", ""]

    # --- uncertainty: 1 % noise with std given ---------------------------------------------------
    noisy = simulate(PAPER_GRID_HZ, truth, noise=0.01, seed=1)
    nfit = identify(noisy, warn=False)
    ci = nfit.confidence_intervals()
    lines += [
        "**Uncertainty.** The true rig's accelerations with 1 % noise (std = 0.01·|A| on the real and "
        f"imaginary parts, given in the data): χ²_red = {nfit.chi2_reduced:.3f}. 95 % intervals from the "
        "Jacobian covariance (± 1.96 std) and from the profile likelihood:", "",
        "| parameter | truth | estimate | std | Jacobian 95 % | profile 95 % |", "|---|---|---|---|---|---|",
    ]
    for n in NAMES:
        v, s = nfit.values[n], nfit.std[n]
        lo, hi = ci[n]
        lines.append(f"| {n} | {getattr(truth, n):g} | {v:.6g} | {s:.3g} | [{v - 1.96 * s:.6g}, {v + 1.96 * s:.6g}] "
                     f"| [{lo:.6g}, {hi:.6g}] |")
    lines += ["", "At this noise level the model is nearly linear over the intervals and the two agree; "
              "see `benchmarks/identification.py` for the coverage over 200 noisy replicates."]

    ctx.results["identify"] = {
        "table1": {
            "paper": dict(PAPER, rel_error=PAPER_ERROR),
            "reg_1e-8": dict(reg.values, rel_error=reg.rel_error, wall_time_s=reg.wall_time),
            "no_reg": dict(exact.values, rel_error=exact.rel_error, wall_time_s=exact.wall_time),
        },
        "global_search": {"truth": hidden, "identified": glob.values, "rel_error": glob.rel_error,
                          "wall_time_s": glob.wall_time},
        "noise_1pct": {"values": nfit.values, "std": nfit.std, "chi2_reduced": nfit.chi2_reduced,
                       "profile_ci_95": {k: list(v) for k, v in ci.items()}},
    }
    return "\n".join(lines)

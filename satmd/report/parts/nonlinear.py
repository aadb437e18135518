"""Report section: a nonlinear rig at three levels, detected, named, fitted, predicted and tuned (issue 35)."""
from __future__ import annotations

ORDER = 57
TITLE = "A nonlinear rig: detected, named, modelled, predicted and tuned across levels"

K3 = 2e11  # the absorber spring's cubic coefficient [N/m³]: kp about +12 % at 10 N RMS


def build(ctx) -> str:
    from ...simulation.frf import simulate
    from ...discovery import discover
    from ...identification.nonlinear.fit import fit_nonlinear
    from ...identification.nonlinear.compare import compare_models
    from ...physics import Rig, nonlinear_element
    from ...physics.nonlinear import kernel
    from ...tuning.nonlinear import tune_nonlinear
    from ..fig_nonlinear import nonlinear_comparison_figure

    if not kernel.available:
        return "Skipped: the compiled integrator (numba) is not installed (`pip install numba`)."
    truth = Rig(m2=0.55, kp=1.2e5, R=30.0, L=0.07)
    element = nonlinear_element("cubic_absorber_spring", k3=K3)
    duration = 12.0 if ctx.quick else 16.0
    def record(level, seed):
        return simulate(rig=truth, time=True, nonlinear=[element], duration_s=duration, fs_hz=1024.0, noise=0.01,
                        level=level, seed=seed)

    train = [record(lv, i) for i, lv in enumerate((1.0, 10.0))]
    held = record(4.0, 7)
    rep = discover(train)
    nl = rep.nonlinear
    named = [f["name"] for f in nl.findings] if nl is not None else []
    fit = fit_nonlinear(train, "cubic_absorber_spring", seconds=None)
    lo, hi = fit.ci95["k3"]
    out = compare_models(train, [held], "cubic_absorber_spring", seconds=None)
    held_row = [r for r in out["levels"] if r["held_out"]][0]
    figure = ctx.figure(nonlinear_comparison_figure(out), "nonlinear_fit_improves.png")
    tuned = tune_nonlinear(fit.rig, [fit.element], levels=[1.0, 4.0, 10.0])
    ctx.results["nonlinear"] = {"named": named, "k3": fit.values["k3"], "k3_ci95": [lo, hi], "k3_true": K3,
                                "held_out_td_ratio": held_row["td_ratio"], "design": dict(tuned.design),
                                "cost_of_linear_db": tuned.cost_of_linear_db}
    return "\n".join([
        f"The paper's rig with a hardening absorber spring (k3 = {K3:.3g} N/m³: kp about 12 % stiffer at "
        f"10 N RMS), recorded {duration:g} s at 1 and 10 N RMS (random force, 1 % sensor noise) and, held "
        "out of every fit, at 4 N RMS.", "",
        f"- **Detected and named** by `discover([rec_1N, rec_10N])`: {', '.join(named) or 'nothing named'} "
        f"(nonlinearity {'detected' if nl is not None and nl.detected else 'not detected'}).",
        f"- **Modelled** by `fit_nonlinear` (time-domain output error, all levels at once): k3 = "
        f"{fit.values['k3']:.4g} N/m³, 95 % interval [{lo:.4g}, {hi:.4g}] (true {K3:.3g}).",
        f"- **The fit improves**: the 4 N recording, held out, is predicted {held_row['td_ratio']:.1f}× better "
        "in the time domain by the nonlinear model than by the best linear one.",
        f"- **Tuned across levels** by `tune_nonlinear` (worst-case |U1| peak over 1, 4 and 10 N): "
        f"R = {tuned.design['R']:.3g} Ω, L = {tuned.design['L']:.4g} H; tuning on the low level's linear "
        f"model instead costs {tuned.cost_of_linear_db:.2f} dB at the worst level.", "",
        figure, "",
        "```", nl.report() if nl is not None else "(no nonlinear block)", "```", "",
        "Rates over many rigs and every element: `benchmarks/nonlinear.py` (detect, name) and "
        "`benchmarks/nonlinear_model.py` (model, predict, tune), in the README.",
    ])

"""Report section: the forward model and the missing-physics vocabulary."""
from __future__ import annotations

import numpy as np

ORDER = 10
TITLE = "Forward model: the rig and the effects"


def build(ctx) -> str:
    from ...physics import CHANNELS, PARAMETER_INFO, Rig, frf
    from ...physics.effects import effect
    from ...plots import frf_figure

    rig = Rig()
    f = np.linspace(20, 160, 700)
    r = frf(f, rig)
    fig = frf_figure([("paper rig", f, {c: r.channel(c) for c in CHANNELS}, {"color": "k"})], list(CHANNELS),
                     "The paper's rig (SPEC §3)")
    lines = ["The coupled electromechanical model (SPEC §2) of the paper's rig, state [U1, U2, Q] and "
             "the accelerations A1, A2, for a unit force on the primary mass.", "",
             "| parameter | value | unit | role |", "|---|---|---|---|"]
    lines += [f"| {n} | {getattr(rig, n):g} | {u} | {role} |" for n, (u, role) in PARAMETER_INFO.items()]
    lines += ["", ctx.figure(fig, "forward_rig.png"), ""]

    examples = [
        effect("sensor_gain", gain_a1=1.05, gain_a2=0.95),
        effect("time_delay", tau_s=2e-4),
        effect("structural_damping", eta=0.03),
        effect("dielectric_loss", tan_delta=0.05),
        effect("shunt_capacitance", Cs=4e-6),
        effect("extra_mode", f_hz=66.0, zeta=0.01, mass_ratio=0.01),
        effect("parameter_offset:k1", value=2.1e5),
    ]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 4, figsize=(16, 6), sharex=True)
    lines += ["The missing-physics vocabulary (SPEC §8): each effect is an exact change to the model.", "",
              "| effect | physics | example | max change of A1 |", "|---|---|---|---|"]
    base = r.channel("a1")
    for ax, eff in zip(axes.flat, examples):
        ra = frf(f, rig, [eff])
        ax.semilogy(f, np.abs(base), "k", lw=1, label="nominal")
        ax.semilogy(f, np.abs(ra.channel("a1")), "tab:red", lw=1, label=eff.name)
        ax.set_title(eff.name, fontsize=9)
        ax.legend(fontsize=7)
        change = np.max(np.abs(ra.channel("a1") - base) / np.abs(base))
        lines.append(f"| `{eff.name}` | {eff.description} | {eff!r} | {100 * change:.1f} % |")
    axes.flat[-1].axis("off")
    fig.supxlabel("frequency [Hz]")
    fig.supylabel("|A1| [m/s²/N]")
    fig.tight_layout()
    lines += ["", ctx.figure(fig, "forward_effects.png")]
    ctx.results["forward"] = {"a1_peak_hz": float(f[np.argmax(np.abs(base))])}
    return "\n".join(lines)

"""Report section: shunt tuning of the paper's rig, and the optimiser against exact optima."""
from __future__ import annotations

import math
from ...conventions import PAPER_BAND_HZ

ORDER = 60
TITLE = "Shunt tuning: the best R and L for the paper's rig"

BAND = PAPER_BAND_HZ


def _textbook_rows():
    """(check, satmd, exact) rows: classic TMD (μ = 0.05) and a piezo RL shunt on an undamped host."""
    from ...physics import Rig
    from ...tuning import tune
    from ...tuning.laws import equal_peak_shunt
    from ...tuning.objective import Objective

    m1, k1, mu = 1.0, (2 * math.pi) ** 2, 0.05
    m2 = mu * m1
    kp0 = m2 * k1 / m1
    tmd = Rig(m1=m1, k1=k1, c1=0.0, cp=0.1, e=0.0, m2=m2, kp=kp0)
    bounds = {"kp": (0.5 * kp0, 1.5 * kp0), "cp": (0.02 * math.sqrt(kp0 * m2), math.sqrt(kp0 * m2))}
    res = tune(tmd, band_hz=(0.3, 3.0), design=("kp", "cp"), bounds=bounds)
    kp, cp = res.design["kp"], res.design["cp"]
    dh = next(c for c in res.closed_forms if c["name"].startswith("Den Hartog"))
    rows = [("classic TMD, μ = 0.05: frequency ratio", f"{math.sqrt(kp / m2 / (k1 / m1)):.5f}", "0.95237"),
            ("damping ratio", f"{cp / (2 * math.sqrt(kp * m2)):.5f}", "0.13394"),
            ("normalised peak U1·k1/F0", f"{res.value * k1:.4f}", "6.4079"),
            ("Den Hartog's damping: peak above the optimum", f"{dh['gap_db']:.3f} dB", "0.05 dB")]
    for kc, expected in ((0.1, "0.002 dB"), (0.2, "0.016 dB")):
        ktot = 194e3 + 111e3
        e = math.sqrt(kc**2 * ktot / (1 + kc**2) * 27e-6)
        rig = Rig(c1=0.0, cp=0.0, e=e, m2=1e6)
        f_oc = math.sqrt(ktot / 0.85) / (2 * math.pi)
        f_sc = math.sqrt((ktot - e**2 / 27e-6) / 0.85) / (2 * math.pi)
        band = (0.5 * f_oc, 1.5 * f_oc)
        opt = tune(rig, band_hz=band, closed_form_check=False)
        closed = Objective("hinf", "u1", band)(rig.replace(**equal_peak_shunt(27e-6, f_oc, f_sc)))[0]
        rows.append((f"piezo RL shunt, undamped host, k_c = {kc}: equal-peak closed form above the minimax",
                     f"{20 * math.log10(closed / opt.value):.4f} dB", expected))
    return rows


def build(ctx) -> str:
    from ...physics import Rig
    from ...tuning import tune

    rig = Rig()
    hinf = tune(rig, band_hz=BAND)
    h2 = tune(rig, objective="h2", band_hz=BAND)
    lines = [
        "`satmd.tune` finds the globally best shunt setting over R ∈ [0.1, 1000] Ω, L ∈ [1e-3, 5] H (log space: "
        "a batched Sobol search, then restarted Nelder–Mead). H∞ is the true peak of |U1| over the band (every "
        "local maximum refined in frequency), H2 its RMS over the band. The paper's rig, nominal model, "
        f"band {BAND[0]:g}–{BAND[1]:g} Hz, current setting R = 22 Ω, L = 0.064 H:", "",
        "| objective | optimal R [Ω] | optimal L [H] | optimal [m/N] | current [m/N] | vs current | "
        "vs open circuit |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in (("H∞ (peak of U1)", hinf), ("H2 (RMS of U1)", h2)):
        att = r.attenuation_db
        lines.append(f"| {name} | {r.design['R']:.2f} | {r.design['L']:.4f} | {r.value:.4g} | {r.current_value:.4g} "
                     f"| {att['vs_current']:.2f} dB | {att['vs_open_circuit']:.2f} dB |")
    lines += ["", f"The H∞ optimum puts the two peaks ({', '.join(f'{f:.1f} Hz' for f in hinf.peaks_hz)}) at equal "
              "height. The classical single-mode laws, applied to each mode of this rig with its open- and "
              "short-circuit frequencies taken from the model:", "",
              "| law | R [Ω] | L [H] | above the H∞ optimum | mode |", "|---|---|---|---|---|"]
    for c in hinf.closed_forms:
        lines.append(f"| {c['name'].split(' (')[0]} | {c['design']['R']:.2f} | {c['design']['L']:.4f} "
                     f"| {c['gap_db']:.2f} dB | {c['note']} |")
    lines += ["", "Both masses move and both modes couple to the shunt, so no single-mode law comes close: "
              "tuning on the full model is worth several dB here.", "",
              ctx.figure(hinf.figure(), "tune_paper_rig.png"), ""]
    rows = _textbook_rows()
    lines += ["**Checked against exact optima** (in the model's limits; `tests/tune`):", "",
              "| check | satmd | exact / published |", "|---|---|---|"]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    ctx.results["tune"] = {
        "paper_rig": {k: r.to_dict() for k, r in (("hinf", hinf), ("h2", h2))},
        "closed_forms_hinf": [{"name": c["name"], "design": c["design"], "gap_db": c["gap_db"]}
                              for c in hinf.closed_forms],
        "textbook": [{"check": a, "satmd": b, "exact": c} for a, b, c in rows],
    }
    return "\n".join(lines)

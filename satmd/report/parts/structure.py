"""Report section: the F-16's joint located among its three accelerometers, modelled, and a level it never saw
predicted (SPEC §11)."""
from __future__ import annotations

ORDER = 59
TITLE = "A structure's joint: where it acts, its model, and a level it never saw (the F-16)"

CHANNELS = "force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]"
FITTED, HELD = (1, 3, 7), 5
QUICK = (1, 7)  # quick: two levels, the spectra's law alone (the named laws are weighed on three or more)


def build(ctx) -> str:
    from ...structure import fit_structure, locate_joint
    from ...structure.figures import draw_joint, draw_prediction
    from .f16 import SKIPPED, recordings

    levels = QUICK if ctx.quick else FITTED
    recs = recordings((*levels, HELD), CHANNELS)
    if recs is None:
        return SKIPPED
    fitted = [recs[i] for i in levels]
    loc = locate_joint(fitted)
    model = fit_structure(fitted, location=loc, files=[f"level {i}" for i in levels],
                          max_nfev=5 if ctx.quick else 40, polish=not ctx.quick)
    held = model.predict(recs[HELD], file=f"level {HELD}")
    joint = model.joint
    # the model's law: the weighing can keep another than the spectra's (`fit_structure`), both said
    ctx.results["structure"] = {"between": list(loc.between), "law": joint.law if joint else None,
                                "spectra_law": loc.law, "fit": model.fit, "held_out": held.to_dict(),
                                "formula": joint.formula() if joint else None}
    names = list(model.channels)
    rows = [f"| {f} (fitted) | " + " | ".join(f"{a:.3f} → {b:.3f}" for a, b in zip(lin, nl)) + " |"
            for f, lin, nl in zip(model.fit["files"], model.fit["linear"], model.fit["nonlinear"])]
    rows.append(f"| **level {HELD} (never seen)** | " + " | ".join(
        f"**{a:.3f} → {b:.3f}**" for a, b in zip(held.linear_nrmse, held.nrmse)) + " |")
    nxt = loc.location[1] if len(loc.location) > 1 else None
    law_text = f"{joint.law}, force {joint.formula()}" + (" N" if joint.units == "N" else " (relative units)") \
        if joint else "none"
    if joint and joint.law != loc.law:
        law_text += (f"; the levels' spectra preferred the {loc.law} law, but simulated on every level this one "
                     "fitted better")
    return "\n".join([
        f"Levels {', '.join(map(str, levels))} of the F-16 benchmark with all three accelerometers (`--map {CHANNELS}`: "
        "acc1 at the shaker, acc2 on the wing beside the payload's mounting, acc3 on the payload). "
        f"`locate_joint` places the joint between {loc.between[0]} and {loc.between[1]}"
        + (f" (next: {' and '.join(nxt['between'])}, ΔBIC {nxt['delta_bic']:.0f})" if nxt else "")
        + f"; the benchmark's description puts it in the payload's mounting, between acc2 and acc3. "
        f"`fit_structure` fits the linear part and the joint ({law_text}) on these levels at once, each simulated "
        f"in time from its measured force; level {HELD} was not used.", "",
        ctx.figure(draw_joint(loc, "F-16: where the joint acts"), "structure_joint.png"), "",
        "NRMSE per channel (RMS of the simulation's error over the RMS of the measured response): the linear model "
        "of the lowest level → the model with the joint.", "",
        "| recording | " + " | ".join(names) + " |", "|---|" + "---|" * len(names), *rows, "",
        ctx.figure(draw_prediction(held), "structure_level5.png"), "",
        f"Level {HELD}, never seen by the fit: measured, linear and with the joint; a second of each channel and the "
        "spectrum of the whole record (above 15 Hz, where the force puts nothing, the response the joint makes).",
    ])

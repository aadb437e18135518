"""The joint's force in newtons: its path scaled by reciprocity through the driving point, and the sign the
structure's modes give a path whose scale they do not fix.

A joint's path κ_r (its force's input to mode r, relative to the shaker's) is fitted free; reciprocity says it
is ``−(A_ar − A_br)/A_dr`` for a driving point d. Where the fitted path follows those shapes, one scale s maps
it onto them and the law's coefficients become forces (``c s``, ``κ / s``: the simulation is unchanged). Where
it departs from them by more than `MAX_MISFIT` the scale is not known, and the coefficients stay relative; the
sign of s can still be: where the path and the shapes point the same way mode by mode (`SIGN_AGREEMENT`), a
coefficient's sign in newtons is its relative sign times sign(s), and a law whose name fixes a sign (a
saturating spring softens, a clearance closes, a friction dissipates) can be told from its opposite.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import TINY
from ..errors import DataError
from .laws import SHAPE_PARAMETERS

MAX_MISFIT = 0.3       # the path's departure from the modes' shapes beyond which its scale is not fixed
SIGN_AGREEMENT = 0.5   # the weighted cosine of path and shapes from which their sign is


def path_scale(model, driving_point=None):
    """(d, s, misfit, agreement) of the joint's path against the modes' shapes at the driving point d (found when
    not given): κ ≈ s·(−(A_a − A_b)/A_d) in least squares weighted by each mode's share at d, its relative misfit,
    and the weighted cosine of the two (1: the same shape, 0: unrelated); None without a joint or a driving point."""
    from .linear import driving_point as found

    lin, j = model.linear, model.joint
    if driving_point is not None and driving_point not in lin.channels:
        raise DataError(f"driving point {driving_point}: no such channel (channels: {', '.join(lin.channels)})")
    # found on the lowest level's model first: the structure under the joint has more poles than modes, whose
    # fitted constants can take any sign (on the F-16 it named the payload, the lowest level the shaker's point)
    d = driving_point or (found(model.reference) if model.reference is not None else None) or found(lin)
    if d is None or j is None:
        return None if d is None else (d, None, None, None)
    phys = -lin.coupling(*j.between, d)
    w = np.abs(lin.residues[lin.index(d)] / lin.poles ** 2)  # each mode's weight at the driving point
    w = np.where(w > 0.05 * w.max(), w, 0.0)  # the structure's modes, not the poles that only shape the fit
    kappa = np.asarray(j.coupling, complex)
    dot = float(np.sum(w * (kappa * phys.conj()).real))
    s = dot / max(float(np.sum(w * np.abs(phys) ** 2)), TINY)
    misfit = np.sqrt(np.sum(w * np.abs(kappa - s * phys) ** 2) / max(np.sum(w * np.abs(kappa) ** 2), TINY))
    norms = np.sqrt(float(np.sum(w * np.abs(kappa) ** 2)) * float(np.sum(w * np.abs(phys) ** 2)))
    return d, s, float(misfit), dot / max(norms, TINY)


def path_sign(model) -> int:
    """+1 or −1: the sign a relative coefficient takes in newtons, where the path agrees with the modes' shapes
    at the driving point in sign (`SIGN_AGREEMENT`); 0 where it does not, or there is no driving point."""
    found = path_scale(model, model.driving_point)
    if found is None or found[1] is None or not np.isfinite(found[1]) or abs(found[3]) < SIGN_AGREEMENT:
        return 0
    return 1 if found[1] > 0 else -1


def passive_sign(model) -> int:
    """+1 or −1: the sign a relative coefficient takes in newtons, from the joint's own path alone (no driving
    point needed); 0 where its modes do not agree (`SIGN_AGREEMENT`). A force at the pair moves the stroke as a
    force at a driving point moves that point: with κ_r = −(A_ar − A_br)/A_dr (a positive coefficient restores
    or resists) each mode's stroke residue ``R_r = pair_r κ_r`` has a receptance modal constant
    ``−(φ_a − φ_b)²`` of one sign, whatever the shapes' scale. The agreement is the constants' sum over the sum
    of their sizes. On an independent chain with a friction joint, whose fitted path agreed with the driving
    point's shapes too little to give a sign (0.42), a quadratic damping was fitted with every mode's constant
    reversed: its force fed the structure, held back at the fitted levels by the linear terms, and at 1.5 times
    the top level the simulation ran away."""
    from ..modal.shapes import modal_constants

    lin, j = model.linear, model.joint
    const = modal_constants(np.asarray(j.stroke_of(lin), complex) * np.asarray(j.coupling, complex), lin.poles)
    size = float(np.sum(np.abs(const)))
    agreement = float(np.sum(const)) / size if size > 0 else 0.0
    if not np.isfinite(agreement) or abs(agreement) < SIGN_AGREEMENT:
        return 0
    return 1 if agreement < 0 else -1


def in_newtons(model, driving_point=None):
    """The joint with its path scaled as reciprocity says (κ_r = −(A_ar − A_br)/A_dr for a driving point d),
    so that its coefficients are forces; the simulation is unchanged (c s, κ / s). As it was when there is no
    driving point or the fitted path does not follow the modes' shapes (a misfit over `MAX_MISFIT`)."""
    found = path_scale(model, driving_point)
    if found is None:
        return model
    d, s, misfit, _ = found
    j = model.joint
    if s is None or not np.isfinite(s) or s == 0 or misfit > MAX_MISFIT:  # the point is known, the scale is not
        return replace(model, driving_point=d)
    # a force coefficient scales by s, whose relative standard error is the path's misfit to the modes' shapes
    # over the modes that set it (a weighted mean's): its interval holds both, in quadrature; a gap or a slip
    # velocity keeps its unit and its interval
    lin = model.linear
    w = np.abs(lin.residues[lin.index(d)] / lin.poles ** 2)
    shapes = set(SHAPE_PARAMETERS.values())
    values = j.parameters()
    rel = float(misfit) / np.sqrt(float(max(int(np.count_nonzero(w > 0.05 * w.max())), 1)))
    ci = {}
    for n, v in values.items() if j.ci95 else ():
        lo, hi = j.ci95.get(n, (v, v))  # none for a coefficient held to fix the path's scale: the scale's alone
        if n in shapes:
            if n in j.ci95:
                ci[n] = [lo, hi]
            continue
        h = abs(s) * float(np.hypot(0.5 * (hi - lo), 1.96 * rel * abs(v)))
        ci[n] = [v * s - h, v * s + h]
    column = None if j.column is None else j.column / s
    return replace(model, joint=replace(j, coefficients=j.coefficients * s, coupling=j.coupling / s, units="N",
                                        ci95=ci, column=column), driving_point=d)

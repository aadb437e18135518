"""Places the spectra cannot tell apart, weighed with the joint's input to each mode that the mode shapes give.

`locate_joint` leaves each mode's input from the joint, κ_r, free (one per mode, shared by every channel): a
place is found whatever the structure's shapes are where its sensors are, and on the F-16, whose sensors sit near
an interface with several degrees of freedom and not at a joint's two ends, that is what placed it. Free inputs
also let a pair whose stroke holds the true one (a chain's acc3–acc6 around acc4–acc5) or a neighbour of it
explain nearly the same change, and on the independent ground vibration tests (`benchmarks/structures_gvt.py`)
the true place lost that way in 10 of 84 joints, by ΔBIC 9 to 2 400 against evidences of 19 000 to 69 000.

Reciprocity fixes the inputs: a force between sensors a and b drives mode r through φ_a − φ_b, and the response
to the shaker holds the shapes, ``A_or = φ_o φ_d s_r`` (d the driving point), so the joint's transfer to channel
o is ``Σ_r κ_r A_or / (iω − λ_r) + c.c.`` with ``κ_r = (A_ar − A_br) / A_dr``, measured, real for normal modes,
one scale left to the law's coefficients. Where places come within `RIVAL` of the evidence, they are weighed so,
at every channel that may be the driving point (`satmd.modal.shapes.driving_point_candidates`: with few modes in
the band several sensors pass) and every law; the best kept. On those tests that placed 81 of 82 joints where the
free inputs and the fits in time after them had placed 77 of 84.
"""
from __future__ import annotations

import numpy as np

from ..modal.shapes import driving_point_candidates

RIVAL = 0.1   # a place is weighed where its ΔBIC to the best is within this share of the joint's evidence
PLACES = 5    # the spectra's best places weighed, at most


def rivals(ranked, bic: dict, evidence: float) -> list:
    """The spectra's best place and the next (up to `PLACES` in all) within `RIVAL` of ``evidence``."""
    best = bic[ranked[0]]
    return [ranked[0], *(p for p in ranked[1:PLACES] if bic[p] - best <= RIVAL * evidence)]


def drives(modal, names, driving_point=None) -> list:
    """The channels that may be at the force's point: the one named, else those the residues' signs allow."""
    if driving_point is not None:
        return [driving_point] if driving_point in names else []
    residues = np.array([[m.residues[c] for m in modal.modes] for c in names])
    poles = np.array([m.pole for m in modal.modes])
    return driving_point_candidates(names, residues, poles)


def reciprocal_inputs(modal, drive: str, place) -> np.ndarray:
    """(modes,) each mode's input from a force between ``place``'s two sensors, relative to the driving point's:
    ``Re((A_ar − A_br) / A_dr)`` = (φ_a − φ_b) / φ_d for normal modes (``b`` may be ``"ground"``: zero)."""
    def shape(c):
        return np.array([m.residues[c] for m in modal.modes], complex) if c != "ground" else 0.0

    at_drive = shape(drive)
    at_drive = np.where(np.abs(at_drive) > 0, at_drive, np.inf)
    return ((shape(place[0]) - shape(place[1])) / at_drive).real


def reciprocal_paths(modal, basis, names, drive: str, place) -> dict:
    """{channel: (shared (K, 1), own)}: `locate.paths` with each mode's input fixed by reciprocity through
    ``drive`` (`reciprocal_inputs`), its scale left to the law's coefficients."""
    n = len(modal.modes)
    a = (basis[:, 0:2 * n:2] - 1j * basis[:, 1:2 * n:2]) / 2  # 1/(iω − λ_r)
    b = (basis[:, 0:2 * n:2] + 1j * basis[:, 1:2 * n:2]) / 2  # 1/(iω − λ_r*)
    kappa = reciprocal_inputs(modal, drive, place)[None, :]
    out = {}
    for c in names:
        A = np.array([m.residues[c] for m in modal.modes], complex)[None, :]
        out[c] = (((A * a + A.conj() * b) * kappa).sum(axis=1, keepdims=True), basis[:, 2 * n:])
    return out


def weighed(places, candidates, modal, freq, names, evidence_of) -> dict:
    """{place: (BIC, driving point)}: each place at its best driving point among ``candidates`` and its best law,
    the inputs reciprocal (``evidence_of(place, transfer)`` the BIC of the place's best law with a given transfer)."""
    basis = modal.basis(freq)
    return {p: min((evidence_of(p, reciprocal_paths(modal, basis, names, d, p)), d) for d in candidates)
            for p in places}

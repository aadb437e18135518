"""Which model of a structure is kept: of places the spectra cannot tell apart (`rivals`, weighed with the mode
shapes' inputs by `weighed`), of laws at one place (`best_fitting`), of places fitted in time (`best_place`).

`locate_joint` leaves each mode's input from the joint, κ_r, free (one per mode, shared by every channel): a
place is found whatever the structure's shapes are where its sensors are, and on the F-16, whose sensors sit near
an interface with several degrees of freedom and not at a joint's two ends, that is what placed it. Free inputs
also let a pair whose stroke holds the true one (a chain's acc3–acc6 around acc4–acc5) or a neighbour of it
explain nearly the same change, and on the independent ground vibration tests (`benchmarks/structures_gvt.py`)
the true place lost that way in 10 of 84 joints, by ΔBIC 345 to 2 392 against evidences of 19 000 to 69 000.

Reciprocity fixes the inputs: a force between sensors a and b drives mode r through φ_a − φ_b, and the response
to the shaker holds the shapes, ``A_or = φ_o φ_d s_r`` (d the driving point), so the joint's transfer to channel
o is ``Σ_r κ_r A_or / (iω − λ_r) + c.c.`` with ``κ_r = (A_ar − A_br) / A_dr``, measured, real for normal modes,
one scale left to the law's coefficients. Where places come within `RIVAL` of the evidence, they are weighed so,
at every channel that may be the driving point (`satmd.modal.shapes.driving_point_candidates`: with few modes in
the band several sensors pass) and every law, and the best is kept; where that moves the place off the spectra's
first, the fits in time (`best_place`) leave it, their first fits following the free inputs' path. On those tests
29 had such places: weighed so, the place came out right in 83 of the 84 joints where the free inputs alone placed
74 (a script in /tmp, not kept), and with the fits in time still checking the places it confirms (a beam's
support, 62, placed by them), `benchmarks/structures_gvt.py` places 84 of 84 where it placed 77. The F-16's places are not
weighed: its next place is a quarter of the evidence behind, and reciprocity through its driving point (acc1)
would rank its interface last, its sensors near the joint, not at its ends.
"""
from __future__ import annotations

import numpy as np

from ..modal.shapes import driving_point_candidates
from .linear import LinearStructure
from .newtons import passive_sign, path_sign

RIVAL = 0.1     # a next place is weighed where its ΔBIC to the best is within this share of the joint's evidence
PLACES = 5      # the spectra's best places weighed (`weighed`) or, where no driving point is read, simulated (`best_place`)
SPARSE_MARGIN = 0.1
PLACE_LAWS = 2  # laws fitted at each next place: the best place's best simulated
FINISH_MARGIN = 0.15  # a named law whose first fit came within this share of the chosen one's is finished too
FINISHED_RIVALS = 2   # at most this many (`close_rivals`)


def rivals(ranked, bic: dict, evidence: float) -> list:
    """The spectra's best place and the next (up to `PLACES` in all) within `RIVAL` of ``evidence``."""
    best = bic[ranked[0]]
    return [ranked[0], *(p for p in ranked[1:PLACES] if bic[p] - best <= RIVAL * evidence)]


def drives(modal, names, driving_point=None) -> list:
    """The channels that may be at the force's point: the one named, else those the residues' signs allow."""
    if driving_point is not None:
        return [driving_point] if driving_point in names else []
    shapes = _as_linear(modal, names)
    return driving_point_candidates(names, shapes.residues, shapes.poles)


def reciprocal_inputs(modal, drive: str, place) -> np.ndarray:
    """(modes,) each mode's input from a force between ``place``'s two sensors, relative to the driving point's:
    ``Re((A_ar − A_br) / A_dr)`` = (φ_a − φ_b) / φ_d for normal modes (``b`` may be ``"ground"``), 0 for a mode the
    driving point does not see (`LinearStructure.coupling`)."""
    names = tuple(dict.fromkeys(c for c in (*place, drive) if c != "ground"))
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = _as_linear(modal, names).coupling(*place, drive).real
    return np.where(np.isfinite(kappa), kappa, 0.0)


def _as_linear(modal, names):
    """A `ModalFit`'s modes as a `LinearStructure` of ``names`` (no residual terms)."""
    return LinearStructure(tuple(names), np.array([m.pole for m in modal.modes], complex),
                           np.array([[m.residues[c] for m in modal.modes] for c in names], complex).reshape(len(names), -1),
                           np.zeros(len(names)))


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


def told(location) -> str:
    """How a `JointLocation`'s ``location`` was weighed with the mode shapes' inputs, in words."""
    weighed = [e for e in location if e.get("inputs") == "reciprocal"]
    first = min(weighed, key=lambda e: e["spectra_delta_bic"])
    return (f"placed among the {len(weighed)} places the spectra could not tell apart with each mode's input from the "
            f"mode shapes (reciprocity through {location[0]['driving_point']})"
            + (f"; with free inputs {' and '.join(first['between'])} came first, this place ΔBIC "
               f"{location[0]['spectra_delta_bic']:.0f} behind" if first is not location[0] else ""))


def best_place(fit, loc, model, laws, others, files):
    """``model`` (at the spectra's best place), or the model at one of the next places (`PLACES`, those within
    `RIVAL` of the joint's evidence) where it simulates every level better: each next place is fitted with ``laws``
    (the best place's best simulated), each place keeps its best law (`best_fitting`), the place kept is the one
    whose model has the least misfit on the whole records (`fit._Fit.misfit`: the squared error its output-error
    fit minimised), and ``others`` are weighed there too.

    The spectra weigh each level's change at the excited lines, through a frequency-domain model that misses
    some of the top level's change; on independent ground vibration tests the true place was second or third in
    5 of 6 misplaced joints (the spectra's ΔBIC 116 to 2366, against an evidence of 14000 to 59000), and fitted
    with the true law it simulated the four levels better in all 5 (a beam's support: mean NRMSE 0.022 against
    0.049, the held-out levels 0.047 against 0.17). The law the spectra name at a next place is often the sparse
    library, which fitted worse there than a named law (0.11 against 0.022).

    The models are weighed as first fitted (their paths the frequency-domain start's), not finished: finishing
    every law at every place, on ground vibration tests 0-39, placed a chain's clearance right (the true place's
    mean NRMSE 0.067 against 0.096 finished, 0.143 against 0.105 before) but took two wings' cubic joints to the
    next place and named a beam's cubic a saturating spring that stiffened (its sign open in relative units):
    placed 32/36 and named 31/36, against 33 and 33. Judged with the path held, the chain stayed misplaced.

    Places on the misfit, laws on the mean NRMSE: on an independent chain with a clearance, the true place's first
    fit had the higher mean NRMSE (0.182 against 0.150 at its neighbour) and the lower misfit (0.229 against 0.276):
    a few channels far off weigh more in the squared error, as they do where the joint acts. Over the 26 ground
    vibration tests where a next place is simulated, that placed the chain (its worst held-out NRMSE 0.089 → 0.029)
    and a wing's root (named clearance, not its cubic); two misplaced chains moved to other wrong places (a friction
    now named), and the 20 placed before kept their place, law and held-out NRMSE.

    Five places, not three: on the tests after 39 a beam's support and two wings' roots to the ground (clearance 82,
    cubic 75 and 99) were fourth or fifth by the spectra, within `RIVAL` of the evidence; simulated, two of the
    three fitted the levels best at their true place (the beam 0.177 against 0.202, its held-out levels
    0.012-0.052 against 0.034-0.73)."""
    def free(e):  # a place's ΔBIC with free inputs (`weighed` keeps it beside its own)
        return e.get("spectra_delta_bic", e["delta_bic"])

    if loc.reciprocal and free(loc.location[0]) > 0:
        return model  # the mode shapes' inputs moved the place off the spectra's first: a first fit's path is theirs
    ranked = sorted(loc.location, key=lambda e: (free(e), tuple(e["between"])))
    rivals = [tuple(e["between"]) for e in ranked[1:PLACES] if free(e) <= RIVAL * loc.evidence]
    if not rivals or not laws or model.joint is None:
        return model
    fit.say(f"the next {len(rivals)} place(s) by the spectra ({', '.join(' and '.join(p) for p in rivals)}), "
            f"{' and '.join(laws)} fitted at each on every level ...")
    tried = [model, *fit.laws([(p, w) for p in rivals for w in laws], files)]
    at: dict = {}  # place -> its best law (`best_fitting`)
    for m in tried:
        if m.joint is not None:
            at.setdefault(m.joint.between, []).append(m)
    kept = [(fit.misfit(m), m) for m in (best_fitting(models) for models in at.values())]
    fit.say("; ".join(f"{' and '.join(m.joint.between)} ({m.joint.law}): mean NRMSE {score(m):.4f}, misfit {c:.4g}"
                      for c, m in kept))
    best = min(kept, key=lambda pair: pair[0])[1]
    if best.joint.between == model.joint.between or not others:
        return best
    fit.say(f"{', '.join(others)} between {best.joint.between[0]} and {best.joint.between[1]}: each fitted ...")
    here = [m for m in tried if m.joint is not None and m.joint.between == best.joint.between]
    return best_fitting([*here, *fit.laws([(best.joint.between, w) for w in others], files)])


def close_rivals(model, tried) -> list:
    """The named laws of ``tried`` at ``model``'s place to finish beside it, best first: for the sparse library the
    best named law; for a named law, up to `FINISHED_RIVALS` others whose first fits came within `FINISH_MARGIN`
    of its score, none contradicting its name (`contradicts`).

    As first fitted, every law's path is the frequency-domain start's, which suits some laws better than others:
    on an independent wing with a stick-slip joint the first fits ranked cubic 0.032, softening 0.034, friction
    0.036 (mean NRMSE), and finished, the friction fitted the levels at 0.011 against the cubic's 0.016."""
    if model.joint is None:
        return []
    named = sorted((m for m in tried if m.joint is not None and m.joint.between == model.joint.between
                    and m.joint.law not in ("sparse", model.joint.law) and not contradicts(m)), key=score)
    if model.joint.law == "sparse":
        return named[:1]
    return [m for m in named if score(m) <= (1 + FINISH_MARGIN) * score(model)][:FINISHED_RIVALS]


def ranked_laws(models) -> list:
    """The named laws of ``models`` (one place), best simulated first (`score`); the sparse library last."""
    ranked = sorted((m for m in models if m.joint is not None), key=lambda m: (m.joint.law == "sparse", score(m)))
    return [m.joint.law for m in ranked]


def best_fitting(models):
    """Of models of one structure with different laws, the one that simulates its recordings best (mean NRMSE
    over every recording and channel); the sparse library only where it beats every named law by more than
    `SPARSE_MARGIN` (its terms fit what a named law leaves, and predict the levels it did not see no better);
    a law whose fitted sign contradicts its name is not that law (`contradicts`)."""
    named = [m for m in models if m.joint is not None and m.joint.law != "sparse" and not contradicts(m)]
    sparse = [m for m in models if m.joint is not None and m.joint.law == "sparse"]
    best = min(named, key=score) if named else None
    if sparse and (best is None or score(sparse[0]) < (1 - SPARSE_MARGIN) * score(best)):
        best = sparse[0]
    return best if best is not None else models[0]


def score(model) -> float:
    """Mean NRMSE of a model's fit table over every recording and channel (inf without a joint)."""
    return float(np.mean(model.fit["nonlinear"])) if model.joint is not None else np.inf


#: law -> its coefficients whose sign the name fixes (positive, as a force that restores or resists): a saturating
#: spring with k_sat < 0 stiffens with the stroke, a clearance with k_contact < 0 gives way beyond its gap, a
#: friction or a quadratic damping of negative sign feeds the structure energy (on an independent chain with a
#: saturating joint, a giving clearance simulated the levels best and was named a clearance; on frames and beams
#: with cubic joints, a stiffening saturating spring in relative units was named softening)
NAMED_SIGN = {"softening": ("k_sat",), "clearance": ("k_contact",), "friction": ("k_stick", "f_slip"),
              "quadratic_damping": ("c2",)}


def contradicts(model) -> bool:
    """A law fitted with the sign its name excludes (`NAMED_SIGN`): not that law, whatever it fits. In newtons the
    coefficient's own sign; in relative units its sign times the path's where the modes' shapes at the driving
    point give that (`newtons.path_sign`), else where the joint's own path does (`newtons.passive_sign`);
    otherwise open, and the law is kept."""
    joint = model.joint
    values = joint.parameters() if joint.law in NAMED_SIGN else {}
    signed = [values[k] for k in NAMED_SIGN.get(joint.law, ()) if k in values]
    if not signed:
        return False
    sign = 1 if joint.units == "N" else (path_sign(model) or passive_sign(model))
    return any(sign * v < 0 for v in signed)

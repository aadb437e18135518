"""`locate_joint`: between which two sensors (or a sensor and the ground) a joint acts, and its law.

For recordings of one structure at several levels (periodic force, one period length, one set of
channels), with the lowest level as the linear reference ``H_o = A_o / F`` (its best linear
approximation), every higher level's change ``E_o = A_o − H_o F`` is, at each excited line and on every
channel o, the response to the joint's force: ``E_o(ω) = Σ_j T_oj(ω) G_j(ω)``, where ``G_j`` are the
spectra of the law's terms of the pair's relative motion (`satmd.structure.laws`) and ``T_oj`` are
transfer functions on the structure's own poles (fitted at the reference level by `satmd.modal.fit_modes`),
linear in their coefficients, so each pair and law is one weighted linear least-squares fit, all levels
and channels at once (the nonlinear force as a feedback input: FNSI, Noël & Kerschen 2013, here in the
frequency domain with the poles known). A force anywhere reaches channel o through mode r in proportion to
the mode's shape there, which the measured column already holds (the reference residue A_or): so
``T_oj = Σ_r κ_rj A_or / (iω − λ_r) + c.c.`` plus each channel's own residual terms (the modes outside the
band), with the joint's input to each mode, κ_rj, one for every channel (`paths`). The input is left free,
not built from the mode shapes at the two sensors: their column of the structure was never measured, and a
guess of it (reciprocity through the driving point) ranked the F-16's true place last; it weighs only the places
the free inputs cannot tell apart (`choice.weighed`: a pair around the true one on a chain). Places are ranked
with κ complex (a place is found whatever phase its modes take the force in); the laws at the best place
with κ real (`real_inputs`: a law in the stroke and one in the velocity are then told apart) and each
law's shape refined off its grid. On 40 chains (`benchmarks/structures_joint.py`) that placed 35 joints and
named 32 laws; free per-channel transfers had placed 31 and named 26.

The stroke a law is evaluated on is made from every line from the band's lowest up to 0.8 of Nyquist
(`PeriodicSpectra.motion`), not from the excited lines alone: the joint's harmonics, and the modes above the band
they ring (a wing's root bounce), move its two ends as much as the force does. On the independent ground
vibration tests (seeds 0-39, the place and law of `benchmarks/structures_gvt_locate.py`) that placed 33 of 36
joints and named 20 laws where the excited lines placed 30 and named 17 (the nulls as before); on their sweeps
(`benchmarks/structures_gvt_sweeps.py`) 7 of 10 where the excited lines placed 5.

Evidence: BIC = N ln(RSS/N) + p ln N per pair and law. Rows are weighted by each channel's mean response
at that level, not by each line's noise: between levels far above the noise the misfit is the model's
(the poles of one level, the joint's terms from the measured motion), which scales with the response, and
weighting by the noise let the quietest lines decide (on the F-16 it put the joint between acc2 and the
ground). A law with a shape constant (a clearance's gap, a friction's smoothing) is tried at each of
`laws.SHAPE_GRID`'s values and keeps its best, counted as one parameter more. A pair's
evidence is its best law's; pairs are ranked by ΔBIC to the best, and those within `EQUIVALENT` are
listed as equivalent places, never dropped. At the best pair the laws are ranked the same way; the
``sparse`` library is named only when it beats every named law by more than `EQUIVALENT`.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from ..conventions import TINY
from ..numerics import unit_columns
from ..errors import DataError
from ..validation import NAMES, Band, validate_params
from . import choice
from .laws import LAWS, SHAPE_GRID
from .simulations import fitted_realisations
from .spectra import PeriodicSpectra, periodic_spectra

#: ΔBIC within which two places (or two laws) are equally supported (SPEC §11).
EQUIVALENT = 10.0
#: lines the places and laws are weighed at, at most: a sweep's record padded to one period has a line every
#: 1/(its length) Hz (80 s of a ground vibration test swept 40 → 5 Hz: 3 500), each exact, and every k-th of them
#: weighs as well at a k-th of the cost; the motion a law sees is still made from every line
MAX_LINES = 1024


@dataclass(frozen=True)
class JointLocation:
    """Where a joint acts and what it does, with the evidence for every place and law (SPEC §11).

    Attributes
    ----------
    between : (a, b) the best pair (``b`` may be ``"ground"``)
    location : [{"between": [a, b], "delta_bic": x, "law": name}, ...] every pair, best first
    law : the law named at the best pair
    laws : [{"law": name, "delta_bic": x}, ...] at the best pair, best first
    equivalent_places, equivalent_laws : those within `EQUIVALENT` of the best (the best excluded)
    evidence : BIC of "one linear structure at every level" (no joint) minus the best joint's: a joint is
        ``detected`` when it is above `EQUIVALENT`
    reference : the source of the level taken as linear; levels: force RMS of every recording
    poles_hz : the structure's modes used (f in Hz, ζ)
    shape : the chosen law's shape constants at the best place (`JointLaw.all_terms` order: a gap, a smoothing)
    form : the chosen law's own terms in the form that explained the levels best (`JointLaw.forms`)
    """

    between: tuple
    location: list
    law: str
    laws: list
    equivalent_places: list
    equivalent_laws: list
    reference: str
    levels: list
    poles_hz: list = field(default_factory=list)
    evidence: float = 0.0
    shape: np.ndarray | None = field(default=None, repr=False)
    form: tuple = ()

    @property
    def detected(self) -> bool:
        """Whether a joint explains the change between levels better than noise does (ΔBIC > `EQUIVALENT`)."""
        return self.evidence > EQUIVALENT

    @property
    def reciprocal(self) -> bool:
        """Whether the place was chosen among the spectra's closest with the inputs the mode shapes give
        (`choice.weighed`): the first entries of ``location`` say ``"inputs": "reciprocal"``, their ΔBIC so weighed."""
        return bool(self.location) and self.location[0].get("inputs") == "reciprocal"

    def to_dict(self) -> dict:
        """The SPEC §11 fields: between, location, law, equivalent (laws), levels."""
        return {"name": "joint", "detected": self.detected, "evidence_delta_bic": round(float(self.evidence), 1),
                "between": list(self.between), "location": self.location, "law": self.law,
                "equivalent": [{"law": e["law"], "delta_bic": e["delta_bic"]} for e in self.equivalent_laws],
                "equivalent_places": self.equivalent_places, "reference": self.reference,
                "levels": self.levels, "modes": [{"f_hz": f, "zeta": z} for f, z in self.poles_hz]}

    def plot(self, path, title: str = ""):
        """The sensors with the joint drawn between two of them, and ΔBIC per place (`figures.joint_figure`)."""
        from .figures import joint_figure

        return joint_figure(self, path, title)

    def report(self) -> str:
        """The verdict in words."""
        a, b = self.between
        if not self.detected:
            return (f"no joint: one linear structure explains every level (the best place, {a} and {b}, gains "
                    f"ΔBIC {self.evidence:.0f} over none)")
        nxt = self.location[1] if len(self.location) > 1 else None
        lines = [f"joint between {a} and {b}" + (f" (next: {' and '.join(nxt['between'])}, ΔBIC {nxt['delta_bic']:.0f})"
                                                if nxt else ""),
                 f"law: {self.law} ({LAWS[self.law].description})"]
        if self.reciprocal:
            lines.append(choice.told(self.location))
        if self.equivalent_places:
            lines.append("equally supported places: " + "; ".join(" and ".join(e["between"]) for e in self.equivalent_places))
        if self.equivalent_laws:
            lines.append("equally supported laws: " + ", ".join(e["law"] for e in self.equivalent_laws))
        return "\n".join(lines)


@validate_params({"laws": [None, NAMES], "band_hz": [None, Band()], "channels": [None, NAMES]})
def locate_joint(recordings, laws=None, band_hz=None, channels=None, driving_point: str | None = None) -> JointLocation:
    """Between which two sensors a joint acts and which law it follows, from recordings at several levels.

    Parameters
    ----------
    recordings : two or more Recordings of one structure (a periodic force, one period length and sample
        rate, the same channels); the lowest force level is the linear reference.
    laws : law names to compare (default every law of `satmd.structure.laws.LAWS`)
    band_hz : (lo, hi) Hz of the excited band to use (default all of it)
    channels : the response channels (default every channel but the force)
    driving_point : the channel at the force's point, where places the spectra cannot tell apart are weighed
        with the inputs the mode shapes give (`choice.weighed`); default: each channel the residues' signs allow

    Returns
    -------
    JointLocation

    Raises
    ------
    DataError
        Fewer than two recordings, a force that is not periodic, recordings of another design (period,
        rate, channels), fewer than two response channels, or a driving point that is not one of them.
    """
    ref, others, names, rows, H, transfer, modal = prepare(recordings, band_hz, channels)
    if driving_point is not None and driving_point not in names:
        raise DataError(f"the driving point {driving_point!r} is not a channel ({', '.join(names)})")
    items = [ref, *others]
    places = [(a, b) for a, b in itertools.combinations(names, 2)] + [(a, "ground") for a in names]
    chosen = [LAWS[n] for n in (laws or LAWS)]
    bic: dict = {(p, law_.name): best_shape(p, law_, others, ref, H, names, rows, transfer)[0]
                 for p in places for law_ in chosen}
    bic[None] = _evidence(None, None, others, ref, H, names, rows, transfer)
    per_place = {p: min(bic[(p, law_.name)] for law_ in chosen) for p in places}
    ranked = sorted(places, key=lambda p: (per_place[p], p))
    weigh = choice.rivals(ranked, per_place, bic[None] - per_place[ranked[0]])
    reciprocal: dict = {}
    if bic[None] - per_place[ranked[0]] > EQUIVALENT and len(weigh) > 1:
        drives = choice.drives(modal, names, driving_point)
        freq = ref.lines[rows[id(ref)]] * ref.fs_hz / ref.period_samples
        reciprocal = choice.weighed(weigh, drives, modal, freq, names, lambda p, tr: min(
            best_shape(p, law_, others, ref, H, names, rows, tr)[0] for law_ in chosen)) if drives else {}
    at = min(reciprocal, key=lambda p: (reciprocal[p][0], p)) if reciprocal else ranked[0]
    real = real_inputs(transfer)
    named = {law_.name: best_shape(at, law_, others, ref, H, names, rows, real, refine=True) for law_ in chosen}
    return _verdict(bic, places, chosen, ref, items, modal, named, reciprocal)


def shape_of(recordings, between, law_name: str, channels=None):
    """(the law in its form, its shape constants): ``law_name`` at ``between`` as it explains the level changes best
    (`best_shape`)."""
    ref, others, names, rows, H, transfer, _ = prepare(recordings, None, channels)
    _, aux, form = best_shape(tuple(between), LAWS[law_name], others, ref, H, names, rows, real_inputs(transfer),
                              refine=True)
    return form, aux


def best_shape(place, law_, others, ref, H, names, rows, transfer, refine=False):
    """(BIC, shape constants, the law in its form) of a law at a place at its best form (`JointLaw.variants`) and
    shape (a gap, a friction's smoothing or stick stroke, a saturating spring's stroke) of `JointLaw.shapes`; with
    ``refine``, the best of the grid is refined between its neighbours (a joint's gap is seldom on the grid, and a
    law off its shape loses to the sparse library); one more parameter counted when there was a choice."""
    d0, v0 = ref.scales(*place)
    tried = [(form, aux) for form in law_.variants() for aux in form.shapes(d0, v0)]
    found = [(_evidence(place, form, others, ref, H, names, rows, transfer, aux), i)
             for i, (form, aux) in enumerate(tried)]
    value, i = min(found)
    law_, best = tried[i]
    tried = [aux for form, aux in tried if form is law_]
    i = next(j for j, aux in enumerate(tried) if aux is best)
    if refine and len(tried) > 1:
        from scipy.optimize import minimize_scalar

        shaped = np.array([t in SHAPE_GRID for t in law_.all_terms])
        def step(j):  # log of the grid's step to neighbour j (a factor 2 past either end)
            return np.log(tried[j][shaped][0] / best[shaped][0]) if 0 <= j < len(tried) else np.log(2.0) * (j - i)

        lo, hi = step(i - 1), step(i + 1)

        def scaled(u):
            return np.where(shaped, best * np.exp(u), best)

        res = minimize_scalar(lambda u: _evidence(place, law_, others, ref, H, names, rows, transfer, scaled(u)),
                              bounds=(lo, hi), method="bounded", options={"xatol": 0.05, "maxiter": 12})
        if res.fun < value:
            value, best = float(res.fun), scaled(res.x)
    n = sum(2 * k.size for k in rows.values() if k is not rows[id(ref)]) * len(names)
    return value + (np.log(n) if len(found) > 1 else 0.0), best, law_


def prepare(recordings, band_hz=None, channels=None):
    """What locating and fitting share: (reference, other levels, channels, rows of the common lines in each,
    the reference FRF per channel, the joint's transfer columns per channel (`paths`), the modal fit)."""
    from ..modal import fit_modes

    items = [r if isinstance(r, PeriodicSpectra) else periodic_spectra(r) for r in fitted_realisations(recordings)]
    if len(items) < 2:
        raise DataError("locating a joint needs recordings at two or more levels")
    ref = min(items, key=lambda s: s.level)
    names = list(channels or ref.responses)
    for s in items:
        if s.period_samples != ref.period_samples or s.fs_hz != ref.fs_hz:
            raise DataError(f"{s.source}: period {s.period_samples} samples at {s.fs_hz:g} Hz, {ref.source}: "
                            f"{ref.period_samples} at {ref.fs_hz:g} Hz; the levels of one test share one design")
        missing = [c for c in names if c not in s.responses]
        if missing:
            raise DataError(f"{s.source}: no channel {', '.join(missing)} (the other levels have it)")
    if len(names) < 2:
        raise DataError("locating a joint between sensors needs two or more response channels")
    common = ref.lines
    for s in items:
        common = np.intersect1d(common, s.lines)
    freq = common * ref.fs_hz / ref.period_samples
    if band_hz is not None:
        keep = (freq >= (band_hz[0] or 0.0)) & (freq <= (band_hz[1] or np.inf))
        common, freq = common[keep], freq[keep]
    if common.size < 8:
        raise DataError(f"the levels share {common.size} excited lines; at least 8 are needed")
    if common.size > MAX_LINES:  # a long sweep's record: every line holds, a share of them says as much
        common = common[::int(np.ceil(common.size / MAX_LINES))]
        freq = common * ref.fs_hz / ref.period_samples
    rows = {id(s): np.searchsorted(s.lines, common) for s in items}
    H = {c: ref.responses[c][rows[id(ref)]] / ref.force[rows[id(ref)]] for c in names}
    modal = fit_modes(freq, H, band_hz=(float(freq[0]), float(freq[-1])))
    others = [s for s in items if s is not ref]
    return ref, others, names, rows, H, paths(modal, modal.basis(freq), names), modal


def paths(modal, basis, names) -> dict:
    """{channel: (shared, own)}: the columns of the joint's transfer to each channel. ``shared`` (K, 2 modes):
    mode r's pair scaled by the channel's reference residue A_or, times the real and the imaginary part of the
    joint's input to mode r, κ_r, which every channel shares; ``own`` (K, 6): the residual terms of the modes
    outside the band, the channel's own. `real_inputs` keeps κ real."""
    n = len(modal.modes)
    a = (basis[:, 0:2 * n:2] - 1j * basis[:, 1:2 * n:2]) / 2  # 1/(iω − λ_r), from the basis's (a + b, i(a − b))
    b = (basis[:, 0:2 * n:2] + 1j * basis[:, 1:2 * n:2]) / 2  # 1/(iω − λ_r*)
    out = {}
    for c in names:
        psi = np.array([m.residues[c] for m in modal.modes], complex)
        shared = np.stack([psi * a + psi.conj() * b, 1j * (psi * a - psi.conj() * b)], axis=2).reshape(a.shape[0], -1)
        out[c] = (shared, basis[:, 2 * n:])
    return out


def real_inputs(transfer) -> dict:
    """`paths` with each mode's input κ_r real: a structure's real modes take a joint's force as the real
    difference of their shapes at its two ends, so its phase is the measured column's, and a law's terms in the
    stroke and in the velocity (a quarter period apart) are told apart."""
    return {c: (shared[:, 0::2], own) for c, (shared, own) in transfer.items()}


def unexplained(recordings, between, law_name: str, channels=None) -> float:
    """The share of the levels' change from the lowest level's FRF that a law at a place leaves unexplained, as
    `locate_joint` weighs it (each mode's input real), at the best of the law's shapes (`JointLaw.shapes`).

    Parameters
    ----------
    recordings : two or more Recordings (or `PeriodicSpectra`) of one structure, as for `locate_joint`
    between : (a, b) the pair (``b`` may be ``"ground"``)
    law_name : one of `satmd.structure.laws.LAWS`
    channels : the response channels (default every channel but the force)

    Returns
    -------
    float
        The weighted residual's sum of squares over the change's, 0 (all explained) to 1.
    """
    ref, others, names, rows, H, transfer, _ = prepare(recordings, None, channels)
    real, law_ = real_inputs(transfer), LAWS[law_name]
    d0, v0 = ref.scales(*between)
    shares = []
    for form in law_.variants():
        for aux in form.shapes(d0, v0):
            rss, total, _, _ = _regression(tuple(between), form, others, ref, H, names, rows, real, aux)
            shares.append(rss / max(total, TINY))
    return float(min(shares))


def _evidence(place, law_, others, ref, H, names, rows, transfer, aux=None) -> float:
    """BIC of one place and law (`_regression`)."""
    rss, _, n_rows, n_par = _regression(place, law_, others, ref, H, names, rows, transfer, aux)
    return n_rows * np.log(max(rss, TINY) / n_rows) + n_par * np.log(n_rows)


def _regression(place, law_, others, ref, H, names, rows, transfer, aux=None):
    """(residual sum of squares, the change's sum of squares, rows, parameters) of one place and law: every channel
    and higher level in one weighted linear least-squares fit, the joint's input to each mode shared by every
    channel (``place`` None: no joint, the levels one linear structure)."""
    G: dict = {id(s): [] for s in others}
    if place is not None:
        d0, v0 = ref.scales(*place)
        for s in others:  # the stroke from every line: the joint's harmonics ring modes above the band
            G[id(s)] = [s.at_lines(t)[rows[id(s)]] for t in law_.columns(*s.relative(*place, whole=True), d0, v0, aux)]
    n_terms = len(G[id(others[0])])
    S_parts, y_parts, n_par, total = [], [], 0, 0.0
    for c in names:  # each channel's own residual terms projected out first: the shared fit is then small
        shared, own = transfer[c]
        S_c, R_c, y_c = [], [], []
        for s in others:
            k = rows[id(s)]
            E = s.responses[c][k] - H[c] * s.force[k]
            sd = np.mean(np.abs(s.responses[c][k]))
            S = np.hstack([shared * g[:, None] for g in G[id(s)]]) if n_terms else np.zeros((k.size, 0))
            R = np.hstack([own * g[:, None] for g in G[id(s)]]) if n_terms else np.zeros((k.size, 0))
            S_c += [S.real / sd, S.imag / sd]
            R_c += [R.real / sd, R.imag / sd]
            y_c += [E.real / sd, E.imag / sd]
        S, R, y = np.vstack(S_c), unit_columns(np.vstack(R_c))[0], np.concatenate(y_c)
        total += float(y @ y)
        if R.shape[1]:
            U, sv, _ = np.linalg.svd(R, full_matrices=False)
            U = U[:, sv > sv[0] * 1e-10] if sv[0] > 0 else U[:, :0]
            S, y = S - U @ (U.T @ S), y - U @ (U.T @ y)
            n_par += U.shape[1]
        S_parts.append(S)
        y_parts.append(y)
    S, y = unit_columns(np.vstack(S_parts))[0], np.concatenate(y_parts)
    r = y - S @ np.linalg.lstsq(S, y, rcond=None)[0] if S.shape[1] else y
    return float(r @ r), total, y.size, n_par + S.shape[1]


def _verdict(bic, places, laws, ref, items, modal, named, reciprocal=None) -> JointLocation:
    """The places ranked by their best law's evidence (each mode's input complex: a place is found whatever the
    phase its modes take the force in), those ``reciprocal`` weighed, {place: (BIC, driving point)}, first by that
    (`choice.weighed`); the laws at the best place ranked by ``named``, {law: (BIC, shape)} with real inputs
    (`real_inputs`)."""
    per_place = {p: min(((bic[(p, law_.name)], law_.name) for law_ in laws)) for p in places}
    ranked = sorted(places, key=lambda p: (per_place[p][0], p))
    best_bic = per_place[ranked[0]][0]
    delta = {p: per_place[p][0] - best_bic for p in places}
    weighed: dict = {}
    if reciprocal:
        top = sorted(reciprocal, key=lambda p: (reciprocal[p][0], p))
        ranked = top + [p for p in ranked if p not in reciprocal]
        weighed = {p: {"inputs": "reciprocal", "driving_point": reciprocal[p][1],
                       "spectra_delta_bic": round(float(delta[p]), 1)} for p in top}
        delta.update({p: reciprocal[p][0] - reciprocal[top[0]][0] for p in top})
    at = ranked[0]
    law_bic = sorted(((named[law_.name][0], law_.name) for law_ in laws))
    plain = [x for x in law_bic if x[1] != "sparse"]
    sparse = [x for x in law_bic if x[1] == "sparse"]
    if plain and not (sparse and sparse[0][0] < plain[0][0] - EQUIVALENT):
        chosen_bic, chosen = plain[0]
    else:
        chosen_bic, chosen = law_bic[0]
    location = [{"between": list(p), "delta_bic": round(float(delta[p]), 1),
                 "law": chosen if p == at else per_place[p][1], **weighed.get(p, {})} for p in ranked]
    laws_out = [{"law": n, "delta_bic": round(float(v - chosen_bic), 1)} for v, n in law_bic]
    return JointLocation(
        between=tuple(at), location=location, law=chosen, laws=laws_out,
        equivalent_places=[e for e in location[1:] if e["delta_bic"] <= EQUIVALENT],
        equivalent_laws=[e for e in laws_out if e["law"] != chosen and e["delta_bic"] <= EQUIVALENT],
        reference=ref.source, levels=[round(float(s.level), 6) for s in items], shape=named[chosen][1],
        form=named[chosen][2].term_names,
        poles_hz=[(round(float(m.f_hz), 4), round(float(m.zeta), 5)) for m in modal.modes],
        evidence=float(bic[None] - best_bic))

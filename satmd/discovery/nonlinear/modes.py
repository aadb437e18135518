"""The level dependence of a structure the SATMD model cannot describe, told per resonance (SPEC §9).

When several levels of one structure are judged and the SATMD model is not adequate for them, no
SATMD element may be named: a joint SATMD fit would turn any change into one of its own parameters.
The finding is ``nonlinear_unexplained`` with ``modes``: the modes of every level from a multi-mode
fit (`satmd.modal.fit_modes`), fitted level by level from one set of modes (`satmd.modal.follow_modes`); a resonance is
listed when its frequency or damping moves beyond its uncertainty, and the level-dependence bands are
put where those resonances move.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...modal import follow_modes
from ..findings import NonlinearFinding
from .distortion import UNEXPLAINED_NL

MODES_ALPHA = 0.05  # family-wise level of the trend tests once a test has detected a level dependence
NOT_SATMD = "the SATMD model does not describe these data, so no SATMD element is named"
WELL = 2.0  # a joint's model within this many times the floor (`where_it_misses`): where it misses is not told


def level_modes(freq_hz, frfs, stds, levels, alpha: float = 0.05, dof=None) -> list:
    """The modes of every level followed over the levels (`satmd.modal.follow_modes`).

    Parameters
    ----------
    freq_hz : (M,) Hz, the grid of every level
    frfs : per level {channel: (M,) complex}
    stds : per level {channel: (M,) std} or None
    levels : one level figure per FRF
    alpha : family-wise level of the trend tests
    dof : degrees of freedom of the stds (their estimator's ``noise_dof``; None: many)

    Returns
    -------
    list of TrackedMode
        Empty when a level has too few frequencies for a modal fit.
    """
    try:
        return follow_modes(freq_hz, frfs, stds, levels, alpha, dof=dof)
    except ValueError:  # too few frequencies for a modal fit
        return []


def modal_finding(datas, levels, unit: str | None = None, alpha: float = 0.05) -> tuple:
    """The ``nonlinear_unexplained`` finding with ``modes``, and the bands where the resonances move.

    Parameters
    ----------
    datas : list of FRFData on one grid, one per level
    levels : one level figure per FRF (trends read from the lowest to the highest)
    unit : the levels' unit in words (e.g. ``N RMS``); None when they are only an order
    alpha : family-wise level of the trend tests

    Returns
    -------
    (NonlinearFinding, list)
        The finding and ``[[lo, hi], ...]`` Hz around each resonance that moves.
    """
    dofs = [float(d.estimator["noise_dof"]) for d in datas if d.estimator.get("noise_dof")]
    tracks = level_modes(datas[0].freq_hz, [d.channels for d in datas],
                         [d.std if d.has_std else None for d in datas], levels, alpha, min(dofs) if dofs else None)
    moving = [t for t in tracks if t.moves]
    stay = [t for t in tracks if not t.moves]
    span = _span(levels, unit)
    if len(moving) == 1:
        text = f"{_describe(moving[0], levels)} {span}"
    elif moving:
        text = f"{span}: " + "; ".join(_describe(t, levels) for t in moving)
    else:
        text = (f"the levels differ, but no resonance's frequency or damping moves beyond its uncertainty "
                f"({len(tracks)} followed over every level)")
    if moving and stay:
        text += "; the resonances at " + ", ".join(f"{t.f_hz[0]:.3g}" for t in stay) + " Hz stay within their " \
                "uncertainty"
    return _finding([t.to_dict() for t in moving], f"{text}; {NOT_SATMD}"), _bands(moving)


def unexplained_by_modes(report, datas, unit: str | None = None):
    """``report`` (a `NonlinearReport` that detected a level dependence) with its finding told per resonance.

    The trends are read at ``MODES_ALPHA`` when a test other than the SATMD-parameter one (which says
    nothing about another structure) detected the level dependence; otherwise a resonance that moves is the
    only evidence, and it is read at the tests' own level.

    Parameters
    ----------
    report : NonlinearReport of the levels
    datas : their FRFData on one grid, in the order of ``report.levels``
    unit : the levels' unit in words, or None

    Returns
    -------
    NonlinearReport
        One ``nonlinear_unexplained`` finding with ``modes``; the level-dependence tests' bands put
        where resonances move (unchanged when none does).
    """
    # the SATMD-parameter test says nothing about a structure the SATMD model cannot describe: left out
    kept = [t for t in report.tests if t.name != "level_dependence_parameters"]
    # where no test that stays detected anything, a resonance that moves is the detection: at the tests' level
    confirmed = any(t.significant for t in kept)
    alpha = MODES_ALPHA if confirmed else min([t.alpha for t in report.tests] + [MODES_ALPHA])
    finding, bands = modal_finding(datas, report.levels, unit, alpha)
    tests = [replace(t, bands_hz=bands) if bands and t.name.startswith("level_dependence") else t for t in kept]
    return replace(report, tests=tests, findings=[finding],
                   detected=any(t.significant for t in tests) or bool(finding.get("modes")))


def _finding(modes, explanation) -> NonlinearFinding:
    return NonlinearFinding(UNEXPLAINED_NL, modes=modes, explanation=explanation)


def _span(levels, unit) -> str:
    lo, hi = min(levels), max(levels)
    return f"from {lo:.3g} to {hi:.3g} {unit}" if unit else "from the lowest to the highest level"


def _describe(track, levels) -> str:
    """'the 7.32 Hz resonance softens by 2.2 % and its damping rises 4.2x' (lowest to highest level)."""
    lo, hi = min(range(len(levels)), key=lambda i: levels[i]), max(range(len(levels)), key=lambda i: levels[i])
    f0, f1, z0, z1 = track.f_hz[lo], track.f_hz[hi], track.zeta[lo], track.zeta[hi]
    moves = {"softening": f"softens by {100 * (1 - f1 / f0):.2g} %",
             "hardening": f"stiffens by {100 * (f1 / f0 - 1):.2g} %", "none": "keeps its frequency"}[track.trend]
    ratio = z1 / z0
    rises = f"rises {ratio:.2g}x" if ratio >= 1.5 else f"rises by {100 * (ratio - 1):.2g} %"
    damping = {"rising": f"its damping {rises}", "falling": f"its damping falls by {100 * (1 - ratio):.2g} %",
               "none": "its damping stays within its uncertainty"}[track.damping_trend]
    return f"the {f0:.3g} Hz resonance {moves} and {damping}"


def _bands(tracks) -> list:
    """[lo, hi] over each track's frequencies widened by its half-power half-widths; overlaps merged."""
    spans = sorted([min(f * (1 - z) for f, z in zip(t.f_hz, t.zeta)),
                    max(f * (1 + z) for f, z in zip(t.f_hz, t.zeta))] for t in tracks)
    out: list = []
    for a, b in spans:
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([float(a), float(b)])
    return out


def with_joint(report, recordings, fit_joint: bool = True):
    """``report`` (told per resonance) with the structure's joint located among its sensors (SPEC §11), when the
    recordings are periodic tests of two or more response channels and a joint explains the change between their
    levels (`satmd.structure.locate_joint`); unchanged otherwise.

    Parameters
    ----------
    report : NonlinearReport with one ``nonlinear_unexplained`` finding (`unexplained_by_modes`)
    recordings : the Recordings of the levels
    fit_joint : the joint's model fitted on every level (`satmd.structure.fit_structure`), else placed and named only

    Returns
    -------
    NonlinearReport
    """
    from ...errors import DataError
    from ...structure import locate_joint

    responses = [c for c in recordings[0].channels if c != "force"] if recordings else []
    if len(recordings) < 2 or len(responses) < 2 or not report.findings:
        return report
    from ..._progress import stage

    untrusted = untrusted_channels(recordings, responses)
    trusted = [c for c in responses if c not in untrusted]
    left_out = "; ".join(f"{c} left out ({why}: the measurement chain's, not the structure's)"
                         for c, why in untrusted.items())

    def told(why):  # the account per resonance stands, and why no joint is told
        old = report.findings[0]
        return replace(report, findings=[replace(old, explanation=f"{old.explanation}; {why}" if old.explanation
                                                 else why[:1].upper() + why[1:]), *report.findings[1:]])

    if len(trusted) < 2:
        return told(f"the joint is not located among the sensors: {left_out}; fewer than two sensors remain")
    stage(f"locating the joint among every pair of {len(trusted)} sensors and the ground ...")
    try:
        loc = locate_joint(recordings, channels=trusted)
    except DataError as err:  # not tests a joint can be located from
        return told(f"the joint is not located among the sensors: {err}")
    if not loc.detected:
        return told(f"no joint among {', '.join(trusted)} explains the change between the levels; {left_out}") \
            if untrusted else report
    a, b = loc.between
    near = [e for e in loc.location[1:] if e["delta_bic"] <= 10.0]
    model = _structure_model(recordings, loc, trusted) if fit_joint else None
    named = model.joint.law if model is not None and model.joint is not None else loc.law
    explanation = (f"a joint between {a} and {b} ({named}): its relative motion explains the change between "
                   f"the levels (ΔBIC {loc.location[1]['delta_bic']:.0f} to the next place, "
                   f"{' and '.join(loc.location[1]['between'])}"
                   + (f", each mode's input from the mode shapes through {loc.location[0]['driving_point']})"
                      if loc.reciprocal else ")") if len(loc.location) > 1 else f"a joint between {a} and {b}")
    if model is not None and model.joint is not None and tuple(model.joint.between) != tuple(loc.between):
        a, b = model.joint.between  # a next place by the spectra; simulated from the force, it fitted every level better
        gap = next(e.get("spectra_delta_bic", e["delta_bic"]) for e in loc.location if tuple(e["between"]) == (a, b))
        explanation = (f"a joint between {a} and {b} ({named}): simulated from each force, a joint there fits every "
                       f"level better than at {' and '.join(loc.between)}, which the levels' spectra ranked first "
                       f"(ΔBIC {gap:.0f} ahead)")
    if near:
        explanation += "; as well supported: " + "; ".join(" and ".join(e["between"]) for e in near)
    if untrusted:
        explanation += f"; {left_out}"
    fit = parameters = None
    if model is not None and model.joint is not None:
        fit = {k: model.fit[k] for k in ("metric", "channels", "linear", "nonlinear")}
        parameters = model.joint.parameters()
        worst_lin = max(max(r) for r in model.fit["linear"])
        worst_nl = max(max(r) for r in model.fit["nonlinear"])
        unit = (" N" if model.joint.units == "N" else
                f", relative units: the fitted path departs from the modes' shapes at the driving point "
                f"{model.driving_point} by over 30 %, so reciprocity does not fix its scale" if model.driving_point else
                ", relative units: no driving point fixes the scale")
        if worst_nl < worst_lin:
            bounds = ", ".join(f"{n} {parameters[n]:.3g} [{lo:.3g}, {hi:.3g}]" for n, (lo, hi) in model.joint.ci95.items())
            explanation += (f"; modelled ({model.joint.formula()}{unit}{'; 95 %: ' + bounds if bounds else ''}), "
                            f"simulated from each force the worst NRMSE goes from {worst_lin:.2f} (linear) to "
                            f"{worst_nl:.2f}")
            if model.acquisition is not None:  # the measurement chain's, not the structure's: said apart
                explanation += f"; {model.acquisition.describe()}"
            worst = where_it_misses(model, recordings)
            if worst is not None:
                fit["worst"] = worst
                explanation += told_miss(worst)
        else:  # said, not hidden: the place or the law the levels point to does not make a better simulation
            explanation += (f"; its model ({model.joint.formula()}{unit}) does not simulate the recordings better than "
                            f"the linear one (worst NRMSE {worst_lin:.2f} linear, {worst_nl:.2f} with the joint): the "
                            "place or the law may be wrong")
    old = report.findings[0]
    law = model.joint.law if model is not None and model.joint is not None else loc.law
    equivalent = [{"law": e["law"], "delta_bic": e["delta_bic"]} for e in loc.equivalent_laws if e["law"] != law]
    if law != loc.law:  # the levels' spectra preferred another law; simulated on every level, this one fitted best
        equivalent.insert(0, {"law": loc.law, "delta_bic": 0.0})
        explanation += (f"; {law}, not the {loc.law} the levels' spectra preferred: simulated from the force, "
                        f"it fitted every level better")
    ci95 = dict(model.joint.ci95) if model is not None and model.joint is not None else {}
    joint = NonlinearFinding("joint", between=[a, b], location=loc.location, law=law, parameters=parameters or {},
                             ci95=ci95, equivalent=equivalent,
                             modes=old.get("modes"), fit=fit,
                             explanation=explanation + (f". {old.explanation[:1].upper()}{old.explanation[1:]}"
                                                        if old.explanation else ""))
    return replace(report, findings=[joint], model=model)


def untrusted_channels(recordings, responses) -> dict:
    """{channel: why} for the response channels a structure's joint must not be located from: clipped at some
    level (a sensor on its range's stops changes with level as a joint does, harmonics and all), or constant (a
    sensor that recorded nothing)."""
    from ...io.recdata import clipped_channels

    out: dict = {}
    for i, r in enumerate(recordings, start=1):
        name = r.meta.get("source", f"recording {i}")
        clipped = clipped_channels(r)
        for c in responses:
            if c in out:
                continue
            if c in clipped:
                out[c] = f"clipped in {name}: {clipped[c]} samples at its extremes"
            elif np.ptp(np.asarray(r[c], float)) == 0:
                out[c] = f"constant in {name}: the sensor recorded nothing"
    return out


def where_it_misses(model, recordings) -> dict | None:
    """The joint's model's worst recording and channel, and how much of its miss lies above the force's band (the
    joint's harmonics and the modes they reach, which the force never showed the linear part) and how much inside
    it; None where that miss is within `WELL` times what the lowest level's linear model leaves on its own level
    (the noise, and what a linear model leaves there).

    Parameters
    ----------
    model : StructureModel with its fit table (`fit["nonlinear"]`, one row per recording)
    recordings : the Recordings it was fitted on, in the table's order

    Returns
    -------
    dict or None
        ``recording`` (its index), ``channel``, ``level`` (force RMS), ``nrmse``, ``above_band`` and
        ``inside_band`` (the NRMSE's two parts: their squares add up to its square), ``measured_above_band``
        (the response there over the channel's RMS) and ``band_top_hz``.
    """
    from ...structure.simulations import fitted_realisations

    recordings = fitted_realisations(recordings)  # the table's rows: a file's realisations each a row
    fits = [max(row) for row in model.fit["nonlinear"]]
    floor = min(max(row) for row in model.fit["linear"])
    i = int(np.argmax(fits))
    if not np.isfinite(fits[i]) or fits[i] <= WELL * floor:
        return None
    p = model.predict(recordings[i])
    c = int(np.argmax(p.nrmse))
    total, above = float(p.nrmse[c]), float(p.above_band["nrmse"][c])
    if not np.isfinite(total):
        return None
    return {"recording": i, "channel": p.channels[c], "level": round(float(p.level), 6), "nrmse": round(total, 4),
            "above_band": round(above, 4), "inside_band": round(float(np.sqrt(max(total ** 2 - above ** 2, 0.0))), 4),
            "measured_above_band": round(float(p.above_band["measured"][c]), 4),
            "band_top_hz": round(float(p.band_top_hz), 4)}


def told_miss(worst: dict) -> str:
    """`where_it_misses`'s finding as a clause of the joint's explanation."""
    head = (f"; its worst channel, {worst['channel']} at {worst['level']:.3g} N RMS, misses {worst['nrmse']:.2f} "
            "of its RMS, most of it ")
    top, above, inside, there = (worst[k] for k in ("band_top_hz", "above_band", "inside_band", "measured_above_band"))
    if above > inside:
        return head + (f"above the force's band ({top:.3g} Hz: {above:.2f}, where {there:.2f} of the response lies "
                       f"and only the joint's harmonics reach, so modes there are known from them alone; "
                       f"{inside:.2f} inside it)")
    return head + f"inside the force's band ({inside:.2f}; {above:.2f} above {top:.3g} Hz, where {there:.2f} of the response lies)"


def _structure_model(recordings, loc, channels=None):
    """The joint's model fitted on every level (`satmd.structure.fit_structure`), or None where it cannot be."""
    from ...errors import DataError
    from ...structure import fit_structure

    try:
        return fit_structure(recordings, location=loc, channels=channels)
    except DataError:
        return None

"""`discover` on several recordings of one rig, and the nonlinear check of one recording.

Several recordings (levels or repeats) are judged together: the ``nonlinear``
block (`findings.analyse_recordings`) says whether they are one
linear system; the linear vocabulary (`effects`) then runs

- on their pooled FRF (inverse-variance mean) when they are: more data, one answer;
- on the lowest level, with the parameter the nonlinear finding moves set free,
  when they are not: the nonlinearity is named once, in its own block, and a
  linear effect that only stands in for it (``parameter_offset`` of that
  parameter, ``unexplained``) is dropped from ``effects``;
- and when the SATMD model is not adequate for them (another structure), no
  SATMD element is named at all: the finding is ``nonlinear_unexplained`` told
  per resonance, from a modal fit of every level (`modes`).

A single recording in which distortion is detected keeps the linear effects
found in ``nonlinear.set_aside`` instead of ``effects``: one level cannot tell a
linear effect from an equivalent linearisation, and a nonlinear rig must not get
linear physics for its nonlinearity.

The linear discovery is passed in (``linear``: `satmd.discovery.discover`) so that
this module does not import the package it serves.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...identification.adequacy import Reason
from ...signal.several import common_frfs, is_forced_recording, on_common_grid, pooled, repeated_hits
from .findings import analyse_recordings, with_strength

_UNEXPLAINED = "unexplained"


def discover_recordings(items, linear, rig=None, free=None, alpha: float = 1e-3, fit_joint: bool = True, **kwargs):
    """Discovery on several recordings (or FRFData with std) of one rig: effects and the nonlinear block.

    Parameters
    ----------
    items : list of Recording (force, acc1, acc2) or of FRFData with std, in any level order
    linear : the linear discovery, ``linear(data, rig=..., free=..., alpha=..., **kwargs)``
    rig, free, alpha, fit_joint, **kwargs : as `satmd.discovery.discover`

    Returns
    -------
    DiscoveryReport
        With ``nonlinear`` (SPEC §9).
    """
    from ...conventions import DEFAULT_FREE
    from .findings import analyse_frfs

    free = tuple(free or DEFAULT_FREE)
    items = list(items)
    hits = repeated_hits(items)
    if hits is not None:  # hits of one test are repeats, not levels: one FRF over all of them
        return linear(hits, rig=rig, free=free, alpha=alpha, **kwargs)
    if all(is_forced_recording(x) for x in items):
        _same_sensors(items)
        unit: str | None = "N RMS"  # the levels are the recordings' force RMS
        datas = common_frfs(items)
        nl = analyse_recordings(items, rig, free, alpha, datas=datas, strength=False)  # a rig's, once it is one
        grid = on_common_grid(datas)
        datas = grid[1] if grid is not None else datas
        levels = nl.levels
    else:
        grid = on_common_grid(items)
        if grid is None:
            from ...errors import DataError

            raise DataError("the FRFs share fewer than 4 frequencies: give them on one grid")
        datas = grid[1]
        unit = "N RMS" if all("force_rms" in d.meta for d in datas) else None
        nl = analyse_frfs(datas, rig, free, alpha)
        levels = nl.levels
    finding = nl.findings[0] if nl.findings else {}
    moving = finding.get("moving")
    if not nl.detected:  # (nothing named: no strength left to fit)
        # one linear system: its FRFs pooled where they share a grid, else the lowest level's alone
        one = pooled(datas) if grid is not None else datas[int(np.argmin(levels))] if levels else datas[0]
        rep = linear(one, rig=rig, free=free, alpha=alpha, **kwargs)
        return replace(rep, nonlinear=nl)
    ref = datas[int(np.argmin(levels))] if levels else datas[0]
    free2 = free + ((moving,) if moving and moving not in free else ())
    rep = linear(ref, rig=rig, free=free2, alpha=alpha, **kwargs)
    if not rep.model_adequate:  # another structure: its level dependence is told per resonance, no element named
        from .modes import unexplained_by_modes, with_joint

        told = unexplained_by_modes(replace(nl, deferred=None), datas, unit)  # no rig's strength to fit
        if all(is_forced_recording(x) for x in items):  # many sensors: where the joint acts (SPEC §11)
            told = with_joint(told, items, fit_joint)
        return replace(rep, nonlinear=told)
    nl = with_strength(nl)  # a SATMD rig: the named element's strength fitted in time
    # with the moving parameter free, an effect that restates it (or what is left unexplained) is the
    # nonlinearity seen at one level; without one, every linear effect may be
    picked = [j.name for j in rep.judged if j.status == "named" and _stands_in(j, moving, rig)]
    why = (f"{moving} moves with level ({finding.get('direction', 'changes')}): a linear effect at one level that "
           "restates it is the nonlinearity seen there" if moving else
           "the data depend on level: a linear effect fitted at one level stands in for the nonlinearity")
    return rep.rejudged(lambda j: j.name in picked, "set_aside", [Reason("level_dependence", why, {"moving": moving})],
                        nonlinear=replace(nl, set_aside=picked))


def _same_sensors(recordings) -> None:
    """Levels of one test carry one set of sensors: a channel missing at one level is refused, named."""
    from ...errors import DataError

    first = recordings[0]
    name0 = first.meta.get("source", "recording 1")
    for i, r in enumerate(recordings[1:], start=2):
        if set(r.channels) != set(first.channels):
            name = r.meta.get("source", f"recording {i}")
            missing = sorted(set(first.channels) - set(r.channels))
            extra = sorted(set(r.channels) - set(first.channels))
            what = "; ".join(x for x in (f"no {', '.join(missing)}" if missing else "",
                                          f"{', '.join(extra)} that {name0} has not" if extra else "") if x)
            raise DataError(f"{name}: its channels differ from {name0}'s ({what}): the levels of one test are "
                            "recorded with one set of sensors")


def _stands_in(judged, moving, rig) -> bool:
    """True when a named candidate may be the nonlinearity seen at one level: the unexplained rest, any effect
    when no parameter is known to move, else an effect that changes the moving parameter itself."""
    from ...physics import Rig
    from ...physics.effects import at_rest

    if judged.name == _UNEXPLAINED or not moving:
        return True
    return getattr(at_rest(judged.name, rig or Rig()), "parameter", None) == moving


def check_one(report, recording, alpha: float = 1e-3, rig=None, free=None):
    """Add the nonlinear block to the discovery of one recording; set linear effects aside when distorted.

    Parameters
    ----------
    report : DiscoveryReport of the recording
    recording : the Recording it came from
    alpha : level of the distortion test
    rig, free : as `satmd.discovery.discover`

    Returns
    -------
    DiscoveryReport
    """
    if not is_forced_recording(recording) or not any(c in recording.channels for c in ("acc1", "acc2")):
        return report
    from ...errors import DataError

    try:
        nl = analyse_recordings([recording], rig, free or (), alpha)
    except DataError:  # too short or too narrow-band for the test: the linear report stands alone
        return report
    if not nl.detected:
        return replace(report, nonlinear=nl)
    aside = report.effect_names
    why = Reason("distortion", "the record is distorted (nonlinear): a linear effect fitted to it stands in for the "
                               "nonlinearity", {"p_value": min((float(t.p_value) for t in nl.tests if not t.not_run),
                                                               default=None)})
    return report.rejudged(lambda j: True, "set_aside", [why], nonlinear=replace(nl, set_aside=aside))

"""A structure model's simulations of recordings: the drives of the output-error fit, their cost, the fit table."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import DataError
from .model import Drive, StructureModel, nrmse
from .spectra import drive_force, warmup_of

FIT_PERIODS = 3  # steady periods of a periodic test in the output-error fit
SHRINK = (1.0, 0.5, 0.25, 0.1, 0.03, 0.01, 0.0)  # scales of the start's joint tried until the loop is stable


def fitted_realisations(recordings) -> list:
    """The realisations a structure's joint is located from and fitted on: of each file, as many of its
    realisations as make up `FIT_PERIODS` steady periods (at least one; `Recording.realisations`), as a periodic
    test gives that many of its own. The others repeat what those show at that level and would cost as much
    each (the F-16's odd multisines hold nine or ten realisations of two steady periods a level)."""
    from ..io.recdata import each_realisation
    from ..signal.excitation import excitation_of

    out = []
    for recording in recordings:
        parts = each_realisation([recording])
        if len(parts) == 1:  # one record: its excitation is read at its door, once
            out.append(recording)
            continue
        steady = 0
        for part in parts:
            if steady >= FIT_PERIODS:
                break
            out.append(part)
            try:
                exc = excitation_of(part)
            except DataError:
                break
            steady += len(exc.steady) if exc.kind == "periodic" else FIT_PERIODS
    return out


def fit_span(recording) -> int:
    """Samples of a recording the output-error fit uses: a periodic force's first steady periods (the next ones
    repeat them, to the noise), with the leading transient, else the whole record."""
    from ..signal.excitation import excitation_of, received

    n = len(recording["force"])
    try:
        exc = excitation_of(received(recording))
    except DataError:
        return n
    if exc.kind != "periodic":
        return n
    return min(n, exc.period_samples * (FIT_PERIODS + int(exc.transient_periods or 0)))


def oversampling(linear, fs_hz: float) -> int:
    """The joint's step: 16 or more a period of the structure's highest mode (a stick-slip or a contact moves
    the force faster than the modes), at most 8 steps a sample."""
    top = float(np.abs(linear.poles).max()) / (2 * np.pi) if linear.poles.size else 0.0
    return int(np.clip(np.ceil(16 * top / fs_hz), 1, 8))


def drives_of(model, recordings, measured, span) -> list:
    """(Drive, measured responses) of each recording's first ``span`` samples through ``model``."""
    return [(Drive(model, drive_force(r)[:n], float(r.fs_hz), warmup_of(r)), m)
            for r, m, n in zip(recordings, measured, span)]


def redrive(drive, model):
    """``drive`` for another model (its own linear part), the same force."""
    return drive if drive.model.linear is model.linear else Drive(model, drive.force, drive.fs, drive.skip)


def cost(model, drives) -> float:
    """Mean squared misfit of ``model`` on drives of the same forces (each through the model's own linear part)."""
    with np.errstate(over="ignore", invalid="ignore"):  # a candidate that runs away costs inf, said by no warning
        total = float(sum(np.sum(((redrive(d, model).outputs(model.joint) - m) / m.std(axis=1, keepdims=True)) ** 2)
                          / m.size for d, m in drives))
    return total if np.isfinite(total) else np.inf


def with_joint(model, c, kappa) -> StructureModel:
    return replace(model, joint=replace(model.joint, coefficients=np.asarray(c, float), coupling=np.asarray(kappa)))


def stable(model, drives) -> StructureModel:
    """The start scaled down (toward the linear model) until every recording's simulation stays finite."""
    j = model.joint
    for s in SHRINK:
        trial = with_joint(model, j.coefficients * s, j.coupling)
        if all(np.all(np.isfinite(d.outputs(trial.joint))) for d, _ in drives):
            return trial
    return model  # pragma: no cover - the scale 0 is the linear model


def with_table(model, recordings, files, drives=None) -> StructureModel:
    """``model`` with its fit table: NRMSE per recording and channel, the lowest level's linear model against the
    model with its joint, simulated on the whole records (or on ``drives`` [(Drive, measured)] where given)."""
    lin, nl = [], []
    for i, r in enumerate(recordings):
        if drives is None:
            drive = Drive(model, drive_force(r), float(r.fs_hz), warmup_of(r))
            measured = np.array([np.asarray(r[c], float) for c in model.channels])
        else:
            drive, measured = drives[i]
        a = drive.outputs(None)
        b = drive.outputs(model.joint) if model.joint is not None else a
        lin.append([round(nrmse(x, m), 4) for x, m in zip(a, measured)])
        nl.append([round(nrmse(x, m), 4) for x, m in zip(b, measured)])
    return replace(model, fit={"metric": "nrmse", "channels": list(model.channels), "files": files,
                               "linear": lin, "nonlinear": nl})

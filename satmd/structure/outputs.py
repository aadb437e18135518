"""Every channel re-solved from every recording at once, the joint's stroke kept apart.

The linear part's residues come from the lowest level alone (or, for the structure under the joint, from the
levels' spectra), and the joint's column at each channel is the force's scaled per mode by one path κ shared by
every channel; the output-error fit then moves the joint alone. Given the joint's force and the modes' states,
a channel's simulated response is linear in its own residues, its joint's column and its feed-through,
``y_o = Re Σ_r 2 (A_or x_r + B_or w_r) + D_o u``, the states x (driven by the force) and w (by the joint) fixed
by the rest of the model. So each channel is one linear least squares over every recording (each in units of its
RMS, as the fit weighs them), exact given the joint, the poles kept. The joint's own two sensors are re-solved
too: the stroke the joint feels was fitted as their difference (`linear.fit_linear`) and is kept as it was
(`Joint.stroke`), so their residues say what each sensor measures without moving the joint's force. On an
independent frame with a cubic joint at the driving point, a channel that the shared path left at 3× the noise
at every level came to 1.3×; on independent ground vibration tests, a wing's sensor at one end of a friction
joint went from 0.063 to 0.042 at its worst held-out level (its noise 0.012), a chain's from 0.22 to 0.14.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import TINY


def resolved_outputs(model, drives):
    """``model`` with the residues, joint's column and feed-through of every channel re-solved by least squares
    on ``drives`` [(Drive, measured (C, N))], the joint's stroke kept as it was (`Joint.stroke`); ``model`` itself
    where it has no joint or the joint ran away on a recording."""
    joint, lin = model.joint, model.linear
    if joint is None:
        return model
    n, channels = lin.poles.size, range(len(lin.channels))
    rows = {i: ([], []) for i in channels}
    for drive, measured in drives:
        x, u = drive.states[:, drive.skip:], drive.u[drive.skip:]
        g, w = drive.driven(joint)
        if not np.all(np.isfinite(g)):
            return model
        basis = np.vstack([2 * x.real, -2 * x.imag, 2 * w.real, -2 * w.imag, u[None, :]]).T
        for i in channels:
            scale = max(float(measured[i].std()), TINY)
            rows[i][0].append(basis / scale)
            rows[i][1].append(measured[i] / scale)
    residues, feedthrough = lin.residues.copy(), lin.feedthrough.copy()
    column = joint.column_of(lin).copy()
    for i in channels:
        prior = np.concatenate([residues[i].real, residues[i].imag, column[i].real, column[i].imag, [feedthrough[i]]])
        theta = prior + _ridge(np.vstack(rows[i][0]), np.concatenate(rows[i][1]), prior)
        residues[i] = theta[:n] + 1j * theta[n:2 * n]
        column[i] = theta[2 * n:3 * n] + 1j * theta[3 * n:4 * n]
        feedthrough[i] = theta[4 * n]
    return replace(model, linear=replace(lin, residues=residues, feedthrough=feedthrough),
                   joint=replace(joint, column=column, stroke=joint.stroke_of(lin)))


RIDGE = 1e-6  # of the regressors' own scale: a direction the recordings barely see stays where the model had it


def _ridge(basis, y, prior) -> np.ndarray:
    """The step from ``prior`` that least squares on ``basis`` asks for, each regressor in units of its norm and
    held to the prior in directions the data do not fix (``RIDGE``): a mode's state driven by the force and the
    one driven by the joint can be nearly the same signal, and unheld they take huge opposite residues that
    cancel on the records fitted and on no other."""
    norms = np.linalg.norm(basis, axis=0)
    norms = np.where(norms > 0, norms, 1.0)
    scaled = basis / norms
    k = scaled.shape[1]
    a = np.vstack([scaled, np.sqrt(RIDGE) * np.eye(k)])
    b = np.concatenate([y - basis @ prior, np.zeros(k)])
    return np.linalg.lstsq(a, b, rcond=None)[0] / norms

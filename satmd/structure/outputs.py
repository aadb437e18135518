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
    if model.joint is None:
        return model
    solved = Projection(model, drives).solve(model.joint)
    return model if solved is None else solved[1]


RIDGE = 1e-6  # of the regressors' own scale: a direction the recordings barely see stays where the model had it


class Projection:
    """Every channel's residues, joint's column and feed-through solved for a trial joint: the linear part of an
    output-error fit, solved inside it (variable projection, Golub & Pereyra 1973) so that the least squares
    moves the joint's law and path for what they alone decide, the joint's force and its feedback through the
    stroke, and not for what each channel's own coefficients would do anyway.

    Each regressor in units of its norm is held to the model's value in directions the data do not fix
    (`RIDGE`): a mode's state driven by the force and the one driven by the joint can be nearly the same signal,
    and unheld they take huge opposite residues that cancel on the records fitted and on no other. Each channel
    of each recording is weighed by its RMS, as the output-error fit weighs them; ``step`` keeps every step-th
    sample (`Drive.outputs`)."""

    def __init__(self, model, drives, step: int = 1):
        self.model, self.step, self.parts = model, int(step), []
        for drive, measured in drives:
            keep = slice(drive.skip, None, self.step)
            x = drive.states[:, keep]
            weight = 1.0 / np.maximum(measured.std(axis=1), TINY)
            self.parts.append((drive, np.vstack([2 * x.real, -2 * x.imag]), drive.u[keep], measured[:, ::self.step],
                               weight))
        self.size = sum(y.size for *_, y, _ in self.parts)
        self.runs = [y.shape[1] for *_, y, _ in self.parts for _ in y]  # the residuals' runs in time (`solve`)

    def solve(self, joint):
        """(residuals (every recording's weighted misfit, flat), the model with ``joint`` and every channel
        solved); None where the joint ran away on a recording."""
        lin = self.model.linear
        n, n_out = lin.poles.size, len(lin.channels)
        gram, moment, bases = 0.0, 0.0, []
        for drive, fixed, u, y, weight in self.parts:
            g, w = drive.driven(joint, self.step)
            if not np.all(np.isfinite(g)):
                return None
            basis = np.vstack([fixed, 2 * w.real, -2 * w.imag, u[None, :]])
            bases.append(basis)
            with np.errstate(over="ignore", invalid="ignore"):  # a state beyond floating point: told below
                gram = gram + (weight ** 2)[:, None, None] * (basis @ basis.T)[None]
                moment = moment + (weight ** 2)[:, None] * (y @ basis.T)
        if not (np.all(np.isfinite(gram)) and np.all(np.isfinite(moment))):
            return None  # a state beyond floating point: ran away as surely as the joint's force
        column = joint.column_of(lin)
        prior = np.hstack([lin.residues.real, lin.residues.imag, column.real, column.imag, lin.feedthrough[:, None]])
        try:
            theta = prior + np.array([_ridge_step(gram[i], moment[i] - gram[i] @ prior[i]) for i in range(n_out)])
        except np.linalg.LinAlgError:
            return None
        residuals = np.concatenate([((theta @ basis - y) * weight[:, None]).ravel()
                                    for basis, (*_, y, weight) in zip(bases, self.parts)]) / np.sqrt(self.size)
        solved = replace(lin, residues=theta[:, :n] + 1j * theta[:, n:2 * n], feedthrough=theta[:, 4 * n])
        joint = replace(joint, column=theta[:, 2 * n:3 * n] + 1j * theta[:, 3 * n:4 * n], stroke=joint.stroke_of(lin))
        return residuals, replace(self.model, linear=solved, joint=joint)


def _ridge_step(gram, moment) -> np.ndarray:
    """The step from the prior that least squares asks for (normal equations ``gram``, the misfit's ``moment``),
    each regressor in units of its norm and held to the prior with weight `RIDGE`."""
    norms = np.sqrt(np.maximum(np.diag(gram), 0.0))
    norms = np.where(norms > 0, norms, 1.0)
    scaled = gram / np.outer(norms, norms) + RIDGE * np.eye(gram.shape[0])
    return np.linalg.solve(scaled, moment / norms) / norms

"""Physical sensitivity of the FRFs to R and L, and its agreement with neural attribution.

The paper's discussion asks for this comparison: neural attribution
(∂R̂/∂X, `satmd.explain.attribution`) against the derivatives of the forward
model ∂A/∂R, ∂A/∂L. The derivatives come from the analytic Jacobian of
`satmd.physics.frf` (``wrt=["R", "L"]``) and are reduced exactly like the
attribution: per frequency, ``Σ |∂X_c(f)/∂θ|`` over Re/Im of A1 and A2, each
curve divided by its maximum.

Agreement per case is the cosine similarity of the two normalised curves
(non-negative curves, so in [0, 1]) and Spearman's rank correlation over
frequency.

A stricter local check needs no normalisation: a consistent inverse satisfies
``R̂(A(R, L)) = R``, so by the chain rule the neural gradient G (2 x 4F) times
the physical Jacobian J (4F x 2) must be the identity in physical units
(`chain_rule_check`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import spearmanr

from ..conventions import ACCEL_CHANNELS
from ..physics import PAPER_GRID_HZ, Rig, frf
from .attributions import OUTPUTS, normalise_max, per_frequency


@dataclass(frozen=True)
class PhysicalSensitivity:
    """|∂A/∂θ| per frequency for a (batch of) rig(s).

    Attributes
    ----------
    freq_hz : (F,)
    curves : (*batch, P, F) normalised, each curve max 1
    jacobian : (*batch, 4F, P) ∂X/∂θ of the raw features [Re A1, Re A2, Im A1, Im A2]
    params : names of θ
    """

    freq_hz: np.ndarray
    curves: np.ndarray
    jacobian: np.ndarray
    params: tuple


def physical_sensitivity(rig: Rig | None = None, freq=PAPER_GRID_HZ, params=OUTPUTS, effects=(),
                         feature_scale=None) -> PhysicalSensitivity:
    """Per-frequency |∂A/∂θ| from the analytic Jacobian, normalised as the attribution.

    Parameters
    ----------
    rig : Rig
        Fields may be arrays (e.g. the six blind R, L): one batched call.
    freq : frequencies [Hz] (default: the paper grid).
    params : parameters θ to differentiate by (default R, L).
    effects : effects included in the model.
    feature_scale : (4F,), e.g. a model's ``scaler_.scale``
        Express the derivatives in standardised feature units, ∂(X_c / s_c)/∂θ,
        before the per-frequency reduction -- the dual of the attribution with
        ``space="scaled"`` (G s and J / s multiply to the same G J).

    Returns
    -------
    PhysicalSensitivity
        ``jacobian`` always holds the raw derivatives.
    """
    rig = Rig() if rig is None else rig
    freq = np.asarray(freq, float)
    r = frf(freq, rig, effects, wrt=list(params), outputs=ACCEL_CHANNELS)
    ja1, ja2 = r.jac["a1"], r.jac["a2"]  # (*batch, F, P)
    z = np.concatenate([ja1, ja2], axis=-2)  # (*batch, 2F, P): [A1 over f, A2 over f]
    jac = np.concatenate([z.real, z.imag], axis=-2)  # raw-feature ordering
    weighted = jac if feature_scale is None else jac / np.asarray(feature_scale, float)[:, None]
    per_f = per_frequency(np.swapaxes(weighted, -1, -2), freq.size)  # (*batch, P, F)
    return PhysicalSensitivity(freq, normalise_max(per_f), jac, tuple(params))


def cosine(a: np.ndarray, b: np.ndarray) -> float:
    a, b = np.ravel(a).astype(float), np.ravel(b).astype(float)
    den = np.linalg.norm(a) * np.linalg.norm(b)
    return float(a @ b / den) if den > 0 else float("nan")


def spearman(a: np.ndarray, b: np.ndarray) -> float:
    return float(spearmanr(np.ravel(a), np.ravel(b)).statistic)


def agreement(neural: np.ndarray, physical: np.ndarray, labels=None) -> list:
    """Per case and output, cosine similarity and Spearman correlation of two sets of normalised curves.

    Parameters
    ----------
    neural : (n, 2, F) attribution curves (S_R, S_L per case).
    physical : (n, 2, F) physical sensitivities, same layout.
    labels : case names (default: case indices).

    Returns
    -------
    list of dict
        One per case: its label and, per output, ``cosine`` and ``spearman``.
    """
    neural = np.asarray(neural, float)
    physical = np.asarray(physical, float).reshape(neural.shape)
    rows = []
    for i in range(neural.shape[0]):
        row = {"case": labels[i] if labels is not None else f"case {i + 1}"}
        for k, name in enumerate(OUTPUTS):
            row[f"cosine_{name}"] = cosine(neural[i, k], physical[i, k])
            row[f"spearman_{name}"] = spearman(neural[i, k], physical[i, k])
        rows.append(row)
    return rows


def chain_rule_check(gradients: np.ndarray, jacobian: np.ndarray, span) -> np.ndarray:
    """∂(R̂, L̂)/∂(R, L) through the data: G J diag(span); a locally consistent inverse gives the identity.

    Parameters
    ----------
    gradients : (n, 2, 4F) gradients G of the normalised outputs w.r.t. the raw features.
    jacobian : (n, 4F, 2) Jacobian J of the raw features w.r.t. (R, L).
    span : output ranges (R_max - R_min, L_max - L_min).

    Returns
    -------
    ndarray
        (n, 2, 2) matrices.
    """
    g = np.asarray(gradients, float) * np.asarray(span, float)[None, :, None]
    return np.einsum("nkd,ndp->nkp", g, np.asarray(jacobian, float))

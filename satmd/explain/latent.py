"""Latent organisation (paper Figure 4, SPEC §6) and the disentanglement test.

``latent_map`` takes the 64-d penultimate activations of the inverse net
(``model.latent``) for a set of labelled FRFs and returns

- their projection on the first two principal components (for the plots
  coloured by R and by L);
- a linear probe: cross-validated R² of ridge regressions R ~ z and L ~ z
  (how linearly R and L can be read from the latent);
- sweeps around anchor points: R varied at fixed L, and L varied at fixed R
  (FRFs from `satmd.physics.frf` with the model's rig). The latent direction
  of each sweep is the least-squares slope dz/dθ (θ normalised by the output
  bounds); the angle between the R and L directions is the disentanglement
  test the paper says is missing: 90° means R and L move the latent along
  orthogonal directions, 0° means one shared "tuning coordinate".
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..errors import DataError
from ..inverse.dataset import complex_to_features
from ..physics import frf
from . import contract

#: Half-widths of the sweeps around each anchor.
SWEEP_HALF_WIDTH = {"R": 5.0, "L": 0.02}


@dataclass(frozen=True)
class LatentMap:
    """Result of `latent_map` (see the module docstring).

    latent (n, 64); pcs (n, 2); explained (2,) variance ratios; R, L (n,);
    probe_r2 {"R": ..., "L": ...}; sweeps: list of dicts with the anchor
    (R, L), ``angle_deg``, the sweep values and their PCA coordinates.
    """

    latent: np.ndarray
    pcs: np.ndarray
    explained: np.ndarray
    R: np.ndarray
    L: np.ndarray
    probe_r2: dict
    sweeps: list

    def to_dict(self) -> dict:
        return {"explained_variance_ratio": self.explained.tolist(), "probe_r2": dict(self.probe_r2),
                "sweeps": [{"anchor": s["anchor"], "angle_deg": s["angle_deg"], "speed": s["speed"]}
                           for s in self.sweeps]}


def _labels(data, labels):
    if labels is not None:
        R, L = labels
    elif isinstance(data, dict) and "R" in data:
        R, L = data["R"], data["L"]
    elif hasattr(data, "R") and hasattr(data, "L") and np.ndim(getattr(data, "R")) >= 1:
        R, L = data.R, data.L
    else:
        raise DataError("latent_map needs R and L labels: pass a dataset with R, L or labels=(R, L)")
    return np.asarray(R, float).ravel(), np.asarray(L, float).ravel()


def linear_probe(Z: np.ndarray, target: np.ndarray, groups=None, folds: int = 5, seed: int = 0) -> float:
    """Cross-validated R² of a ridge regression target ~ Z (grouped folds when groups are given)."""
    from sklearn.linear_model import RidgeCV
    from sklearn.metrics import r2_score
    from sklearn.model_selection import GroupKFold, KFold, cross_val_predict
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    est = make_pipeline(StandardScaler(), RidgeCV(alphas=np.logspace(-4, 3, 15)))
    if groups is not None and len(np.unique(groups)) >= folds:
        cv = GroupKFold(n_splits=folds)
        pred = cross_val_predict(est, Z, target, cv=cv, groups=groups)
    else:
        pred = cross_val_predict(est, Z, target, cv=KFold(folds, shuffle=True, random_state=seed))
    return float(r2_score(target, pred))


def _direction(Z: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Least-squares slope dz/dt of the latent along a sweep (64,)."""
    tc = t - t.mean()
    return (tc[:, None] * (Z - Z.mean(axis=0))).sum(axis=0) / (tc @ tc)


def angle_deg(u: np.ndarray, v: np.ndarray) -> float:
    """Angle between two directions (lines, not arrows) in degrees, in [0, 90]."""
    den = np.linalg.norm(u) * np.linalg.norm(v)
    if den == 0:
        return float("nan")
    return float(np.degrees(np.arccos(np.clip(abs(u @ v) / den, 0.0, 1.0))))


def sweep(model, anchor, n: int = 11, half_width=None) -> dict:
    """Latent directions of R- and L-sweeps through ``anchor`` = (R, L)."""
    half = {**SWEEP_HALF_WIDTH, **(half_width or {})}
    R0, L0 = map(float, anchor)
    lo_R = max(R0 - half["R"], 0.5)
    lo_L = max(L0 - half["L"], 0.005)
    Rs = np.linspace(lo_R, R0 + half["R"], n)
    Ls = np.linspace(lo_L, L0 + half["L"], n)
    R = np.concatenate([Rs, np.full(n, R0)])
    L = np.concatenate([np.full(n, L0), Ls])
    rig = contract.model_rig(model).replace(R=R, L=L)
    r = frf(model.freq_hz, rig, outputs=ACCEL_CHANNELS)
    Z = contract.latent(model, complex_to_features(np.stack([r.channel(c) for c in ACCEL_CHANNELS], axis=1)))
    span = contract.bounds_span(model)
    dR = _direction(Z[:n], Rs / span[0])
    dL = _direction(Z[n:], Ls / span[1])
    return {"anchor": [R0, L0], "angle_deg": angle_deg(dR, dL), "R": Rs, "L": Ls, "latent_R": Z[:n],
            "latent_L": Z[n:], "speed": {"R": float(np.linalg.norm(dR)), "L": float(np.linalg.norm(dL))}}


def latent_map(model, data, labels=None, anchors=None, n_sweep: int = 11, folds: int = 5, seed: int = 0) -> LatentMap:
    """PCA of the latent, linear probe and R/L sweeps (module docstring).

    Parameters
    ----------
    model : a trained net-kind `InverseModel` (or an object following its contract)
    data : labelled FRFs: an `InverseDataset`, or FRFs with ``labels=(R, L)``
    labels : (R, L) arrays when ``data`` carries no labels
    anchors : (R, L) points for the sweeps (default: the six blind pairs of SPEC §5)
    n_sweep : points of each R or L sweep
    folds : folds of the cross-validated linear probe
    seed : seed of the folds

    Returns
    -------
    LatentMap
    """
    from sklearn.decomposition import PCA

    from .attributions import BLIND_CASES

    contract.check_net_model(model)
    R, L = _labels(data, labels)
    raw = contract.raw_features(model, data)
    if raw.shape[0] != R.size:
        raise DataError(f"{raw.shape[0]} FRFs but {R.size} labels")
    Z = contract.latent(model, raw)
    pca = PCA(n_components=2, random_state=seed).fit(Z)
    groups = getattr(data, "group", None)
    probe = {"R": linear_probe(Z, R, groups, folds, seed), "L": linear_probe(Z, L, groups, folds, seed)}
    anchors = BLIND_CASES if anchors is None else anchors
    sweeps = []
    for a in anchors:
        s = sweep(model, a, n_sweep)
        s["pcs_R"], s["pcs_L"] = pca.transform(s["latent_R"]), pca.transform(s["latent_L"])
        sweeps.append(s)
    return LatentMap(Z, pca.transform(Z), pca.explained_variance_ratio_, R, L, probe, sweeps)

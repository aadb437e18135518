"""Step 1 of `satmd.modal.fit_modes`: modes from the stabilisation diagram of a common-denominator fit.

A least-squares complex-frequency fit of a rational fraction with one denominator common to all
output channels (the rational-fraction polynomial method of Richardson & Formenti 1982, IMAC I; in
the z-domain form of the pLSCF estimator, Guillaume, Verboven, Vanlanduit, Van der Auweraer &
Peeters 2003, IMAC XXI), solved by its reduced normal equations at every model order up to
``max_order``. A pole that stays put from one order to the next (``STABLE_F`` in frequency,
``STABLE_ZETA`` in damping) is stable; a mode is a frequency where stable poles gather over many
orders.
"""
from __future__ import annotations

import numpy as np

STABLE_F = 0.01  # relative frequency change between consecutive orders of a stable pole
STABLE_ZETA = 0.10  # relative damping change between consecutive orders of a stable pole
CLUSTER_GAP = 0.005  # stable poles closer than this (relative) are one mode
MIN_SUPPORT = 4  # a mode is stable at this many orders at least ...
SUPPORT_SHARE = 0.3  # ... and at this share of the orders from its first appearance on
MAX_ZETA = 0.3  # poles more damped than this are left to the residual terms


def stable_poles(w, H, S, max_order: int) -> list:
    """Modes that the stabilisation diagram of an LSCF fit shows, most persistent first.

    Parameters
    ----------
    w : (M,) rad/s
    H : (C, M) complex FRFs of the channels
    S : (C, M) their std (the weights 1/S)
    max_order : highest denominator order

    Returns
    -------
    list of (f_hz, zeta, support)
        The median of each cluster of stable poles and the number of orders it is stable at.
    """
    Ts = np.pi / (1.1 * w[-1])  # the band's top just below Nyquist of the z-domain basis
    blocks = _normal_blocks(w, H, S, max_order, Ts)
    lo, hi = w[0] / (2 * np.pi), w[-1] / (2 * np.pi)
    previous, stable = None, []
    for n in range(2, max_order + 1):
        f, z = _poles_at(blocks, n, Ts)
        keep = (f >= lo) & (f <= hi) & (z > 0) & (z < MAX_ZETA)
        f, z = f[keep], z[keep]
        if previous is not None:
            for fi, zi in zip(f, z):
                close = (np.abs(previous[0] - fi) <= STABLE_F * fi) & (np.abs(previous[1] - zi) <= STABLE_ZETA * zi)
                if close.any():
                    stable.append((n, fi, zi))
        previous = (f, z)
    return _clusters(stable, max_order)


def _normal_blocks(w, H, S, n, Ts):
    """Per channel the real normal-equation blocks R, S, T of N(z)/D(z) ≈ H at the highest order n."""
    z = np.exp(1j * np.outer(w * Ts, np.arange(n + 1)))
    out = []
    for h, s in zip(H, S):
        X = z / s[:, None]
        Y = -X * h[:, None]
        out.append(((X.conj().T @ X).real, (X.conj().T @ Y).real, (Y.conj().T @ Y).real))
    return out


def _poles_at(blocks, n, Ts):
    """(f_hz, zeta) of the upper-half-plane poles of the order-n denominator (monic: α_n = 1)."""
    k = n + 1
    M = np.zeros((k, k))
    for R, Sx, T in blocks:
        Sk = Sx[:k, :k]
        M += T[:k, :k] - Sk.T @ np.linalg.lstsq(R[:k, :k], Sk, rcond=None)[0]
    with np.errstate(all="ignore"):  # an ill-posed order gives wild roots: they are filtered out below
        alpha = np.linalg.lstsq(M[:n, :n], -M[:n, n], rcond=None)[0]
        roots = np.roots(np.append(alpha, 1.0)[::-1])
        s = np.log(roots.astype(complex)) / Ts
    s = s[np.isfinite(s) & (s.imag > 0)]
    wn = np.abs(s)
    return wn / (2 * np.pi), -s.real / np.maximum(wn, np.finfo(float).tiny)


def _clusters(stable, max_order):
    """Group stable poles by frequency; keep groups that persist over orders."""
    stable = sorted(stable, key=lambda p: p[1])
    groups, out = [], []
    for p in stable:
        if groups and p[1] - groups[-1][-1][1] <= CLUSTER_GAP * p[1]:
            groups[-1].append(p)
        else:
            groups.append([p])
    for g in groups:
        orders = {p[0] for p in g}
        support = len(orders)
        if support >= max(MIN_SUPPORT, SUPPORT_SHARE * (max_order - min(orders) + 1)):
            out.append((float(np.median([p[1] for p in g])), float(np.median([p[2] for p in g])), support))
    return sorted(out, key=lambda c: -c[2])

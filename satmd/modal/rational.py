"""`vector_fit`: a stable pole-residue model of measured FRFs, accurate to what the data hold.

`fit_modes` keeps the modes the data support (BIC) and stands for everything else with residual terms
that have no time-domain state. A simulation needs the other thing: a causal, stable rational model that
reproduces the measured FRF closely over the band, physical modes or not. Vector fitting (Gustavsen &
Semlyen 1999) gives it: starting from poles spread over the band, each iteration fits ``σ(s) H(s)`` and
``σ(s)`` with the same poles (linear least squares, every channel sharing σ) and moves the poles to the
zeros of σ; unstable poles are reflected into the left half-plane. The residues and a flat feed-through
are then solved with the poles fixed.
"""
from __future__ import annotations

import numpy as np

from ..errors import DataError

MIN_ZETA = 1e-3  # the least damping ratio of a fitted pole


def _columns(s, poles) -> np.ndarray:
    """(M, 2K) complex columns whose real coefficients (p, q) give (p + iq)/(s − λ) + (p − iq)/(s − λ*)."""
    a = 1.0 / (s[:, None] - poles[None, :])
    b = 1.0 / (s[:, None] - poles.conj()[None, :])
    return np.stack([a + b, 1j * (a - b)], axis=2).reshape(s.size, -1)


def _stack(X, y):
    """(rows, right-hand side) of a complex least-squares problem as a real one."""
    return np.vstack([X.real, X.imag]), np.concatenate([y.real, y.imag])


def _relocate(poles, sigma) -> np.ndarray:
    """The zeros of σ(s) = 1 + Σ (p̃ + i q̃)/(s − λ) + conj: the next poles (stable, upper half-plane)."""
    k = poles.size
    A = np.zeros((2 * k, 2 * k))
    b = np.zeros(2 * k)
    for j, lam in enumerate(poles):
        A[2 * j:2 * j + 2, 2 * j:2 * j + 2] = [[lam.real, lam.imag], [-lam.imag, lam.real]]
        b[2 * j] = 2.0
    z = np.linalg.eigvals(A - np.outer(b, sigma))
    tol = 1e-9 * max(1.0, float(np.abs(z).max()))
    upper = list(z[z.imag > tol])
    reals = np.sort(z[np.abs(z.imag) <= tol].real)
    for r1, r2 in zip(reals[0::2], reals[1::2]):  # two real zeros become one lightly separated pair
        upper.append(0.5 * (r1 + r2) + 0.5j * max(abs(r2 - r1), tol))
    z = np.array(upper, complex)
    # reflected into the stable half-plane, and damped at least MIN_ZETA: a pole that sharp fits noise, and in a
    # simulation with a joint it stores whatever the joint gives it
    z = -np.maximum(np.abs(z.real), MIN_ZETA * np.abs(z)) + 1j * z.imag
    return np.sort_complex(z)


def vector_fit(freq_hz, frf, weight=None, n_pairs: int = 10, iterations: int = 12):
    """Poles, residues and feed-through of ``frf`` on shared stable poles.

    Parameters
    ----------
    freq_hz : (M,) Hz
    frf : (C, M) complex: one FRF per channel
    weight : (M,) or (C, M) weights of each line's error (default 1 over each channel's mean magnitude)
    n_pairs : complex-conjugate pole pairs
    iterations : pole relocations

    Returns
    -------
    (poles (K,) complex, residues (C, K) complex, feedthrough (C,) float): the model
    ``H_o(iω) = Σ_r R_or/(iω − λ_r) + R_or*/(iω − λ_r*) + D_o``.
    """
    f = np.asarray(freq_hz, float)
    H = np.atleast_2d(np.asarray(frf, complex))
    if H.shape[1] != f.size or f.size < 2 * n_pairs + 2:
        raise DataError(f"vector_fit: {f.size} lines for {n_pairs} pole pairs on FRFs of shape {H.shape}")
    W = np.broadcast_to(1.0 / np.abs(H).mean(axis=1, keepdims=True) if weight is None else weight, H.shape)
    s = 2j * np.pi * f
    beta = 2 * np.pi * np.linspace(f[0], f[-1], n_pairs)
    poles = -beta / 100.0 + 1j * beta
    for _ in range(iterations):
        P = _columns(s, poles)
        n_own = P.shape[1] + 1
        rows, rhs = [], []
        for h, w in zip(H, W):  # each channel's own residues projected out: R of [M, y] holds what σ sees
            M, y = _stack(np.hstack([P, np.ones((s.size, 1)), -h[:, None] * P]) * w[:, None], h * w)
            R = np.asarray(np.linalg.qr(np.column_stack([M, y]), mode="r"))
            rows.append(R[n_own:-1, n_own:-1])
            rhs.append(R[n_own:-1, -1])
        sigma = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
        poles = _relocate(poles, sigma)
    return (poles, *residues_at(f, H, W, poles))


def residues_at(freq_hz, frf, weight, poles):
    """(residues (C, K) complex, feedthrough (C,) float) of ``frf`` (C, M) on fixed ``poles``: weighted linear
    least squares per channel (`vector_fit`'s last step)."""
    f = np.asarray(freq_hz, float)
    H = np.atleast_2d(np.asarray(frf, complex))
    W = np.broadcast_to(weight, H.shape)
    s = 2j * np.pi * f
    P = np.hstack([_columns(s, np.asarray(poles, complex)), np.ones((s.size, 1))])
    residues, feed = [], []
    for h, w in zip(H, W):
        A, b = _stack(P * w[:, None], h * w)
        c = np.linalg.lstsq(A, b, rcond=None)[0]
        residues.append(c[0:-1:2] + 1j * c[1:-1:2])
        feed.append(float(c[-1]))
    return np.array(residues), np.array(feed)


def vector_fit_inputs(blocks, n_pairs: int, iterations: int = 12, poles=None):
    """Shared stable poles of a system with several inputs, from input and output spectra (vector fitting).

    Each output o is ``Y_o = Σ_i H_oi U_i`` with ``H_oi(s) = Σ_r R_oir/(s − λ_r) + conj + D_oi``: with σ as in
    `vector_fit`, ``σ Y_o = Σ_i (Σ_r ... + D_oi) U_i`` is linear in the residues and σ's, over every block of
    lines (a test at one level is one block).

    Parameters
    ----------
    blocks : [(freq_hz (M,), inputs (I, M) complex, outputs (C, M) complex, weights (C, M)), ...]
    n_pairs : pole pairs
    iterations : pole relocations
    poles : (n_pairs,) starting poles (default spread over the blocks' band)

    Returns
    -------
    (poles (K,), residues (C, I, K) complex, feedthrough (C, I) float)
    """
    lo = min(float(b[0][0]) for b in blocks)
    hi = max(float(b[0][-1]) for b in blocks)
    if poles is None:
        beta = 2 * np.pi * np.linspace(lo, hi, n_pairs)
        poles = -beta / 100.0 + 1j * beta
    poles = np.asarray(poles, complex)
    n_out = blocks[0][2].shape[0]
    n_in = blocks[0][1].shape[0]

    def design(p):
        return [np.hstack([np.hstack([_columns(2j * np.pi * f, p), np.ones((f.size, 1))]) * u[:, None] for u in U])
                for f, U, _, _ in blocks]

    for _ in range(iterations):
        own = design(poles)
        rows, rhs = [], []
        for o in range(n_out):
            parts = []
            for (f, U, Y, W), X in zip(blocks, own):
                P = _columns(2j * np.pi * f, poles)
                parts.append(np.column_stack([np.hstack([X, -Y[o][:, None] * P]) * W[o][:, None], Y[o] * W[o]]))
            M = np.vstack(parts)
            R = np.asarray(np.linalg.qr(np.vstack([M.real, M.imag]), mode="r"))
            n_own = own[0].shape[1]
            rows.append(R[n_own:-1, n_own:-1])
            rhs.append(R[n_own:-1, -1])
        sigma = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
        poles = _relocate(poles, sigma)
    own = design(poles)
    k = poles.size
    residues = np.zeros((n_out, n_in, k), complex)
    feed = np.zeros((n_out, n_in))
    for o in range(n_out):
        X = np.vstack([x * W[o][:, None] for x, (_, _, _, W) in zip(own, blocks)])
        y = np.concatenate([Y[o] * W[o] for _, _, Y, W in blocks])
        A, b = _stack(X, y)
        c = np.linalg.lstsq(A, b, rcond=None)[0].reshape(n_in, 2 * k + 1)
        residues[o] = c[:, 0:2 * k:2] + 1j * c[:, 1:2 * k:2]
        feed[o] = c[:, -1]
    return poles, residues, feed

"""Where the output-error fit of a structure's joint starts (`fit.fit_structure`): the joint's law and path from
the levels' spectra, in the frequency domain.

Two starts. ``measured_start``: the lowest level's linear model as the structure, the joint's coefficients c
and its path κ (one complex number per mode, reciprocity's form) alternated in least squares on every level's
change. ``underlying_start``: the structure under the joint and the joint together, the force and the joint's
force as two inputs of one vector fit over every level (FNSI's feedback form, Noël & Kerschen 2013).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import TINY
from .laws import SHAPE_GRID
from .laws import law as law_named
from .linear import LinearStructure
from .model import Joint, StructureModel
from .simulations import cost, drives_of, oversampling, stable

ALTERNATIONS = 30  # of the frequency-domain start (κ at fixed c, c at fixed κ)


def underlying_start(linear, spectra, between, lw, d0, v0, aux, extra_pairs: int = 2):
    """(LinearStructure, c, κ): the structure under the joint and the joint, from every level at once.

    Every channel's response at every level is the structure's FRF times the force plus the joint's column
    times the spectrum of its force, ``A = H_u F + T G`` (FNSI's feedback form). At fixed law coefficients c
    this is a two-input system whose shared poles and residues a vector fit finds (`vector_fit_inputs`); at
    fixed H_u and T, c is linear; alternated. The poles are the structure's under the joint (not the
    lowest level's, where the joint already damps and stiffens it). The pair's first sensor is fitted as the
    pair's difference (see `linear.fit_linear`). κ is T's residues over H_u's, mode by mode, in least squares
    over the channels."""
    from ..modal.rational import vector_fit_inputs

    names = linear.channels
    ia = names.index(between[0])
    ib = names.index(between[1]) if between[1] != "ground" else None
    data = []
    for s in spectra:
        A = np.array([s.responses[c] for c in names])
        if ib is not None:
            A[ia] = A[ia] - A[ib]
        G = np.array([s.at_lines(t) for t in lw.columns(*s.relative(*between), d0, v0, aux)])
        W = np.repeat(1.0 / np.maximum(np.abs(A).mean(axis=1, keepdims=True), TINY), A.shape[1], axis=1)
        data.append((s.freq_hz, s.force, G, A, W))
    c = np.zeros(len(lw.all_terms))
    c[0] = 1.0
    k = linear.poles.size + extra_pairs
    poles = None
    for _ in range(ALTERNATIONS // 3):
        blocks = [(f, np.array([F, c @ G]), A, W) for f, F, G, A, W in data]
        poles, res, feed = vector_fit_inputs(blocks, k, iterations=6 if poles is not None else 12, poles=poles)
        T = [model_frf(f, poles, res[:, 1], feed[:, 1]) for f, *_ in data]
        X = np.vstack([np.column_stack([(T[m][i] * g) * W[i] for g in G])
                       for m, (f, F, G, A, W) in enumerate(data) for i in range(len(names))])
        y = np.concatenate([(A[i] - model_frf(f, poles, res[i:i + 1, 0], feed[i:i + 1, 0])[0] * F) * W[i]
                            for f, F, G, A, W in data for i in range(len(names))])
        Xr, yr = real_rows(X, y)
        c_new = np.linalg.lstsq(Xr, yr, rcond=None)[0]
        c = c_new / (abs(c_new[0]) or 1.0)
    blocks = [(f, np.array([F, c @ G]), A, W) for f, F, G, A, W in data]
    poles, res, feed = vector_fit_inputs(blocks, k, iterations=6, poles=poles)
    R, D, T = res[:, 0].copy(), feed[:, 0].copy(), res[:, 1].copy()
    if ib is not None:  # back to the sensors' own channels
        R[ia] += R[ib]
        D[ia] += D[ib]
        T[ia] += T[ib]
    kappa = np.sum(R.conj() * T, axis=0) / np.maximum(np.sum(np.abs(R) ** 2, axis=0), TINY)
    return LinearStructure(names, poles, R, D), c, kappa


def model_frf(f, poles, residues, feed):
    """(C, M) accelerance of a pole-residue model (residues (C, K)) at ``f`` Hz."""
    return LinearStructure(tuple(range(len(residues))), poles, residues, np.asarray(feed, float)).frf(f)


def real_rows(X, y):
    """A complex least-squares problem as a real one: real parts stacked over imaginary parts."""
    return np.vstack([X.real, X.imag]), np.concatenate([y.real, y.imag])


def measured_start(linear, spectra, between, lw, d0, v0, aux):
    """(c, κ): the joint's coefficients and coupling from the level changes, in the frequency domain."""
    names = linear.channels
    lam = linear.poles
    blocks = []
    for s in spectra:
        f = s.freq_hz
        iw = 2j * np.pi * f[:, None]
        H = linear.frf(f)
        G = [s.at_lines(t) for t in lw.columns(*s.relative(*between), d0, v0, aux)]
        for i, c in enumerate(names):
            a = linear.residues[i][None, :] / (iw - lam[None, :])
            b = linear.residues[i].conj()[None, :] / (iw - lam.conj()[None, :])
            cols = np.stack([a + b, 1j * (a - b)], axis=2).reshape(f.size, -1)  # real (Re κ, Im κ) per mode
            w = 1.0 / max(float(np.mean(np.abs(s.responses[c]))), TINY)
            blocks.append((cols * w, G, (s.responses[c] - H[i] * s.force) * w))
    y = np.concatenate([e for _, _, e in blocks])
    y = np.concatenate([y.real, y.imag])
    c = np.zeros(len(lw.all_terms))
    c[0] = 1.0
    kappa = np.zeros(2 * lam.size)
    for _ in range(ALTERNATIONS):
        X = np.vstack([cols * sum(cj * g for cj, g in zip(c, G))[:, None] for cols, G, _ in blocks])
        kappa = np.linalg.lstsq(np.vstack([X.real, X.imag]), y, rcond=None)[0]
        X = np.vstack([np.stack([(cols @ kappa) * g for g in G], axis=1) for cols, G, _ in blocks])
        c = np.linalg.lstsq(np.vstack([X.real, X.imag]), y, rcond=None)[0]
        scale = abs(c[0]) or 1.0  # the pair (c, κ) is known up to a scale: the law's first term is 1 in size
        c, kappa = c / scale, kappa * scale
    return c, kappa[0::2] + 1j * kappa[1::2]


def simulated_shape(linear, spectra, between, lw, d0, v0, aux, recordings, measured, span, levels):
    """(the law in its form, its shape constants) the output-error fit starts from: of the spectra's choice and
    every form's grid (`JointLaw.variants`, `JointLaw.shapes`), the one whose frequency-domain start simulates the
    recordings best. The spectra weigh each level's change at the excited lines; the simulation weighs what the
    fit will, and a fit of a sharp law stays near the shape it starts from (on the F-16 a friction started at 3 RMS
    velocities of slip ended at worst NRMSE 0.30-0.45 per level, started at the best simulated one at 0.22-0.44)."""
    tried = [(lw, aux)] + [(form, a) for form in law_named(lw.name).variants() for a in form.shapes(d0, v0)
                           if any(t in SHAPE_GRID for t in form.all_terms)]
    if len(tried) == 1:
        return lw, aux
    best, best_cost = (lw, aux), np.inf
    for form, a in tried:
        c, kappa = measured_start(linear, spectra, between, form, d0, v0, a)
        if not (np.all(np.isfinite(c)) and np.all(np.isfinite(kappa))):
            continue
        model = StructureModel(linear, Joint(between, form.name, c, a, kappa, form=form.term_names), levels,
                               reference=linear, oversample=oversampling(linear, spectra[0].fs_hz))
        drives = drives_of(model, recordings, measured, span)
        simulated = cost(stable(model, drives), drives)
        if simulated < best_cost:
            best, best_cost = (form, a), simulated
    return best


def with_modes_above(model, wider, fs_hz, recordings, measured, span):
    """(model, its drives): the start ``wider`` with the modes above the band its joint's harmonics drive
    (`above_band`) where its simulation of the recordings is the closer (an added mode can also carry the joint's
    feedback away: on a chain with a cubic joint it did), else the start as it was."""
    runs = []
    for m in (model,) if wider is model else (model, wider):
        m = replace(m, oversample=oversampling(m.linear, fs_hz))
        runs.append((m, drives_of(m, recordings, measured, span)))
    return min(runs, key=lambda run: cost(stable(*run), run[1]))

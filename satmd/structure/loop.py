"""Modes above the force's band in the joint's loop: where a joint's own stroke flexibility lies.

A shaker's multisine reaches only the modes in its band; the joint's harmonics reach the modes above it, and
through them the joint feels its own force: its stroke per unit force is the sum over every mode of the stroke's
residue over the pole, ``Σ 2 Re(q_r / (−λ_r³))`` at rest. On independent ground vibration tests
(`benchmarks/structures_gvt.py`, the simulator's truth read) the held-out levels were missed where most of that
flexibility lies above the band: with under a quarter there, 37 of 54 joints were predicted within 3x the noise,
with over half, 10 of 29. Modes added above the band from the harmonics of the measured stroke
(`outside.above_band`) do not carry it: the acquisition's anti-alias filter takes the stroke's own motion there,
so the force of the measured stroke lacks the harmonics the loop makes, and their stroke residues stay near
nothing.

Here a few modes are added at the poles the harmonics point to, driven by the joint alone (no shaker residue),
each with a stroke residue ``q`` that gives it a share of the in-band modes' static stroke flexibility, and their
poles, ``q`` and the law's coefficients are fitted by output error in time, every channel's residues and the
joint's column solved inside each step (`outputs.Projection`). The shaker's path κ and the shape constants are
held. On an independent ground vibration test's chain with a cubic joint (`structures_gvt` seed 0, place and
law given) the poles went from 92.2 and 101.1 Hz to 91.2 and 103.3 Hz (the simulator's 90.7 and 104.2) and its
worst held-out NRMSE from 0.121, 0.360, 0.624 to 0.093, 0.145, 0.298 (levels 2, 4, 6).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .output_error import ProjectedFit
from .simulations import oversampling

PAIRS = 2                       # modes added to the loop
#: the added modes' static stroke flexibility at the start, over the in-band modes': the best kept, of the first
#: `LARGE`, or of the rest where none of those stays finite. A law's force that takes back some of the joint's
#: stiffness (a slip, a softening) is a negative spring on that flexibility and runs away above 1/k: on an
#: independent beam with a friction support, three added modes ran away from 0.01 up
SHARES = (1.0, 0.3, 0.1, 0.03, 0.01, 0.003, 0.001)
LARGE = 3
ZETA = (1e-4, 0.3)              # the added modes' damping ratios are held within these
TOP = 0.95                      # of the Nyquist frequency: the added modes stay below it
RUNAWAY = 10.0                  # a smaller share's start this many times the misfit without the added modes: none
STEP = 2                        # every STEP-th sample in the fit (the added modes lie below the record's Nyquist)
FIRST_NFEV = 12                 # steps of the fit (each simulates every recording 2 + 4 × modes + coefficients times)
GAINING = 0.1                   # ... and up to the caller's max_nfev where these first steps took this share off


def static_flexibility(poles, stroke) -> float:
    """The stroke per unit joint force at rest of modes ``poles`` with stroke residues ``stroke`` (accelerance)."""
    return float(np.sum(2 * (stroke / (-poles ** 3)).real))


def _starts(problem, starts, k: int) -> list:
    """[(misfit, θ)] of the starts (one per `SHARES`) that stay finite: the first `LARGE`, and only where none of
    them does the smaller ones, each under `RUNAWAY` times the misfit with the ``k`` added modes undriven (the
    last 2k of θ zero): a share can answer a misfit of 1e254 without running past floating point."""
    def answered(thetas):
        return [(float(a[0] @ a[0]), t) for a, t in ((problem.answer(t), t) for t in thetas) if a is not None]

    finite = answered(starts[:LARGE])
    if finite or len(starts) <= LARGE:
        return finite
    undriven = starts[0].copy()
    undriven[-2 * k:] = 0.0
    held = problem.answer(undriven)
    bound = np.inf if held is None else RUNAWAY * float(held[0] @ held[0])
    return [(c, t) for c, t in answered(starts[LARGE:]) if c < bound]


def with_loop_modes(model, poles, recordings, measured, span, max_nfev: int, fs_hz: float, promising=None):
    """``model`` (a joint, its path and channels solved) with modes at ``poles`` (complex, above the band) in the
    joint's loop, their poles, stroke residues and the law's coefficients fitted on the records' first ``span``
    samples; None where no start keeps the loop finite or the fit gains nothing. The fit goes on past its first
    `FIRST_NFEV` steps where they took `GAINING` off and ``promising`` (callable(model) -> bool, the caller's
    judgement of the model they gave) agrees; None where it does not.

    Returns
    -------
    StructureModel (the added modes' shaker residues zero, their columns solved; intervals of the law's
    coefficients from this fit) or None
    """
    lin, j = model.linear, model.joint
    k, n_c, n_out = poles.size, j.coefficients.size, len(lin.channels)
    in_band = static_flexibility(lin.poles, j.stroke_of(lin) * j.coupling)
    if k == 0 or not np.isfinite(in_band) or in_band == 0:
        return None
    column, stroke = j.column_of(lin), j.stroke_of(lin)

    def build(theta):
        f, zeta = np.exp(theta[n_c:n_c + k]), np.exp(theta[n_c + k:n_c + 2 * k])
        lam = 2 * np.pi * f * (-zeta + 1j * np.sqrt(1 - zeta ** 2))
        q = -0.5 * in_band * lam ** 3 * (theta[n_c + 2 * k:n_c + 3 * k] + 1j * theta[n_c + 3 * k:])
        added = replace(lin, poles=np.concatenate([lin.poles, lam]),
                        residues=np.hstack([lin.residues, np.zeros((n_out, k))]))
        joint = replace(j, coefficients=theta[:n_c], coupling=np.concatenate([j.coupling, q]),
                        column=np.hstack([column, np.zeros((n_out, k))]), stroke=np.concatenate([stroke, np.ones(k)]))
        return replace(model, linear=added, joint=joint, oversample=oversampling(added, fs_hz))

    f0 = np.abs(poles) / (2 * np.pi)
    zeta0 = np.clip(-poles.real / np.abs(poles), 1.01 * ZETA[0], 0.99 * ZETA[1])
    top = np.log(TOP * fs_hz / 2)
    lower = np.concatenate([np.full(n_c, -np.inf), np.full(k, np.log(f0.min()) - 0.5), np.full(k, np.log(ZETA[0])),
                            np.full(2 * k, -np.inf)])
    upper = np.concatenate([np.full(n_c, np.inf), np.full(k, top), np.full(k, np.log(ZETA[1])), np.full(2 * k, np.inf)])
    problem = ProjectedFit(build, (recordings, measured, span), STEP, (lower, upper), 1e-4)
    finite = _starts(problem, [np.concatenate([j.coefficients, np.log(f0), np.log(zeta0), np.full(k, s / k),
                                               np.zeros(k)]) for s in SHARES], k)
    if not finite:
        return None
    start_cost, theta0 = min(finite, key=lambda x: x[0])
    theta0 = np.clip(theta0, lower + 1e-9, upper - 1e-9)
    scale = np.concatenate([np.maximum(np.abs(j.coefficients), 1e-3 * float(np.abs(j.coefficients).max() or 1.0)),
                            np.full(2 * k, 0.1), np.full(2 * k, 1.0 / k)])
    sol = problem.least_squares(theta0, scale, min(max_nfev, FIRST_NFEV))
    if not 2 * sol.cost < start_cost:
        return None
    if 2 * sol.cost < (1 - GAINING) * start_cost and max_nfev > FIRST_NFEV:  # it gains: let it go on ...
        answer = problem.answer(sol.x)
        if answer is None or (promising is not None and not promising(answer[1])):
            return None  # ... where the caller finds it promising (the F-16's gained here and lost on the records)
        sol = problem.least_squares(sol.x, scale, max_nfev - FIRST_NFEV)
    result = problem.result(sol)
    if result is None:
        return None
    fitted, half = result
    names = list(fitted.joint.parameters())
    ci = dict(j.ci95)
    for i, c in enumerate(fitted.joint.coefficients):
        if half is not None and np.isfinite(half[i]):
            ci[names[i]] = [float(c - half[i]), float(c + half[i])]
        else:
            ci.pop(names[i], None)
    return replace(fitted, joint=replace(fitted.joint, ci95=ci))

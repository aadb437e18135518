"""The fused kernels of the plain model (no effects) give the bits of the generic path (issue 36).

`solve_plain_into` is `model.solve(model.terms(...))` fused; `plain_dual_terms` is `model.terms` with
duals seeded on the usual free parameters. Both are checked against the generic path at every output
subset, scalar and per-row fields, the static point (f = 0) and both thread counts through `frf`.
"""
from __future__ import annotations

import numpy as np
import pytest

from satmd.conventions import DEFAULT_FREE
from satmd.physics import CHANNELS, PAPER_GRID_HZ, Rig, frf, solve, terms
from satmd.physics import dual
from satmd.physics.buffers import Workspace
from satmd.physics.kernels import PLAIN_WRT, plain_dual_terms, solve_plain_into, solve_with_tangents

FREQ = np.concatenate([[0.0, 2.0], PAPER_GRID_HZ, [480.0]])
OMEGA = 2 * np.pi * FREQ


def _rig(n, seed, which):
    rng = np.random.default_rng(seed)
    kw = dict(m2=rng.uniform(0.3, 0.8, (n, 1)), kp=rng.uniform(5e4, 2e5, (n, 1)), R=rng.uniform(0, 100, (n, 1)),
              L=rng.uniform(0, 0.5, (n, 1)))
    if which == "coupling":
        kw.update(cp=rng.uniform(0, 10, (n, 1)), Cp=rng.uniform(1e-6, 1e-4, (n, 1)), e=rng.uniform(0, 1, (n, 1)))
    elif which == "host":
        kw.update(k1=rng.uniform(1e5, 3e5, (n, 1)), m1=rng.uniform(0.5, 2, (n, 1)), c1=rng.uniform(0, 20, (n, 1)),
                  F0=rng.uniform(0.1, 3, (n, 1)))
    elif which == "scalar":
        kw = {k: float(v[0, 0]) for k, v in kw.items()}
    return Rig(**kw)


WHICH = ["rows", "coupling", "host", "scalar"]
OUTPUTS = [CHANNELS, ("a1", "a2"), ("q",), ("u2", "a1")]


@pytest.mark.parametrize("outputs", OUTPUTS)
@pytest.mark.parametrize("which", WHICH)
def test_solve_plain_into_is_solve_of_terms_bit_for_bit(which, outputs):
    work = Workspace()
    for n, seed in ((7, 0), (7, 1), (3, 2)):  # one workspace across chunks, the last one smaller
        rig = _rig(n, seed, which)
        want = solve(terms(OMEGA, rig))
        shape = np.broadcast_shapes(rig.batch_shape, OMEGA.shape)
        out = {ch: np.full(shape, np.nan, dtype=complex) for ch in outputs}
        solve_plain_into(OMEGA, rig.as_dict(), out, work)
        for ch in outputs:
            np.testing.assert_array_equal(out[ch], np.broadcast_to(want[ch], shape), err_msg=ch)


@pytest.mark.parametrize("wrt", [tuple(DEFAULT_FREE), ("R", "L"), ("L",), ("kp", "m2"), ("R",)])
@pytest.mark.parametrize("which", WHICH)
def test_plain_dual_terms_are_the_terms_of_the_duals(which, wrt):
    assert set(wrt) <= PLAIN_WRT
    work, ref = Workspace(), Workspace()
    for n, seed in ((5, 3), (2, 4)):
        rig = _rig(n, seed, which)
        shape = np.broadcast_shapes(rig.batch_shape, OMEGA.shape)
        seeded = rig.replace(**{p: dual.Dual.variable(getattr(rig, p), p) for p in wrt})
        got_v = {ch: np.empty(shape, dtype=complex) for ch in CHANNELS}
        got_j = {ch: np.empty(shape + (len(wrt),), dtype=complex) for ch in CHANNELS}
        want_v = {ch: np.empty(shape, dtype=complex) for ch in CHANNELS}
        want_j = {ch: np.empty(shape + (len(wrt),), dtype=complex) for ch in CHANNELS}
        solve_with_tangents(plain_dual_terms(OMEGA, rig.as_dict(), wrt, work), wrt, CHANNELS, got_v, got_j, work)
        solve_with_tangents(terms(OMEGA, seeded), wrt, CHANNELS, want_v, want_j, ref)
        for ch in CHANNELS:
            np.testing.assert_array_equal(got_v[ch], want_v[ch], err_msg=ch)
            np.testing.assert_array_equal(got_j[ch], want_j[ch], err_msg=ch)


def test_the_buffers_change_no_bit_of_the_tangents():
    """`solve_with_tangents` with a workspace (buffers reused) and without one (new arrays)."""
    rig = _rig(6, 5, "coupling")
    wrt = ("m2", "kp", "R", "L", "cp", "e", "k1", "F0")
    seeded = rig.replace(**{p: dual.Dual.variable(getattr(rig, p), p) for p in wrt})
    shape = np.broadcast_shapes(rig.batch_shape, OMEGA.shape)
    res = []
    for work in (None, Workspace()):
        v = {ch: np.empty(shape, dtype=complex) for ch in CHANNELS}
        j = {ch: np.empty(shape + (len(wrt),), dtype=complex) for ch in CHANNELS}
        solve_with_tangents(terms(OMEGA, seeded), wrt, CHANNELS, v, j, work)
        res.append((v, j))
    for ch in CHANNELS:
        np.testing.assert_array_equal(res[0][0][ch], res[1][0][ch])
        np.testing.assert_array_equal(res[0][1][ch], res[1][1][ch])


@pytest.mark.parametrize("wrt", [None, tuple(DEFAULT_FREE), ("R", "cp")])
def test_frf_fast_paths_equal_the_generic_path(wrt):
    """frf takes the fused paths without effects; a neutral effect sends it down the generic one."""
    from satmd.physics import effect

    rng = np.random.default_rng(6)
    n = 2000  # chunked, and threaded with threads=2
    rig = Rig(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n), R=rng.uniform(1, 100, n),
              L=rng.uniform(0.01, 0.5, n))
    neutral = [effect("sensor_gain", gain_a1=1.0, gain_a2=1.0)]
    for threads in (1, 2):
        fast = frf(FREQ, rig, wrt=wrt, threads=threads)
        generic = frf(FREQ, rig, neutral, wrt=wrt, threads=threads)
        for ch in CHANNELS:
            np.testing.assert_array_equal(getattr(fast, ch), getattr(generic, ch), err_msg=ch)
            if wrt:
                np.testing.assert_array_equal(fast.jac[ch], generic.jac[ch], err_msg=ch)

"""The in-place NumPy kernel gives the bits of the reference closed form `model.solve`."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.physics import CHANNELS, PAPER_GRID_HZ, Rig, effect, frf, solve, terms
from satmd.physics.buffers import Workspace
from satmd.physics.kernels import solve_into

FREQ = np.concatenate([[0.0, 2.0], PAPER_GRID_HZ, [480.0]])


def _rig(n, seed):
    rng = np.random.default_rng(seed)
    return Rig(m2=rng.uniform(0.3, 0.8, (n, 1)), kp=rng.uniform(5e4, 2e5, (n, 1)), R=rng.uniform(1, 100, (n, 1)),
               L=rng.uniform(0.01, 0.5, (n, 1)))


EFFECTS = {
    "none": [],
    "sensors": [effect("sensor_gain", gain_a1=1.07, gain_a2=0.94), effect("time_delay", tau_s=1.5e-4)],
    "all": [effect("structural_damping", eta=0.03), effect("dielectric_loss", tan_delta=0.04),
            effect("shunt_capacitance", Cs=3e-6), effect("extra_mode", f_hz=66.0, zeta=0.01, mass_ratio=0.01),
            effect("sensor_gain", gain_a1=1.07, gain_a2=0.94)],
}


@pytest.mark.parametrize("outputs", [CHANNELS, ("a1", "a2"), ("q",), ("u2", "a1")])
@pytest.mark.parametrize("which", sorted(EFFECTS))
def test_solve_into_is_solve_bit_for_bit(which, outputs):
    omega = 2 * np.pi * FREQ
    work = Workspace()
    for n, seed in ((7, 0), (7, 1), (3, 2)):  # the same workspace across chunks, the last one smaller
        t = terms(omega, _rig(n, seed), EFFECTS[which])
        want = solve(t)
        out = {ch: np.full((n, FREQ.size), np.nan, dtype=complex) for ch in outputs}
        solve_into(t, out, work)
        for ch in outputs:
            np.testing.assert_array_equal(out[ch], want[ch], err_msg=ch)


def test_frf_chunked_and_threaded_equals_one_solve():
    rig = Rig(m2=np.linspace(0.3, 0.8, 1000), R=np.linspace(5.0, 100.0, 1000))
    want = solve(terms(2 * np.pi * PAPER_GRID_HZ, rig.replace(m2=rig.m2[:, None], R=rig.R[:, None])))
    for threads in (1, 2):
        got = frf(PAPER_GRID_HZ, rig, threads=threads)
        for ch in CHANNELS:
            np.testing.assert_array_equal(getattr(got, ch), want[ch], err_msg=ch)

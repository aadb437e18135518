"""Sine sweeps at several levels are followed resonance by resonance (issue 47): the levels' local-polynomial
FRFs fall on one grid, so every resonance can be compared level by level."""
from __future__ import annotations

import warnings

import numpy as np

from satmd import discover
from satmd.signal.excitation import received
from satmd.signal.several import common_frfs, on_common_grid
from tests.structure.chain import log_sweep, simulate_chain

FS = 100.0


def _levels():
    """A 4-mass chain (modes near 2.5, 7.1, 10.9, 13.4 Hz) whose second and third masses are joined by a mount
    that gives way (a saturating spring), swept 15 -> 2 Hz in 60 s at four levels, as a GVT sweeps."""
    return simulate_chain(n=4, joint=(1, 2), law=lambda d, v: 3.0 * np.tanh(d / 2e-3), levels=(1.0, 2.0, 4.0, 8.0),
                          fs=FS, force=log_sweep(FS, 60.0, 15.0, 2.0), band=(2.0, 15.0), seed=1, k=2e3)


def test_the_levels_of_a_sweep_share_one_grid():
    recs = [received(r) for r in _levels()]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        datas = common_frfs(recs)
    grid = on_common_grid(datas)
    assert grid is not None and grid[0].size >= 0.5 * min(d.freq_hz.size for d in datas)


def test_a_softening_mount_is_followed_over_swept_levels():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = discover(_levels())
    nl = rep.nonlinear
    assert not rep.model_adequate and nl.detected
    modes = [m for f in nl.findings for m in (f.get("modes") or [])]
    soft = [m for m in modes if m["trend"] == "softening"]
    assert soft, [m["trend"] for m in modes]  # before: no resonance followed (the levels shared no frequency)
    moved = max(soft, key=lambda m: 1 - m["f_hz"][-1] / m["f_hz"][0])
    assert 1 - moved["f_hz"][-1] / moved["f_hz"][0] > 0.02


def _rung_out(quiet_s, laws_seed=1):
    """The mount of `_levels` on a 3-mass chain swept 15 -> 2 Hz in 30 s, with ``quiet_s`` of quiet recorded after."""
    fs = 40.0
    sweep = np.concatenate([log_sweep(fs, 30.0, 15.0, 2.0), np.zeros(int(quiet_s * fs))])
    return simulate_chain(n=3, joint=(1, 2), law=lambda d, v: 3.0 * np.tanh(d / 2e-3), levels=(1.0, 4.0, 8.0), fs=fs,
                          force=sweep, band=(2.0, 15.0), seed=laws_seed, k=2e3)


def test_a_joint_is_located_from_sweeps_that_ring_out_when_asked():
    """A sweep at rest at both ends is one period of its padded DFT: ``E = A − H F`` holds at every line, and the
    joint is placed as from multisines (the place's evidence far ahead of the next), where the sweeps' spectra are
    given explicitly; on their own, sweeps are refused with the measured reason."""
    import pytest

    from satmd.errors import DataError
    from satmd.structure import locate_joint, transient_spectra

    levels = _rung_out(30.0)
    loc = locate_joint([transient_spectra(r) for r in levels], laws=["softening", "cubic"])
    assert loc.detected and loc.between == ("acc2", "acc3") and loc.law == "softening"
    assert loc.location[1]["delta_bic"] > 100
    with pytest.raises(DataError, match="the force is a sweep; locating a joint needs a periodic force .* 7 of 10"):
        locate_joint(levels)


def test_a_sweep_cut_while_the_structure_moves_is_refused_and_discover_says_why_no_joint():
    import pytest

    from satmd.errors import DataError
    from satmd.structure import locate_joint

    from satmd.structure import transient_spectra

    levels = _rung_out(0.0)
    with pytest.raises(DataError, match="the sweep.s record ends with the structure still moving .*a few seconds of "
                                        "quiet after the sweep"):
        locate_joint([transient_spectra(r) for r in levels])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = discover(levels)
    text = rep.report()
    assert "the joint is not located among the sensors" in text and "needs a periodic force" in text
    measurement = [m["name"] for m in rep.estimator.get("measurement", [])]
    assert "narrowband_interference" not in measurement  # the sweep's own transient is not the sensor chain's

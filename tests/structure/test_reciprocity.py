"""The joint's input to each mode from the mode shapes (`satmd.structure.choice`): exact on a chain whose
modes are known in closed form, and what it decides on a ground vibration test satmd did not simulate."""
from __future__ import annotations

import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import eigh

from satmd.modal import fit_modes
from satmd.structure.choice import drives, reciprocal_inputs

M = np.diag([1.0, 1.5, 0.8, 1.2])
K = 1e4 * np.array([[3.0, -1.0, 0.0, 0.0], [-1.0, 2.0, -1.0, 0.0], [0.0, -1.0, 2.5, -1.5], [0.0, 0.0, -1.5, 1.5]])


def _accelerance(freq_hz, drive: int) -> dict:
    """Every mass's accelerance to a force at ``drive``, damping proportional (C = 0.5 M + 2e-4 K): normal modes."""
    w = 2 * np.pi * np.asarray(freq_hz)
    C = 0.5 * M + 2e-4 * K
    H = np.array([np.linalg.solve(K - wk ** 2 * M + 1j * wk * C, np.eye(4)[:, drive]) for wk in w])
    return {f"acc{i + 1}": -(w ** 2) * H[:, i] for i in range(4)}


def test_each_mode_s_input_is_the_shapes_difference_over_the_driving_point_s():
    """κ_r = (φ_a − φ_b) / φ_d of the mass-normalised modes (the generalised eigenproblem K φ = ω² M φ), from the
    residues alone, for a pair of masses and for a mass to the ground."""
    values, shapes = eigh(K, M)
    freq = np.linspace(0.5 * np.sqrt(values[0]), 1.3 * np.sqrt(values[-1]), 900) / (2 * np.pi)
    modal = fit_modes(freq, _accelerance(freq, drive=0))
    assert len(modal.modes) == 4
    order = np.argsort([m.f_hz for m in modal.modes])
    np.testing.assert_allclose(np.array([modal.modes[i].f_hz for i in order]), np.sqrt(values) / (2 * np.pi),
                               rtol=1e-3)
    for place, expected in ((("acc2", "acc3"), (shapes[1] - shapes[2]) / shapes[0]),
                            (("acc4", "ground"), shapes[3] / shapes[0])):
        np.testing.assert_allclose(reciprocal_inputs(modal, "acc1", place)[order], expected, rtol=2e-3, atol=1e-6)


def test_the_driving_point_is_the_named_one_else_each_the_residues_allow():
    values, _ = eigh(K, M)
    freq = np.linspace(0.5 * np.sqrt(values[0]), 1.3 * np.sqrt(values[-1]), 900) / (2 * np.pi)
    modal = fit_modes(freq, _accelerance(freq, drive=2))
    names = ["acc1", "acc2", "acc3", "acc4"]
    assert drives(modal, names) == ["acc3"]  # four modes: only the force's point is in phase with it on each
    assert drives(modal, names, "acc2") == ["acc2"] and drives(modal, names, "acc9") == []


@pytest.fixture(scope="module")
def wing():
    """The independent ground vibration test simulator's wing 75 (`benchmarks/_indep_gvt.py`: a cantilever wing, a
    payload on a pylon, four accelerometers, the shaker at acc3, a cubic spring from acc1 to the ground), its
    levels 1, 3, 5, 7 written to CSV and read back as a user's files."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    import _indep_gvt as sim
    from satmd.io import load_recording

    test = sim.make_test(75, "wing", "cubic")
    records = sim.simulate(test)
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = []
        for level in (1, 3, 5, 7):
            sim.write_csv(records[level - 1], Path(tmp) / f"L{level}.csv")
            loaded.append(load_recording(Path(tmp) / f"L{level}.csv"))
    return test, loaded


def test_places_the_spectra_cannot_tell_apart_are_weighed_with_the_mode_shapes(wing):
    """With each mode's input free, a spring from the wing's root to the ground is placed between acc1 and acc2
    (the true place fifth, ΔBIC 474 of an evidence of 45 000); weighed with the inputs the mode shapes give, at the
    sensors that may be the driving point (two modes: several), the root is placed, and by thousands."""
    from satmd.structure import locate_joint

    test, loaded = wing
    assert tuple(test.between) == ("acc1", "ground") and test.describe()["drive"] == "acc3"
    loc = locate_joint(loaded)
    assert loc.between == ("acc1", "ground") and loc.reciprocal
    weighed = [e for e in loc.location if e.get("inputs") == "reciprocal"]
    assert 1 < len(weighed) <= 5 and weighed[0]["spectra_delta_bic"] > 0  # not the spectra's first
    assert weighed[1]["delta_bic"] > 1000 and "reciprocity through" in loc.report()


def test_a_driving_point_that_is_not_a_channel_is_refused(wing):
    from satmd.errors import DataError
    from satmd.structure import locate_joint

    with pytest.raises(DataError, match="the driving point 'acc9' is not a channel"):
        locate_joint(wing[1], driving_point="acc9")

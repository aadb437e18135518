"""A lab's file of several random-phase realisations (the F-16's odd multisines: Force realisation × time,
Acceleration channel × realisation × time): read whole, estimated as the best linear approximation over them."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.io import load_recording
from satmd.signal import estimate_frf
from satmd.structure import LinearStructure, StructureModel
from tests.structure.chain import multisine

FS, PERIOD, PERIODS, REALISATIONS = 256.0, 1024, 3, 4


def _two_modes():
    fr, zeta = np.array([11.0, 26.0]), np.array([0.02, 0.015])
    wn = 2 * np.pi * fr
    poles = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2)
    residues = np.array([poles ** 2 / (2j * poles.imag), 0.5 * poles ** 2 / (2j * poles.imag)])
    return StructureModel(LinearStructure(("acc1", "acc2"), poles, residues, np.array([1.0, 0.5])), None, (1.0, 1.0))


@pytest.fixture(scope="module")
def lab_file(tmp_path_factory):
    """Four realisations of three periods, each from rest, 1 % noise on every channel, as the F-16 stores them."""
    model, rng = _two_modes(), np.random.default_rng(11)
    forces, accels = [], []
    for seed in range(REALISATIONS):
        force = np.tile(multisine(PERIOD, FS, 5.0, 40.0, 20 + seed), PERIODS)
        accel = model.simulate(force, FS)
        forces.append(force + 0.01 * force.std() * rng.standard_normal(force.size))
        accels.append(accel + 0.01 * accel.std(axis=1, keepdims=True) * rng.standard_normal(accel.shape))
    path = tmp_path_factory.mktemp("lab") / "odd.npz"
    np.savez(path, Force=np.array(forces), Acceleration=np.stack(accels, axis=1), Fs=np.float64(FS))
    return path, model


def test_the_realisations_give_the_best_linear_approximation_over_them(lab_file):
    """The estimate is the mean over realisations at every line excited in all of them, its std from their spread
    (2 (M - 1) degrees of freedom): the true FRF's error over it is distributed as it says (|e|²/(2 s²) ~ F(2,
    2 (M - 1)): 95 % of the lines within that F's 95 % point, 0.88-0.995 allowed for ~140 lines a channel)."""
    from scipy.stats import f as fisher

    path, model = lab_file
    data = estimate_frf(load_recording(path))
    assert data.estimator["method"] == "realisations" and data.estimator["realisations"] == REALISATIONS
    assert data.estimator["noise_dof"] == 2 * (REALISATIONS - 1) and data.estimator["steady_periods"] == 2
    assert data.freq_hz[0] <= 5.5 and data.freq_hz[-1] >= 39.5 and data.freq_hz.size > 100
    truth = model.linear.frf(data.freq_hz)
    for i, name in enumerate(("a1", "a2")):
        ratio = np.abs(data.channels[name] - truth[i]) ** 2 / (2 * data.std[name] ** 2)
        assert 0.88 <= np.mean(ratio < fisher.ppf(0.95, 2, 2 * (REALISATIONS - 1))) <= 0.995
        assert np.median(data.std[name] / np.abs(truth[i])) < 0.01
        assert np.median(data.coherence[name]) > 0.99


def test_a_map_still_picks_one_realisation(lab_file):
    """One realisation read through a channel map is one periodic test: the mean over its steady periods."""
    path, _ = lab_file
    one = load_recording(path, channel_map="force=Force[2],a1=Acceleration[1,2],a2=Acceleration[2,2]")
    assert estimate_frf(one).estimator["method"] == "periodic"


def test_info_says_the_file_holds_realisations(lab_file, capsys):
    from satmd.cli import main

    path, _ = lab_file
    assert main(["info", str(path)]) == 0
    assert f"{REALISATIONS} realisations of {PERIOD * PERIODS} samples, one after another" in capsys.readouterr().out

"""A lab's realisations in one file (`Recording.realisations`): each simulated, located and fitted as the periodic
test it is."""
from __future__ import annotations

import numpy as np

from satmd.io import Recording
from satmd.structure import LinearStructure, StructureModel
from tests.structure.chain import multisine

FS, PERIOD = 256.0, 1024


def _realisations(periods, count, seed=3):
    """Random-phase multisines of ``periods`` periods each, one after another (their force as the response)."""
    forces = [np.tile(multisine(PERIOD, FS, 5.0, 40.0, seed + k), periods) for k in range(count)]
    meta = {"source": "lab.mat", "realisations": str(count), "realisation_samples": str(forces[0].size)}
    return Recording(FS, {"force": np.concatenate(forces), "acc1": np.concatenate(forces)}, meta=meta)


def test_each_realisation_is_simulated_from_its_own_start():
    """A lab's file of several realisations (each a multisine from rest) is predicted one realisation at a time:
    as closely as one realisation alone (the force driven at its lines leaves 0.2-0.4 %) where the responses were
    simulated so, while one simulation through the whole record carries the first realisation's ringing into
    the second."""
    from satmd.structure.prediction import nrmse as plain_nrmse

    fr, zeta = np.array([9.0, 31.0]), np.array([0.01, 0.015])  # the ringing lasts into the second period
    wn = 2 * np.pi * fr
    poles = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2)
    model = StructureModel(LinearStructure(("acc1",), poles, (poles ** 2 / (2j * poles.imag))[None, :],
                                           np.array([2.0])), None, (1.0, 1.0))
    forces = [np.tile(multisine(PERIOD, FS, 5.0, 40.0, seed), 4) for seed in (3, 4)]
    responses = [model.simulate(f, FS)[0] for f in forces]
    meta = {"source": "test", "realisations": "2", "realisation_samples": str(forces[0].size)}
    rec = Recording(FS, {"force": np.concatenate(forces), "acc1": np.concatenate(responses)}, meta=meta)
    prediction = model.predict(rec)
    assert prediction.nrmse[0] < 0.01 and prediction.to_dict()["realisations"] == 2
    assert prediction.going_on == 0 and "over 2 realisations (0 going on from the one before" in prediction.report()
    through = model.simulate(np.concatenate(forces), FS)[0]
    assert plain_nrmse(through, np.concatenate(responses)) > 0.05


def test_a_realisation_is_read_again_as_the_periodic_test_it_is():
    """Each realisation given back (`each_realisation`) is read again, a periodic test of its own with its own
    periods, whatever was read from the whole (two random-phase multisines one after another: six periods of
    which the first realisation's three were taken for a start-up)."""
    from satmd.signal.excitation import excitation_of, received
    from satmd.io.recdata import each_realisation

    forces = [np.tile(multisine(PERIOD, FS, 5.0, 40.0, seed), 3) for seed in (5, 6)]
    meta = {"source": "lab.mat", "realisations": "2", "realisation_samples": str(forces[0].size)}
    whole = received(Recording(FS, {"force": np.concatenate(forces), "acc1": np.concatenate(forces)}, meta=meta))
    parts = each_realisation([whole])
    assert [p.meta["source"] for p in parts] == ["lab.mat (realisation 1)", "lab.mat (realisation 2)"]
    assert all(excitation_of(p).kind == "periodic" and excitation_of(p).period_samples == PERIOD
               and excitation_of(p).periods == 3 for p in parts)


def test_the_fit_takes_as_many_realisations_as_make_its_steady_periods():
    """Of each file the output-error fit simulates the realisations that make up `FIT_PERIODS` steady periods
    (each realisation's first period is its start-up): one of four steady periods, two of two (5 and 3 periods
    a realisation; of two periods both are kept, so two of those too); a file of one record is that record."""
    from satmd.structure.simulations import FIT_PERIODS, fitted_realisations

    assert FIT_PERIODS == 3
    counts = [len(fitted_realisations([_realisations(periods, 4)])) for periods in (5, 3, 2)]
    assert counts == [1, 2, 2]
    one = _realisations(3, 1)
    assert fitted_realisations([one]) == [one]


def test_a_joint_is_located_from_files_of_realisations():
    """Two levels of a chain with a cubic joint between masses 3 and 4, each a file of two random-phase
    realisations (three periods each, from rest): located between acc3 and acc4 from the realisations, where
    the whole files read as one record each are no periodic test."""
    from satmd.structure import locate_joint
    from tests.structure.chain import simulate_chain

    sets = [simulate_chain(joint=(2, 3), levels=(1.0, 8.0), periods=3, seed=seed) for seed in (21, 22)]
    files = []
    for level, parts in enumerate(zip(*sets)):
        n = parts[0].n_samples
        meta = {"source": f"level{level + 1}.mat", "realisations": "2", "realisation_samples": str(n)}
        files.append(Recording(parts[0].fs_hz, {c: np.concatenate([p[c] for p in parts]) for c in parts[0].channels},
                               meta=meta))
    assert locate_joint(files).between == ("acc3", "acc4")


def test_where_the_model_misses_is_found_among_the_fitted_realisations():
    """The fit table has a row per fitted realisation: its worst row is that realisation, not a file (one file of
    two realisations: the second is the worst; it was an IndexError)."""
    from types import SimpleNamespace

    from satmd.discovery.nonlinear.modes import where_it_misses

    seen = []

    class TwoRows:
        fit = {"linear": [[0.01, 0.012], [0.2, 0.3]], "nonlinear": [[0.01, 0.012], [0.1, 0.32]]}

        def predict(self, recording):
            seen.append(recording.meta.get("realisation"))
            return SimpleNamespace(nrmse=[0.1, 0.32], channels=["acc1", "acc2"], level=8.0, band_top_hz=40.0,
                                   above_band={"nrmse": [0.05, 0.30], "measured": [0.1, 0.45]})

    found = where_it_misses(TwoRows(), [_realisations(3, 2)])
    assert found["recording"] == 1 and seen == ["2"]


def test_a_realisation_measured_without_stopping_goes_on_from_the_one_before():
    """Realisations measured one after another without stopping the shaker (one simulation through them all) are
    predicted going on from the one before, as closely as one realisation alone; each from rest they missed by 0.15."""
    fr, zeta = np.array([9.0, 31.0]), np.array([0.01, 0.015])
    wn = 2 * np.pi * fr
    poles = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2)
    model = StructureModel(LinearStructure(("acc1",), poles, (poles ** 2 / (2j * poles.imag))[None, :],
                                           np.array([2.0])), None, (1.0, 1.0))
    forces = [np.tile(multisine(PERIOD, FS, 5.0, 40.0, seed), 4) for seed in (3, 4, 5)]
    through = model.simulate(np.concatenate(forces), FS)[0]
    meta = {"source": "test", "realisations": "3", "realisation_samples": str(forces[0].size)}
    prediction = model.predict(Recording(FS, {"force": np.concatenate(forces), "acc1": through}, meta=meta))
    assert prediction.going_on == 2 and prediction.nrmse[0] < 0.01

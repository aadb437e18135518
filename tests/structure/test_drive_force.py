"""The force a structure model is driven by (`satmd.structure.spectra.drive_force`): the load cell's noise is not
the structure's input."""
from __future__ import annotations

import numpy as np

from satmd.io import Recording
from satmd.structure import LinearStructure, StructureModel
from satmd.structure.model import nrmse
from satmd.structure.spectra import drive_force
from tests.structure.chain import multisine

FS, PERIOD, PERIODS = 256.0, 1024, 6


def _periodic_force(noise, seed=0, harmonic=0.0):
    """(clean, measured) force: a 5-40 Hz multisine repeated from rest, plus a tone at 60 Hz (``harmonic``,
    as a shaker's own distortion), plus white noise of ``noise`` times the multisine's RMS."""
    one = multisine(PERIOD, FS, 5.0, 40.0, seed)
    t = np.arange(PERIOD) / FS
    one = one + harmonic * np.sin(2 * np.pi * 60.0 * t)
    clean = np.tile(one, PERIODS)
    rng = np.random.default_rng(seed + 1)
    return clean, clean + noise * rng.standard_normal(clean.size)


def test_the_steady_periods_keep_the_force_and_lose_its_noise():
    """Over the steady periods the driven force is the mean period at the lines above the noise: the multisine
    and a tone the shaker adds above the band (20 % of the RMS) stay, the white noise (3 %) drops to what its
    share of the excited lines over the periods averaged leaves (~1 %)."""
    clean, measured = _periodic_force(0.03, harmonic=0.2)
    rec = Recording(FS, {"force": measured, "acc1": clean}, meta={"source": "test"})
    driven = drive_force(rec)
    steady = slice(PERIOD, None)  # the first period is the start from rest the response shows
    before = np.std(measured[steady] - clean[steady]) / np.std(clean)
    after = np.std(driven[steady] - clean[steady]) / np.std(clean)
    assert before > 0.025 and after < 0.012
    tone = np.abs(np.fft.rfft(driven[-PERIOD:]))[int(60.0 * PERIOD / FS)] / (PERIOD / 2)
    assert abs(tone - 0.2) < 0.01


def test_a_force_that_is_not_periodic_is_driven_as_measured():
    rng = np.random.default_rng(3)
    force = rng.standard_normal(PERIOD * PERIODS)
    rec = Recording(FS, {"force": force, "acc1": rng.standard_normal(force.size)}, meta={"source": "test"})
    assert np.array_equal(drive_force(rec), force)


def test_a_prediction_is_not_the_structure_s_answer_to_the_load_cell_s_noise():
    """A driving point with a mode above the band (80 Hz) and force noise of 2 %: driven by the measured force
    the simulated response carries the mode's answer to the noise (several times the accelerometers' 0.5 %);
    driven by `drive_force` the prediction of the steady periods comes back to within twice that noise."""
    fr, zeta, shape = np.array([12.0, 27.0, 80.0]), np.array([0.02, 0.015, 0.01]), np.array([1.0, -0.8, 1.5])
    wn = 2 * np.pi * fr
    poles = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2)
    receptance = shape ** 2 / (2j * poles.imag)  # a mass-normalised mode's residue in displacement
    linear = LinearStructure(("acc1",), poles, (receptance * poles ** 2)[None, :], np.array([np.sum(shape ** 2)]))
    model = StructureModel(linear, None, (1.0, 1.0))
    clean, measured = _periodic_force(0.02, seed=4)
    response = model.simulate(clean, FS)[0]
    rng = np.random.default_rng(5)
    recorded = response + 0.005 * np.std(response) * rng.standard_normal(response.size)
    rec = Recording(FS, {"force": measured, "acc1": recorded}, meta={"source": "test"})
    steady = slice(PERIOD, None)
    as_measured = nrmse(model.simulate(measured, FS)[0][steady], recorded[steady])
    predicted = model.predict(rec)
    driven = nrmse(predicted.signals["acc1"][2][steady], recorded[steady])
    assert as_measured > 3 * 0.005
    assert driven < 2 * 0.005


def test_a_start_from_rest_keeps_its_transient_and_loses_the_noise_after_it():
    """Before the steady periods the driven force is the mean period plus the start's departure from it while that
    stands above the load cell's noise: a shaker's own start-up (a 15 Hz kick decaying in 50 ms) is kept, the
    noise (3 %) after it is gone from the first period as from the others."""
    clean, _ = _periodic_force(0.0, seed=2)
    t = np.arange(PERIOD) / FS
    clean[:PERIOD] += 2.0 * np.exp(-t / 0.05) * np.sin(2 * np.pi * 15.0 * t)
    measured = clean + 0.03 * np.random.default_rng(7).standard_normal(clean.size)
    fr, zeta = np.array([12.0, 27.0]), np.array([0.02, 0.015])
    wn = 2 * np.pi * fr
    poles = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2)
    model = StructureModel(LinearStructure(("acc1",), poles, (poles ** 2 / (2j * poles.imag))[None, :],
                                           np.array([2.0])), None, (1.0, 1.0))
    rec = Recording(FS, {"force": measured, "acc1": model.simulate(clean, FS)[0]}, meta={"source": "test"})
    driven = drive_force(rec)
    kick, after = slice(0, 32), slice(int(0.5 * FS), PERIOD)  # the kick's first 125 ms; the first period after it
    assert np.std(clean[kick] - clean[PERIOD:PERIOD + 32]) > 0.5  # the kick, beside the steady period
    assert np.std(driven[kick] - clean[kick]) < 0.045
    assert np.std(measured[after] - clean[after]) > 0.025 and np.std(driven[after] - clean[after]) < 0.012


def test_the_load_cell_s_noise_lines_are_not_kept_as_force():
    """Off the excited lines the force is noise alone; judged line by line from a few periods, a ratio of three
    standard errors let one noise line in about a hundred through (F(2, 2(P − 1)) tails), some four a record here.
    Judged against its neighbours' spread, over five records of six periods no more than one noise line is kept,
    and the shaker's own tone above the band (1 % of the RMS) always is."""
    kept, tones = 0, 0
    for seed in range(5):
        clean, measured = _periodic_force(0.03, seed=seed, harmonic=0.01)
        rec = Recording(FS, {"force": measured, "acc1": clean}, meta={"source": "test"})
        line = np.abs(np.fft.rfft(drive_force(rec)[-PERIOD:]))
        f = np.fft.rfftfreq(PERIOD, 1.0 / FS)
        tone = int(60.0 * PERIOD / FS)
        off = (f > 41.0) & (np.arange(f.size) != tone)  # beyond the multisine, but for the tone
        kept += int(np.sum(line[off] > 1e-9 * line.max()))
        tones += int(line[tone] > 0.5 * 0.01 * np.std(clean) * PERIOD / 2)
    assert kept <= 1 and tones == 5


def test_a_sweep_loses_the_load_cell_s_noise_outside_its_band():
    """A sweep is not periodic: no mean period to take. What it holds outside its band (5-40 Hz of the 128 Hz a
    record carries) is the load cell's noise alone, and goes; the sweep stays (what is left of the 2 % noise is its
    share in the band, about half), and after the sweep the quiet is quieter by as much. A white random force
    has no band of its own and stays as measured (the test above)."""
    from tests.structure.chain import log_sweep

    clean = np.concatenate([log_sweep(FS, 20.0, 40.0, 5.0), np.zeros(int(10 * FS))])
    noise = 0.02 * np.std(clean[: int(20 * FS)]) * np.random.default_rng(11).standard_normal(clean.size)
    rec = Recording(FS, {"force": clean + noise, "acc1": clean}, meta={"source": "test"})
    driven = drive_force(rec)
    scale, tail = np.std(clean), slice(int(22 * FS), None)
    assert np.std(noise) / scale > 0.019 and np.std(driven - clean) / scale < 0.6 * np.std(noise) / scale
    assert np.std(driven[tail]) < 0.6 * np.std(noise[tail])
    spectrum = np.abs(np.fft.rfft(driven - clean))
    f = np.fft.rfftfreq(clean.size, 1.0 / FS)
    assert np.sqrt(np.mean(spectrum[f > 45.0] ** 2)) < 0.2 * np.sqrt(np.mean(spectrum[(f > 10) & (f < 35)] ** 2))


def test_a_hammer_s_force_is_driven_as_measured():
    """An impact fills the spectrum up to Nyquist: no band stands above a floor, nothing is taken out."""
    force = np.zeros(PERIOD * 4)
    for start in range(100, force.size, PERIOD):
        force[start:start + 2] = (300.0, 120.0)
    force += 0.5 * np.random.default_rng(12).standard_normal(force.size)
    rec = Recording(FS, {"force": force, "acc1": force}, meta={"source": "test"})
    assert np.array_equal(drive_force(rec), force)


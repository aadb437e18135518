"""Modes above the force's band, from the start from rest (`satmd.structure.startup`), on the independent chain of
`chain.py`: four masses, a multisine to 36 Hz (two modes in the band, 48.8 and 59.8 Hz above it)."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.io import Recording
from satmd.structure import StructureModel
from satmd.structure.linear import fit_linear
from satmd.structure.spectra import periodic_spectra
from satmd.structure.startup import band_top_hz, start_up_modes
from tests.structure.chain import chain_matrices, simulate_chain

BAND = (3.0, 36.0)
NOISE = 0.005
LINEAR = dict(n=4, joint=(0, None), law=lambda d, v: 0.0, band=BAND, noise=NOISE, period=1024, periods=4)


def _above_band_hz():
    M, K, _ = chain_matrices(4)
    f = np.sort(np.sqrt(np.linalg.eigvals(np.linalg.solve(np.diag(M), K)).real)) / (2 * np.pi)
    return f[f > BAND[1]]


@pytest.fixture(scope="module")
def chain():
    """Two levels from rest (the fit's), and a held-out level with another multisine."""
    fitted = simulate_chain(levels=(1.0, 2.0), seed=3, **LINEAR)
    held = simulate_chain(levels=(1.5,), seed=4, **LINEAR)[0]
    spectra = [periodic_spectra(r) for r in fitted]
    names = tuple(c for c in fitted[0].channels if c != "force")
    return fitted, held, spectra, fit_linear(spectra[0], names)


def _worst_nrmse(linear, recording):
    return max(StructureModel(linear, None, (1.0, 2.0)).predict(recording).nrmse)


def test_the_modes_above_the_band_are_found_in_the_start_from_rest(chain):
    """The steady spectra know no mode above 36 Hz; the first period's ring-down shows both (within 1 % in
    frequency), and the held-out level, from rest too, is then simulated within three times the noise, a quarter
    closer than without them (the rest is the force's noise and its straight lines between samples, which the
    model takes for the band-limited force)."""
    fitted, held, spectra, linear = chain
    top = band_top_hz(spectra)
    assert top == pytest.approx(BAND[1], abs=0.3)
    wider = start_up_modes(linear, fitted, top)
    above = np.sort(wider.poles.imag[wider.poles.imag > 2 * np.pi * top]) / (2 * np.pi)
    truth = _above_band_hz()
    assert all(np.min(np.abs(above - f)) < 0.01 * f for f in truth), (above, truth)
    without, with_modes = _worst_nrmse(linear, held), _worst_nrmse(wider, held)
    assert without > 3 * NOISE
    assert with_modes < 3 * NOISE and with_modes < 0.75 * without


def test_a_record_in_steady_state_shows_no_mode_above_the_band(chain):
    """Without the start (the first period dropped: the record starts in steady state) nothing is seen above
    the band, and the model is returned as it was."""
    fitted, _, spectra, linear = chain
    n = 1024
    steady = [Recording(r.fs_hz, {c: np.asarray(r[c])[n:] for c in r.channels}, meta=r.meta) for r in fitted]
    assert start_up_modes(linear, steady, band_top_hz(spectra)) is linear


def test_a_structure_with_no_mode_above_the_band_is_left_as_it_was():
    """Three masses excited to 62 Hz (all three modes in the band): no pole above it pays."""
    three = dict(LINEAR, n=3, band=(3.0, 62.0))
    fitted = simulate_chain(levels=(1.0,), seed=5, **three)
    spectra = [periodic_spectra(r) for r in fitted]
    linear = fit_linear(spectra[0], ("acc1", "acc2", "acc3"))
    assert start_up_modes(linear, fitted, band_top_hz(spectra)) is linear


def test_a_record_begun_in_motion_is_no_start_from_rest(chain):
    """A record cut from a longer test, its first periods drifting as the F-16's do (read as a transient), starts
    in steady state (`warmup_of`: one period of warm-up) and shows no mode above the band; the same test from
    rest starts from rest."""
    from satmd.signal.excitation import excitation_of, received
    from satmd.structure.spectra import warmup_of

    fitted, _, spectra, linear = chain
    n = 1024
    cut = {c: np.asarray(fitted[0][c], float)[n:] for c in fitted[0].channels}
    drift = 1.0 + 0.05 * np.exp(-np.arange(cut["force"].size) / n)  # a gain settling over the first periods
    moving = Recording(fitted[0].fs_hz, {c: x * drift if c != "force" else x for c, x in cut.items()},
                       meta=fitted[0].meta)
    assert excitation_of(received(moving)).transient_periods  # the drift reads as a transient
    assert warmup_of(moving) == n and warmup_of(fitted[0]) == 0
    assert start_up_modes(linear, [moving], band_top_hz(spectra)) is linear


def test_poles_refined_to_one_point_are_one_pole():
    """Refined together, two poles above the band can run to one corner of their bounds, their least-squares
    residues then cancelling at a hundred million times the modes' (a double pole, no mode): one of them is kept.
    So is one of two poles closer than a record of a few seconds resolves (86.79 and 86.82 Hz); poles apart, in
    frequency (86.8 and 88 Hz) or in damping (27 % and 25 %), are all kept."""
    from satmd.structure.startup import _distinct, _pole

    corner = _pole(102.4, 0.3)
    assert _distinct(np.array([corner, corner * (1 + 1e-5), _pole(86.8, 0.009)])).size == 2
    assert _distinct(np.array([_pole(86.79, 0.0087), _pole(86.82, 0.0088)])).size == 1
    apart = np.array([_pole(86.8, 0.0087), _pole(88.0, 0.0088), _pole(102.4, 0.27), _pole(102.4, 0.25)])
    assert np.array_equal(_distinct(apart), apart)

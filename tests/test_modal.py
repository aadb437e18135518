"""satmd.modal: several modes at once from exact modal data, their intervals, and tracking over levels."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from satmd.io.frfdata import FRFData
from satmd.modal import fit_modes, track_modes

FREQ = np.linspace(5.0, 60.0, 600)


def modal_frf(freq, modes, kind="accelerance"):
    """Closed-form FRFs of two channels: Σ_r A_r / (iω − λ_r) + conjugate, receptance or accelerance.

    ``modes``: (f_hz, zeta, residue of a1, residue of a2); the residues are those of a receptance.
    """
    iw = 2j * np.pi * np.asarray(freq)
    out = {"a1": np.zeros(iw.size, complex), "a2": np.zeros(iw.size, complex)}
    for f, zeta, *residues in modes:
        wn = 2 * np.pi * f
        lam = -zeta * wn + 1j * wn * np.sqrt(1 - zeta ** 2)
        for c, A in zip(out, residues):
            out[c] += A / (iw - lam) + np.conj(A) / (iw - np.conj(lam))
    if kind == "accelerance":
        out = {c: iw ** 2 * h for c, h in out.items()}
    return out


def noisy(H, share, rng):
    """H plus complex Gaussian noise of std ``share`` × max|H| per real and imaginary part, and that std."""
    std = {c: np.full(h.size, share * np.abs(h).max()) for c, h in H.items()}
    return {c: h + std[c] * (rng.standard_normal(h.size) + 1j * rng.standard_normal(h.size))
            for c, h in H.items()}, std


THREE = [(12.0, 0.010, -1e-3j, -0.6e-3j), (25.0, 0.020, -2e-3j, 1e-3j), (48.0, 0.005, -0.5e-3j, -0.8e-3j)]


def found(fit, truth):
    """The fitted mode nearest each true one."""
    return [min(fit.modes, key=lambda m: abs(m.f_hz - t[0])) for t in truth]


@pytest.mark.parametrize("kind", ["accelerance", "receptance"])
def test_exact_data_give_the_modes_exactly(kind):
    H = modal_frf(FREQ, THREE, kind)
    fit = fit_modes(FREQ, H)
    assert len(fit.modes) == 3
    for m, (f, zeta, *_rest) in zip(fit.modes, THREE):
        assert m.f_hz == pytest.approx(f, rel=1e-6)
        assert m.zeta == pytest.approx(zeta, rel=1e-4)
    pred = fit.predict(FREQ)
    for c in H:
        assert np.abs(pred[c] - H[c]).max() <= 1e-6 * np.abs(H[c]).max()


def test_noisy_data_close_modes_and_intervals_that_hold_the_truth():
    truth = [(12.0, 0.010, -1e-3j, -0.6e-3j), (25.0, 0.015, -2e-3j, 1e-3j), (25.8, 0.012, -1e-3j, -1e-3j),
             (48.0, 0.005, -0.5e-3j, -0.8e-3j)]
    H, std = noisy(modal_frf(FREQ, truth), 0.01, np.random.default_rng(1))
    fit = fit_modes(FREQ, H, std)
    assert len(fit.modes) == 4
    assert fit.weighted and 0.8 < fit.chi2_reduced < 1.2
    for m, (f, zeta, *_rest) in zip(fit.modes, truth):
        assert m.f_hz == pytest.approx(f, rel=2e-3)
        assert m.zeta == pytest.approx(zeta, rel=0.1)
        assert m.f_ci95[0] - 3 * m.f_std < f < m.f_ci95[1] + 3 * m.f_std  # 95 % interval, with some slack
        assert m.zeta_ci95[0] - 3 * m.zeta_std < zeta < m.zeta_ci95[1] + 3 * m.zeta_std


def test_a_mode_at_the_band_edge():
    truth = [(20.0, 0.01, -1e-3j, -1e-3j), (39.6, 0.01, -1e-3j, 0.5e-3j)]
    H = modal_frf(FREQ, truth)
    fit = fit_modes(FREQ, H, band_hz=(10.0, 39.8))  # the second peak's upper flank is cut off
    assert [round(m.f_hz, 4) for m in fit.modes] == [20.0, 39.6]
    assert fit.modes[1].zeta == pytest.approx(0.01, rel=1e-3)


def test_intervals_cover_the_truth_over_noisy_draws():
    truth = [(15.0, 0.02, -1e-3j, -0.5e-3j), (40.0, 0.01, -1e-3j, 1e-3j)]
    freq = np.linspace(5.0, 60.0, 300)  # 5 points per half-power width at 40 Hz: enough, and quick
    exact = modal_frf(freq, truth)
    rng = np.random.default_rng(7)
    hits = {"f": 0, "zeta": 0, "f no std": 0}
    draws = 20
    for _ in range(draws):
        H, std = noisy(exact, 0.02, rng)
        weighted, plain = fit_modes(freq, H, std), fit_modes(freq, H)
        for m, mp, (f, zeta, *_rest) in zip(found(weighted, truth), found(plain, truth), truth):
            hits["f"] += m.f_ci95[0] <= f <= m.f_ci95[1]
            hits["zeta"] += m.zeta_ci95[0] <= zeta <= m.zeta_ci95[1]
            hits["f no std"] += mp.f_ci95[0] <= f <= mp.f_ci95[1]
    # 95 % intervals: about 38 of 40 hit; a binomial at 95 % falls below 33 with probability < 0.1 %
    assert all(h >= 33 for h in hits.values()), hits


def test_frfdata_in_and_to_dict_out():
    H, std = noisy(modal_frf(FREQ, THREE), 0.005, np.random.default_rng(3))
    data = FRFData(FREQ, H, std)
    fit = fit_modes(None, data)
    assert fit.weighted and len(fit.modes) == 3
    d = fit.to_dict()
    assert set(d["modes"][0]) == {"f_hz", "f_ci95", "zeta", "zeta_ci95"}
    assert all(np.isfinite(d["modes"][i]["f_ci95"]).all() for i in range(3))


@settings(max_examples=12, deadline=None)
@given(f=st.floats(8.0, 55.0), zeta=st.floats(0.002, 0.05), ratio=st.floats(-2.0, 2.0).filter(lambda r: abs(r) > 0.05))
def test_one_exact_mode_anywhere_in_the_band(f, zeta, ratio):
    # a normal mode (imaginary residues): alone in the band, it is a physical FRF
    H = modal_frf(FREQ, [(f, zeta, -1e-3j, -1e-3j * ratio)])
    fit = fit_modes(FREQ, H)
    assert len(fit.modes) == 1
    assert fit.modes[0].f_hz == pytest.approx(f, rel=1e-5)
    assert fit.modes[0].zeta == pytest.approx(zeta, rel=1e-3)


# --- tracking -----------------------------------------------------------------------------------------------
def level_fits(moving, seed, levels):
    """Fits of three noisy levels: the 25 Hz mode follows ``moving`` (f, zeta per level), the others stay."""
    rng = np.random.default_rng(seed)
    fits = []
    for f, zeta in moving:
        truth = [(12.0, 0.010, -1e-3j, -0.6e-3j), (f, zeta, -2e-3j, 1e-3j), (48.0, 0.005, -0.5e-3j, -0.8e-3j)]
        H, std = noisy(modal_frf(FREQ, truth), 0.005, rng)
        fits.append(fit_modes(FREQ, H, std))
    return track_modes(fits, levels)


def test_a_mode_that_softens_with_rising_damping():
    # given out of level order: the lists follow the order given, the trends the levels
    tracks = level_fits([(24.6, 0.030), (25.0, 0.015), (24.8, 0.020)], seed=4, levels=[80.0, 10.0, 40.0])
    assert len(tracks) == 3
    moved = [t for t in tracks if t.moves]
    assert len(moved) == 1
    t = moved[0]
    assert (t.trend, t.damping_trend) == ("softening", "rising")
    assert t.f_hz[0] == pytest.approx(24.6, rel=2e-3) and t.f_hz[1] == pytest.approx(25.0, rel=2e-3)
    d = t.to_dict()
    assert len(d["f_ci95"]) == 3 and d["zeta"][0] > d["zeta"][2] > d["zeta"][1]


def test_modes_that_stay_put_do_not_move():
    tracks = level_fits([(25.0, 0.015)] * 3, seed=5, levels=None)
    assert len(tracks) == 3
    assert [(t.trend, t.damping_trend) for t in tracks] == [("none", "none")] * 3


def test_a_lightly_damped_mode_that_moves_beyond_its_bandwidth_is_still_followed():
    # 25 -> 26 Hz is ten half-power widths of a 0.2 % mode, far less than the 13 Hz to its neighbours (issue 35)
    tracks = level_fits([(25.0, 0.004), (25.5, 0.004), (26.0, 0.004)], seed=6, levels=[1.0, 2.0, 3.0])
    assert len(tracks) == 3
    t = [t for t in tracks if 20 < t.f_hz[0] < 30][0]
    assert t.trend == "hardening" and t.f_hz[2] == pytest.approx(26.0, rel=2e-3)

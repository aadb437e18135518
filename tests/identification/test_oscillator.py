"""Single-mode polynomial-stiffness oscillator: the integrator and the output-error fit (issue 27 item 5)."""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from satmd.errors import DataError
from satmd.io.shared import real_data
from tests.conftest import needs_real
from satmd.identification.oscillator import fit_oscillator, frf_start, rms_error
from satmd.physics.oscillator import PolynomialOscillator, fine_input

FS = 200.0
W = 2 * np.pi * 20.0
SILVERBOX = real_data("silverbox", "SNLS80mV.mat") or Path("absent")


def duffing(k3=3.0, k2=0.0):
    return PolynomialOscillator(k=W * W, c=2 * 0.05 * W, k2=k2 * W * W, k3=k3 * W * W, gain=W * W)


def test_linear_steady_state_matches_the_frf():
    """A sine through the linear oscillator settles to |G(jω)| = g/|k − mω² + jcω| (exact)."""
    osc = duffing(k3=0.0)
    f = 17.0
    n = 4000
    u = np.sin(2 * np.pi * f * np.arange(n) / FS)
    y = osc.simulate(u, FS, substeps=8, intersample="bandlimited")
    tail = y[-1000:]
    t = np.arange(n)[-1000:] / FS
    basis = np.stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)], axis=1)
    amp = np.hypot(*np.linalg.lstsq(basis, tail, rcond=None)[0])
    w = 2 * np.pi * f
    exact = osc.gain / abs(osc.k - w * w + 1j * osc.c * w)
    assert amp == pytest.approx(exact, rel=2e-5)


def test_rk4_converges_at_fourth_order():
    osc = duffing(k3=5.0, k2=1.0)
    u = np.random.default_rng(1).normal(size=600) * 0.3
    ref = osc.simulate(u, FS, substeps=64)
    e4, e8 = (np.max(np.abs(osc.simulate(u, FS, substeps=s) - ref)) for s in (4, 8))
    assert 12.0 < e4 / e8 < 21.0


def test_segments_side_by_side_equal_the_serial_simulation():
    osc = duffing(k3=3.0)
    u = np.random.default_rng(2).normal(size=3000) * 0.1
    serial = osc.simulate(u, FS)
    # start-up differs only in what the band-limited input does before sample 0; skip the first
    # segment. 900 samples of warm-up forget the start to exp(-ζω·900/fs) ≈ 5e-13
    seg = osc.simulate(u, FS, warmup=900, length=500)
    assert np.max(np.abs(seg[500:] - serial[500:])) < 1e-7 * np.max(np.abs(serial))


@settings(max_examples=20, deadline=None)
@given(delay=st.floats(0.0, 3.0), kind=st.sampled_from(["bandlimited", "zoh", "foh"]))
def test_fine_input_passes_through_the_samples(delay, kind):
    u = np.sin(2 * np.pi * 3 * np.arange(64) / 64)
    fine = fine_input(u, 8, delay=delay, intersample=kind)
    assert fine.shape == (64 * 8 + 1,)
    if delay == 0.0:
        assert np.allclose(fine[:-1:8], u, atol=1e-12)


def test_frf_start_finds_the_resonance():
    osc = duffing(k3=0.0)
    u = np.random.default_rng(3).normal(size=8000)
    s = frf_start(u, osc.simulate(u, FS), FS)
    assert s["wn"] == pytest.approx(W, rel=0.02)
    assert s["gain"] == pytest.approx(1.0, rel=0.05)


def test_fit_recovers_k3_within_its_interval():
    truth = duffing(k3=3.0, k2=0.5)
    rng = np.random.default_rng(4)
    u = rng.normal(size=4000) * 0.1
    y_clean = truth.simulate(u, FS)
    y = y_clean + rng.normal(size=u.size) * 0.01 * np.std(y_clean)
    t0 = time.perf_counter()
    fit = fit_oscillator(u, y, FS, delay=False, substeps=4)
    assert time.perf_counter() - t0 < 20.0
    for name in ("k3", "k2", "k"):
        assert abs(fit.values[name] - getattr(truth, name)) < fit.half_width95[name], name
        lo, hi = fit.ci95[name]  # spelt [lo, hi] as every result's ci95
        assert lo < fit.values[name] < hi and hi - lo == pytest.approx(2 * fit.half_width95[name])
    assert fit.half_width95["k3"] < 0.05 * truth.k3
    assert fit.rms_fit < 0.2 * fit.rms_fit_linear
    d = fit.to_dict()
    assert d["model"]["k3"] == fit.model.k3 and "k3" in fit.report()


def test_bad_records_are_refused():
    with pytest.raises(DataError, match="same length"):
        fit_oscillator(np.zeros(10), np.zeros(11), FS)
    with pytest.raises(DataError, match="NaN"):
        fit_oscillator(np.r_[np.nan, np.zeros(9)], np.zeros(10), FS)
    with pytest.raises(DataError, match="inside the record"):
        fit_oscillator(np.zeros(10), np.zeros(10), FS, ranges=[(5, 20)])


def test_rms_error_in_percent():
    r = rms_error([1.0, 1.0], [2.0, 2.0])
    assert r["rms"] == 1.0 and r["pct"] == 50.0 and r["n"] == 2


@needs_real("silverbox", "SNLS80mV.mat")
def test_silverbox_cubic_model_beats_the_linear_one_on_the_arrow():
    """Fit on part of one multisine realisation; predict the arrow's first (in-range) part."""
    from scipy.io import loadmat

    d = loadmat(SILVERBOX)
    u, y = d["V1"].ravel(), d["V2"].ravel()
    fs = 610.35
    fit = fit_oscillator(u, y, fs, ranges=[(40814, 40814 + 4500)], delay=False, substeps=3, segment=1000,
                         max_nfev=12)
    ua, ya = u[100:12100], y[100:12100]
    lin = rms_error(fit.predict(ua, linear=True), ya, 50)
    nl = rms_error(fit.predict(ua), ya, 50)
    assert nl["pct"] < lin["pct"] / 5
    assert 60.0 < fit.values["natural_frequency_hz"] < 75.0 and fit.values["k3"] > 0

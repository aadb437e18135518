"""Time-domain fit of a nonlinear element with m2, kp, R, L across levels (issue 27 items 1 and 3)."""
from __future__ import annotations

import numpy as np
import pytest

from satmd import simulate
from satmd.errors import DataError
from satmd.identification.nonlinear.fit import fit_nonlinear, predict
from satmd.identification.nonlinear.compare import compare_models
from satmd.io.recording import Recording
from satmd.physics import Rig, nonlinear_element

from satmd.physics.nonlinear import kernel

# time-domain fits and direct-simulation tuning run hundreds of simulations: compiled integrator only
pytestmark = pytest.mark.skipif(not kernel.available, reason="numba not installed (pip install numba)")

TRUE = Rig(m2=0.55, kp=1.2e5, R=30.0, L=0.07)
KW = dict(duration_s=16.0, fs_hz=1024.0, noise=0.01)


def _recs(el, levels, seed=0):
    return [simulate(rig=TRUE, time=True, nonlinear=[el], level=lv, seed=seed + i, **KW) for i, lv in enumerate(levels)]


@pytest.fixture(scope="module")
def cubic():
    el = nonlinear_element("cubic_absorber_spring", k3=2e11)  # kp +~12 % at 10 N
    return el, _recs(el, [1.0, 10.0]), _recs(el, [4.0], seed=10)


def test_cubic_spring_recovered_within_its_interval(cubic):
    el, recs, _ = cubic
    fit = fit_nonlinear(recs, "cubic_absorber_spring", seconds=None)
    lo, hi = fit.ci95["k3"]
    assert abs(fit.values["k3"] / 2e11 - 1) < 0.01 and 0 < hi - lo < 0.02 * 2e11
    assert abs(fit.values["k3"] - 2e11) < 2.0 * (hi - lo)  # within two interval widths (coverage: the benchmark)
    for p in ("m2", "kp", "R", "L"):
        assert abs(fit.values[p] / getattr(TRUE, p) - 1) < 2e-3
    assert all(e["a1"] < 0.013 for e in fit.rel_error_per_level.values())  # down to the 1 % sensor noise
    assert fit.rel_error == pytest.approx(np.sqrt(np.mean([e ** 2 for per in fit.rel_error_per_level.values()
                                                           for e in per.values()])))  # one figure, as FitResult's
    kp_eq = fit.equivalent_linear["kp"]
    assert kp_eq[1] > kp_eq[0] > TRUE.kp  # hardening: kp up with level
    finding = fit.finding()
    assert finding["name"] == "cubic_absorber_spring" and finding["ci95"]["k3"][0] == lo
    assert "hardens" in fit.report()


def test_held_out_level_predicted_much_better_than_linear(cubic):
    el, recs, held = cubic
    out = compare_models(recs, held, "cubic_absorber_spring", seconds=None)
    row = [r for r in out["levels"] if r["held_out"]][0]
    assert row["td_ratio"] > 3.0
    assert row["frf_residual"]["nonlinear"] < 0.5 * row["frf_residual"]["linear"]
    assert out["nonlinear"]["model"] == "cubic_absorber_spring" and out["linear"]["model"] == "linear"


def test_quadratic_damping_recovered():
    el = nonlinear_element("quadratic_damping", c2=40.0)  # cp +~3 N·s/m at 10 N
    fit = fit_nonlinear(_recs(el, [1.0, 10.0], seed=20), "quadratic_damping", seconds=None, start=TRUE)
    lo, hi = fit.ci95["c2"]
    assert lo <= 40.0 <= hi and hi - lo < 20.0
    assert fit.equivalent_linear["cp"][1] > fit.equivalent_linear["cp"][0]


def test_linear_rig_gives_no_cubic_term():
    lin = [simulate(rig=TRUE, time=True, level=lv, seed=30 + i, **KW) for i, lv in enumerate([1.0, 10.0])]
    fit = fit_nonlinear(lin, "cubic_absorber_spring", seconds=None, start=TRUE)
    lo, hi = fit.ci95["k3"]
    assert lo <= 0.0 <= hi or max(abs(lo), abs(hi)) < 2e9  # within noise of zero: < 0.1 % on kp at 10 N
    assert abs(predict(fit, lin[1])["rel_error"]["a1"] - 0.01) < 0.003


def test_bad_input():
    rec = Recording(1000.0, {"force": np.ones(100), "acc1": np.ones(100)})
    with pytest.raises(DataError, match="acc2"):
        fit_nonlinear([rec], "quadratic_damping", start=TRUE)
    with pytest.raises(DataError, match="at least one"):
        fit_nonlinear([], "quadratic_damping")
    with pytest.raises(DataError):
        fit_nonlinear([rec], "bogus", start=TRUE)


def test_inductor_saturation_by_name():
    el = nonlinear_element("inductor_saturation", isat=0.2)  # L -~10 % at 10 N on this rig
    fit = fit_nonlinear(_recs(el, [1.0, 10.0], seed=40), "inductor_saturation", seconds=None, start=TRUE)
    lo, hi = fit.ci95["isat"]
    assert abs(fit.values["isat"] / 0.2 - 1) < 0.05 and lo < hi
    assert fit.equivalent_linear["L"][1] < fit.equivalent_linear["L"][0] < TRUE.L  # L down with level


def test_error_where_the_response_is_excited():
    from satmd.identification.nonlinear.drive import band_error, excited_bins, excited_error

    fs, n = 1024.0, 16384
    rng = np.random.default_rng(5)
    f = np.fft.rfftfreq(n, 1 / fs)
    x = np.fft.rfft(rng.standard_normal(n)) * ((f > 20) & (f < 200))
    h = 1.0 / (1 - (f / 80.0) ** 2 + 2j * 0.02 * f / 80.0)  # a resonance at 80 Hz
    clean = np.fft.irfft(x * h, n)[None]
    noisy = clean + 0.05 * clean.std() * rng.standard_normal(n)
    keep = excited_bins(noisy, fs, (20.0, 200.0))[0]
    assert keep[np.argmin(abs(f - 80.0))] and not keep[np.argmin(abs(f - 190.0))] and not keep[np.argmin(abs(f - 300.0))]
    assert excited_error(noisy, noisy, fs, (20.0, 200.0))[0] == 0.0
    # a perfect model judged on a noisy recording: the excited bins hold less of the noise than the whole band
    on_excited = excited_error(clean, noisy, fs, (20.0, 200.0))[0]
    on_band = band_error(clean, noisy, fs, (20.0, 200.0))[0]
    assert 0 < on_excited < 0.5 * on_band
    # a model off at the resonance is judged there, where it matters: its error is not diluted
    off = np.fft.irfft(x / (1 - (f / 81.0) ** 2 + 2j * 0.02 * f / 81.0), n)[None]
    assert excited_error(off, noisy, fs, (20.0, 200.0))[0] > band_error(off, noisy, fs, (20.0, 200.0))[0]

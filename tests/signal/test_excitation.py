"""The lab's other excitations: periodic forces, impacts and sweeps, detected from the force and estimated."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from satmd.errors import DataError, FormatError
from satmd.io import Recording, load_recording
from satmd.signal import estimate_frf
from satmd.io.shared import real_data
from tests.conftest import needs_real
from satmd.signal.excitation import detect_excitation, find_period
from satmd.physics.timemodel import LinearRig
from satmd.physics import Rig, frf

FS = 1000.0
F16 = real_data("f16") or Path("absent")


def _record(force, noise=0.01, seed=0, fs=FS):
    """Responses of the paper's rig from rest, white noise on every channel (a share of each one's RMS)."""
    rng = np.random.default_rng(seed)
    out = LinearRig(Rig()).respond(force, fs)
    chans = {}
    for name in ("force", "acc1", "acc2"):
        x = out[name]
        chans[name] = x + noise * np.std(x) * rng.standard_normal(x.size)
    return Recording(fs, chans, meta={"source": "test"})


def _multisine(period, periods, lo=20.0, hi=200.0, seed=1, fs=FS):
    rng = np.random.default_rng(seed)
    k = np.arange(period // 2 + 1)
    f = k * fs / period
    spec = np.where((f >= lo) & (f <= hi), np.exp(2j * np.pi * rng.random(k.size)), 0)
    one = np.fft.irfft(spec, period)
    return np.tile(one / np.std(one), periods)


def _hits(times, n, width_s=0.006, fs=FS, heights=None, clip=None):
    x = np.zeros(n)
    w = int(width_s * fs)
    pulse = np.sin(np.pi * np.arange(w) / w)
    for j, t in enumerate(times):
        i = int(t * fs)
        x[i:i + w] += (1.0 if heights is None else heights[j]) * 50.0 * pulse[: max(0, min(w, n - i))]
    if clip is not None:
        x = np.minimum(x, clip)
    return x


def _calibration(data, fs=FS):
    """RMS of (estimate − truth)/std over every point and part (1 for a calibrated std)."""
    truth = frf(data.freq_hz, Rig())
    z = [((data[c] - getattr(truth, c)) / data.std[c]) for c in data.channels]
    z = np.concatenate([np.concatenate([v.real, v.imag]) for v in z])
    return float(np.sqrt(np.mean(z ** 2)))


# --- periodic -------------------------------------------------------------------------------------------
def test_multisine_from_rest_is_detected_and_estimated_at_its_lines():
    rec = _record(_multisine(2000, 8), noise=0.02)
    exc = detect_excitation(rec)
    assert exc.kind == "periodic" and exc.period_samples == 2000 and exc.periods == 8
    assert exc.transient_periods >= 1  # the rig starts at rest
    data = estimate_frf(rec)
    assert data.estimator["method"] == "periodic"
    assert data.estimator["excitation"]["kind"] == "periodic"
    assert data.freq_hz[0] >= 20.0 and data.freq_hz[-1] <= 200.0
    assert np.allclose(np.diff(data.freq_hz), 0.5)  # every line of the design, nothing between them
    assert 0.75 < _calibration(data) < 1.35


def test_two_periods_are_said_to_hide_a_start_up_transient():
    """Two periods of a multisine from rest: both averaged (the first cannot be told from the noise with no third
    to compare), said as a measurement finding and, among levels, as the next experiment."""
    from satmd.discovery.nonlinear.findings import two_periods
    from satmd.signal.excitation import received
    from satmd.signal.periodic import excitation_findings

    two, five = (received(_record(_multisine(2000, n), noise=0.02)) for n in (2, 5))
    exc = detect_excitation(two)
    assert exc.kind == "periodic" and exc.periods == 2 and exc.transient_periods == 0
    assert [f.name for f in excitation_findings(exc)] == ["two_periods"]
    assert "two_periods" not in [f.name for f in excitation_findings(detect_excitation(five))]
    assert two_periods([five, two]) == ["test"]


def test_pseudo_random_and_a_given_period_agree():
    rng = np.random.default_rng(4)
    one = rng.standard_normal(1000)
    spec = np.fft.rfft(one)
    f = np.fft.rfftfreq(1000, 1 / FS)
    spec[(f < 15) | (f > 250)] = 0
    force = np.tile(np.fft.irfft(spec, 1000), 10)
    rec = _record(force, noise=0.01, seed=3)
    auto = estimate_frf(rec)
    given = estimate_frf(rec, excitation="periodic", period_s=1.0)
    assert auto.estimator["excitation"]["source"] == "detected"
    assert given.estimator["excitation"]["source"] == "given"
    assert np.allclose(auto["a1"], given["a1"])
    assert 0.75 < _calibration(auto) < 1.35


def test_a_glitch_is_left_out_and_said():
    force = _multisine(1000, 10, seed=2)
    force[5300:5340] += 8.0  # a burst in period 6
    rec = _record(force, noise=0.01)
    exc = detect_excitation(rec)
    assert exc.kind == "periodic" and 5 not in exc.steady
    data = estimate_frf(rec)
    assert "glitch" in [m["name"] for m in data.estimator["measurement"]]
    assert 0.7 < _calibration(data) < 1.4


def test_a_partial_last_period_and_a_drifting_period():
    force = _multisine(1000, 6, seed=5)
    exc = detect_excitation(_record(force[:5600]))
    assert exc.kind == "periodic" and exc.periods == 5
    t = np.arange(12000) / FS
    drift = np.sin(2 * np.pi * 37.0 * t * (1 + 0.02 * t))  # a tone whose period drifts: not periodic
    assert detect_excitation(_record(drift + np.random.default_rng(1).standard_normal(t.size))).kind != "periodic"


def test_random_force_is_not_periodic():
    rng = np.random.default_rng(0)
    rec = _record(rng.standard_normal(20000))
    assert detect_excitation(rec).kind == "random"
    assert find_period(rng.standard_normal(20000))[0] == 0


def test_a_given_period_that_does_not_fit_is_refused():
    rec = _record(_multisine(1000, 4))
    with pytest.raises(DataError, match="whole number of samples"):
        detect_excitation(rec, period_s=1.0005)
    with pytest.raises(DataError, match="does not repeat"):
        detect_excitation(rec, period_s=0.7)
    with pytest.raises(DataError, match="not one of"):
        detect_excitation(rec, kind="chirpy")


def test_linear_rig_under_a_multisine_is_linear_with_no_physics():
    from satmd import discover

    rep = discover(_record(_multisine(2000, 8), noise=0.02, seed=7))
    assert rep.model_adequate
    assert rep.effect_names == []
    assert rep.nonlinear is not None and not rep.nonlinear.detected
    assert rep.to_dict()["estimator"]["excitation"]["kind"] == "periodic"



def test_a_periodic_chirps_weak_tails_are_not_detection_lines():
    """A linear chirp repeated from rest: its spectrum leaks, weakly on every line, far above the band. The
    rig answers there; that answer is no distortion (the old rule, force over 10x its noise line by line,
    flagged the third of these seeds at p ~ 1e-15)."""
    from scipy.signal import chirp

    from satmd import discover
    from satmd.discovery.nonlinear.distortion import multisine_test
    from satmd.signal.periodic import multisine_arrays
    from satmd.discovery.nonlinear.periodic import forced_lines
    from satmd.signal.excitation import with_excitation

    fs = 2000.0
    t = np.arange(2000) / fs
    out = LinearRig(Rig()).respond(np.tile(chirp(t, 13.0, 1.0, 435.0), 16), fs)
    for seed in range(4):
        rng = np.random.default_rng(seed)
        share = {"force": 0.02, "acc1": 0.002, "acc2": 0.002}  # a noisier force than responses
        noisy = {c: x + share[c] * np.std(x) * rng.standard_normal(x.size) for c, x in out.items()}
        rec = Recording(fs, noisy, meta={"source": "test"})
        rec = with_excitation(rec, detect_excitation(rec))
        u, _, lines = multisine_arrays(rec)
        assert forced_lines(u, lines=lines).max() > lines.max() + 20  # the tail is force, if weak
        test = multisine_test(rec)
        assert not test.significant, (seed, test.report())
        if test.not_run:
            assert test.to_dict()["p_value"] is None and "not run" in test.report()
    rep = discover(rec)
    assert rep.effect_names == [] and not rep.nonlinear.detected

# --- impacts --------------------------------------------------------------------------------------------
def test_hits_are_segmented_and_h1_is_calibrated():
    n = int(20 * FS)
    times = [0.5, 3.6, 6.8, 10.1, 13.2, 16.4]
    rec = _record(_hits(times, n, heights=[1, 0.8, 1.2, 0.9, 1.1, 1.0]), noise=0.01, seed=2)
    exc = detect_excitation(rec)
    assert exc.kind == "impact" and len(exc.hits) == 6 and not exc.dropped
    data = estimate_frf(rec)
    assert data.estimator["method"] == "impact"
    assert data.freq_hz[0] < 25 and data.freq_hz[-1] > 200
    assert 0.7 < _calibration(data) < 1.4


def test_double_clipped_and_late_hits_are_dropped_with_their_reason():
    n = int(20 * FS)
    rec = _record(_hits([0.5, 3.6, 3.62, 6.8, 10.1, 13.2, 19.5], n), noise=0.005)
    force = rec["force"].copy()
    hit = slice(int(10.0 * FS), int(10.3 * FS))
    force[hit] = np.minimum(force[hit], 0.3 * force[hit].max())  # the ADC clips this hit's top
    rec = Recording(FS, dict(rec.channels, force=force), meta=rec.meta)
    exc = detect_excitation(rec)
    reasons = " ".join(r for _, r in exc.dropped)
    assert exc.kind == "impact" and len(exc.hits) == 3
    assert "double hit" in reasons and "clipped" in reasons and "record's end" in reasons
    data = estimate_frf(rec)
    names = {m["name"] for m in data.estimator["measurement"]}
    assert {"double_hit", "clipped_hit", "truncated_hit"} <= names


def test_linear_rig_under_hits_is_not_called_nonlinear():
    from satmd import discover

    n = int(24 * FS)
    rec = _record(_hits([0.5 + 3.9 * j for j in range(6)], n), noise=0.01, seed=9)
    rep = discover(rec)
    assert rep.model_adequate
    assert rep.effect_names == []
    assert rep.nonlinear is None or not rep.nonlinear.detected


# --- sweeps ---------------------------------------------------------------------------------------------
def test_a_fast_sweep_at_rest_at_both_ends_is_estimated_without_leakage():
    from scipy.signal import chirp

    from satmd import discover

    t = np.arange(int(4 * FS)) / FS
    force = np.where(t < 2.0, chirp(t, 15.0, 2.0, 250.0), 0.0) * np.sin(np.pi * np.clip(t / 2.0, 0, 1)) ** 0.1
    rec = _record(np.concatenate([force, np.zeros(int(4 * FS))]), noise=0.01, seed=5)
    data = estimate_frf(rec)
    assert data.estimator["method"] == "sweep" and data.estimator["excitation"]["kind"] == "sweep"
    assert 0.8 < _calibration(data) < 1.25  # ~90 Hz/s through resonances a few Hz wide: no smearing
    rep = discover(rec)
    assert rep.effect_names == [] and not rep.nonlinear.detected  # no distortion test for a sweep: it says so
    assert "sweep" in rep.nonlinear.tests[0].not_run


def test_a_log_sweep_is_recognised_with_its_law():
    from satmd.simulation.timesim import log_sweep

    rec = _record(log_sweep(int(40 * FS), FS, 15.0, 250.0), noise=0.01)
    exc = detect_excitation(rec)
    assert exc.kind == "sweep"
    assert exc.sweep["law"] == "logarithmic" and exc.sweep["direction"] == "up"
    assert 12 < exc.sweep["f_start_hz"] < 25 and 200 < exc.sweep["f_end_hz"] < 300
    data = estimate_frf(rec)  # tapered to rest over its last 2 s: the record holds whole transients
    assert data.estimator["method"] == "sweep" and 0.8 < _calibration(data) < 1.25
    cut = Recording(FS, {c: rec[c][: int(30 * FS)] for c in rec.channels})  # stopped mid-sweep, still ringing
    data = estimate_frf(cut)
    assert data.estimator["method"] == "lpm" and data.estimator["excitation"]["kind"] == "sweep"


# --- files as labs write them -----------------------------------------------------------------------------
def test_mat_with_lab_names_and_rows(tmp_path):
    from scipy.io import savemat

    rec = _record(_multisine(1000, 4))
    path = tmp_path / "lab.mat"
    savemat(path, {"Force": rec["force"][None], "Acc": np.stack([rec["acc2"], rec["acc1"]]), "Fs": FS})
    got = load_recording(path, channel_map="force=Force,a1=Acc[2],a2=Acc[1]")
    assert np.allclose(got["acc1"], rec["acc1"]) and got.fs_hz == FS
    unmapped = load_recording(path)  # a force and one matrix of accelerations: its rows in order
    assert np.array_equal(unmapped["acc1"], rec["acc2"]) and np.array_equal(unmapped["acc2"], rec["acc1"])
    with pytest.raises(FormatError, match="rows 1..2"):
        load_recording(path, channel_map="force=Force,a1=Acc[3]")
    with pytest.raises(FormatError, match="no variable 'Missing'"):
        load_recording(path, channel_map="force=Missing,a1=Acc[1]")
    savemat(tmp_path / "nofs.mat", {"force": rec["force"], "acc1": rec["acc1"]})
    with pytest.raises(FormatError, match="sample rate"):
        load_recording(tmp_path / "nofs.mat")
    assert load_recording(tmp_path / "nofs.mat", fs_hz=FS).fs_hz == FS


@needs_real("f16")
def test_f16_reads_as_it_is_and_equals_the_periodic_estimate():
    path = F16 / "F16Data_FullMSine_Level1.mat"
    rec = load_recording(path, channel_map="force=Force,a1=Acceleration[2],a2=Acceleration[3]")
    data = estimate_frf(rec)
    ex = data.estimator["excitation"]
    assert ex["kind"] == "periodic" and abs(ex["period_s"] - 20.48) < 1e-9 and ex["periods"] == 9
    # the textbook estimate: periods 2-9 averaged, the FFT at the excited lines
    u = rec["force"].reshape(9, 8192)[1:].mean(axis=0)
    y = rec["acc1"].reshape(9, 8192)[1:].mean(axis=0)
    lines = np.round(data.freq_hz * 8192 / 400.0).astype(int)
    textbook = np.fft.rfft(y)[lines] / np.fft.rfft(u)[lines]
    z = (data["a1"] - textbook) / data.std["a1"]
    assert np.sqrt(np.mean(np.abs(z) ** 2) / 2) < 1.5
    mag = np.abs(data["a1"])
    assert abs(data.freq_hz[np.argmax(mag * (data.freq_hz > 6) * (data.freq_hz < 8))] - 7.32) < 0.1
    assert np.corrcoef(mag[1:], mag[:-1])[0, 1] > 0.8  # smooth, not noise-like


def test_one_hit_per_file_is_one_test_of_repeats():
    from satmd import discover

    n = int(6 * FS)
    recs = [_record(_hits([0.6], n, heights=[h]), noise=0.01, seed=s) for s, h in enumerate((1.0, 0.7, 1.3, 0.9))]
    rep = discover(recs)
    ex = rep.to_dict()["estimator"]["excitation"]
    assert ex["kind"] == "impact" and ex["hits"] == 4
    assert rep.model_adequate and rep.effect_names == []
    assert rep.nonlinear is None or not rep.nonlinear.detected


def test_an_exponential_window_is_modelled_exactly_and_not_taken_for_damping():
    """Files cut while the rig still rings: the window e^(-t/τ) makes the estimate H(iω + 1/τ) exactly; the
    fit evaluates its model there, so the nominal rig fits (no damping, no physics) and its std is calibrated."""
    from satmd import discover
    from satmd.identification import identify

    n = int(0.7 * FS)  # the rig rings for seconds: half a second after the hit is cut mid-ring
    recs = [_record(_hits([0.2], n, heights=[h]), noise=0.005, seed=s) for s, h in enumerate((1.0, 0.8, 1.2, 0.9, 1.1))]
    data = estimate_frf(recs[0])  # one file alone
    tau = data.estimator["window_decay_s"]
    assert "exponential_window" in [m["name"] for m in data.estimator["measurement"]]
    exact = frf(data.freq_hz - 1j / (2 * np.pi * tau), Rig())  # the model at s = iω + 1/τ
    z = np.concatenate([((data[c] - exact.channel(c)) / data.std[c]) for c in data.channels])
    assert 0.7 < np.sqrt(np.mean(np.abs(z) ** 2) / 2) < 1.4
    assert identify(data).model_adequate
    rep = discover(recs)
    assert rep.effect_names == [] and rep.model_adequate

def test_csv_as_a_lab_writes_it(tmp_path):
    rec = _record(_multisine(1000, 4))
    t = np.arange(rec.n_samples) / FS * 1e3
    rows = np.column_stack([t, rec["force"] / 1e3, rec["acc2"] / 9.80665, rec["acc1"] / 9.80665])
    path = tmp_path / "lab.csv"
    np.savetxt(path, rows, delimiter=",", header="Time (ms),Force [kN],Acc payload [g],Acc wing [g]", comments="")
    from satmd.io import is_recording

    assert is_recording(path)
    with pytest.raises(FormatError, match="channel map"):
        load_recording(path)
    got = load_recording(path, channel_map="force=Force,a1=Acc wing,a2=Acc payload")
    assert got.fs_hz == FS and np.allclose(got["acc1"], rec["acc1"], rtol=1e-6, atol=1e-9)
    assert np.allclose(got["force"], rec["force"], rtol=1e-6, atol=1e-9)
    with pytest.raises(FormatError, match="no column 'Acc tail'"):
        load_recording(path, channel_map="force=Force,a1=Acc tail")
    named = tmp_path / "named.csv"
    np.savetxt(named, rows[:, :3], delimiter=",", header="t (ms),FORCE (N),acc1", comments="")
    assert set(load_recording(named).channels) == {"force", "acc1"}


def test_periodic_realisations_give_the_best_linear_approximation():
    from satmd import discover

    recs = [_record(_multisine(1000, 6, seed=20 + j), noise=0.02, seed=j) for j in range(4)]
    rep = discover(recs)
    est = rep.to_dict()["estimator"]
    assert est["method"] == "periodic" and est["realisations"] == 4
    assert rep.model_adequate and rep.effect_names == []
    assert not rep.nonlinear.detected

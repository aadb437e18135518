"""Recordings: files, time simulation, FRF estimation with an honest noise model, transmissibility."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from satmd.errors import DataError, FormatError
from satmd.io import DataWarning, Recording, load_recording, save_recording
from satmd.signal import default_nperseg, estimate_frf, model_transmissibility, transmissibility
from satmd.simulation import simulate_recording
from satmd.physics import Rig, effect, frf


@pytest.fixture(scope="module")
def rec():
    return simulate_recording(20.0, 500.0, noise=0.02, seed=7)


# --- the Recording object ---------------------------------------------------------
def test_recording_validates_its_channels():
    with pytest.raises(DataError, match="different lengths"):
        Recording(100.0, {"force": np.zeros(10), "acc1": np.zeros(9)})
    with pytest.raises(DataError, match="NaN .* sample 3"):
        Recording(100.0, {"acc1": np.array([0.0, 1.0, 2.0, np.nan])})
    with pytest.raises(DataError, match="sample rate"):
        Recording(0.0, {"acc1": np.zeros(4)})
    with pytest.raises(DataError, match="at least 2 samples"):
        Recording(10.0, {"acc1": np.zeros(1)})
    r = Recording(10.0, {"acc1": np.zeros(25)})
    assert (r.n_samples, r.duration_s, r.has_force) == (25, 2.5, False)


# --- files --------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".csv", ".uff", ".wav", ".npz", ".mat"])
def test_round_trip_every_format(tmp_path, rec, suffix):
    short = Recording(rec.fs_hz, {k: v[:600] for k, v in rec.channels.items()})
    back = load_recording(save_recording(short, tmp_path / f"rec{suffix}"))
    assert back.fs_hz == short.fs_hz and list(back.channels) == ["force", "acc1", "acc2"]
    for name, v in short.channels.items():
        np.testing.assert_array_equal(back[name], v)  # doubles everywhere: exact
    assert back.units["acc1"] == "m/s^2" and back.units["force"] == "N"


def test_uff_ascii_time_records(tmp_path, rec):
    from satmd.io.recording import write_recording_uff

    short = Recording(rec.fs_hz, {k: v[:100] for k, v in rec.channels.items()})
    back = load_recording(write_recording_uff(short, tmp_path / "rec.unv", binary=False))
    assert back.fs_hz == 500.0
    np.testing.assert_allclose(back["acc2"], short["acc2"], rtol=1e-11, atol=1e-11 * np.abs(short["acc2"]).max())


def test_csv_errors_name_line_and_column(tmp_path):
    p = tmp_path / "r.csv"
    cases = {
        "time_s,force,acc1\n0,1,2\n0.01,1,2\n0.03,1,2\n0.04,1,2\n": "line 4, column 1 .*non-uniform sampling",
        "time_s,force,acc0\n0,1,2\n": "unknown column 'acc0'",  # acc9 is a role now; acc0 is not
        "time_s,force,acc1\n0,1,2\n0.01,1\n": "line 3: 2 fields",
        "time_s,force,acc1\n0,1,2\n0.01,nan,2\n": "line 3, column 2 \\(force\\)",
        "force,acc1\n1,2\n": "first column must be time_s",
        "time_s,acc1\n0,1\n": "1 data row",
        "": "empty file",
    }
    for text, match in cases.items():
        p.write_text(text)
        with pytest.raises(FormatError, match=match):
            load_recording(p)
    p.write_bytes(b"\x00\x01\x02garbage\xff")
    with pytest.raises(FormatError, match="not a text file"):
        load_recording(p)


def test_output_only_csv_and_clipping_warning(tmp_path):
    t = np.arange(2000) / 1000.0
    acc1 = np.clip(3 * np.sin(2 * np.pi * 31 * t), -2.0, 2.0)  # a saturated sensor
    p = tmp_path / "oo.csv"
    p.write_text("time_s,acc1,acc2\n" + "".join(f"{a:.6f},{b:.17g},{c:.17g}\n" for a, b, c in zip(t, acc1, np.cos(t))))
    with pytest.warns(DataWarning, match="acc1 looks clipped"):
        r = load_recording(p)
    assert not r.has_force and r.fs_hz == 1000.0
    p.write_text("time_s,acc1,acc2\n" + "".join(f"{a:.6f},{b:.17g},0\n" for a, b in zip(t, np.cos(t))))
    with pytest.warns(DataWarning, match="channel acc2 is constant .0 throughout.: a sensor that recorded nothing"):
        load_recording(p)  # a dead sensor, said
    with pytest.raises(DataError, match="no force channel"):
        estimate_frf(r)


def test_wav_int16_scale_units_and_clipping(tmp_path):
    from scipy.io import wavfile

    t = np.arange(4000) / 2000.0
    x = np.column_stack([np.sin(2 * np.pi * 40 * t), 1.5 * np.sin(2 * np.pi * 50 * t), np.cos(9 * t)])
    pcm = (np.clip(x, -1, 1) * 32767).astype(np.int16)  # channel 2 saturates
    p = tmp_path / "r.wav"
    wavfile.write(p, 2000, pcm)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = load_recording(p)
    text = " ".join(str(w.message) for w in caught)
    assert "carry no units" in text and "acc1 looks clipped" in text and "force looks clipped" not in text
    assert r.units["force"] == "full scale"
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataWarning)
        with pytest.raises(DataWarning, match="clipped"):
            load_recording(p, scale={"force": 10.0, "acc1": 9.81, "acc2": 9.81})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataWarning)
        r = load_recording(p, scale={"force": 10.0, "acc1": 9.81, "acc2": 9.81})
        swapped = load_recording(p, channel_map="force=#3,a1=#1,a2=#2")
    assert r.units["force"] == "N"
    np.testing.assert_allclose(r["force"], pcm[:, 0] / 32768 * 10.0)
    np.testing.assert_array_equal(swapped["force"], pcm[:, 2] / 32768)
    with pytest.raises(FormatError, match="#1..#3"):
        load_recording(p, channel_map="force=1:3")


def test_uff_time_records_from_other_software(tmp_path):
    pyuff = pytest.importorskip("pyuff")
    t = np.arange(256) / 256.0
    force, a1, a2 = np.sin(20 * t), np.cos(30 * t), np.sin(40 * t) + 0.1

    def rec58(data, node, spec, unit, name):
        return pyuff.prepare_58(binary=1, func_type=1, rsp_node=node, rsp_dir=3, ref_node=0, ref_dir=0, data=data,
                                x=t, id1=name, abscissa_spacing=1, abscissa_spec_data_type=17,
                                ordinate_spec_data_type=spec, orddenom_spec_data_type=0,
                                ordinate_axis_units_lab=unit, abscissa_axis_units_lab="s")

    p = tmp_path / "daq.uff"
    pyuff.UFF(str(p)).write_sets([rec58(a1 / 9.80665, 1, 12, "g", "acc"), rec58(force / 1e3, 1, 13, "kN", "hammer"),
                                  rec58(a2, 2, 12, "m/s^2", "acc")], mode="add")
    r = load_recording(p)
    assert list(r.channels) == ["acc1", "force", "acc2"] and r.fs_hz == 256.0
    np.testing.assert_allclose(r["acc1"], a1, rtol=1e-12)
    np.testing.assert_allclose(r["force"], force, rtol=1e-12)
    r = load_recording(p, channel_map="a1=2:3,a2=#1,force=#2")
    np.testing.assert_allclose(r["acc2"], a1, rtol=1e-12)
    with pytest.raises(FormatError, match="2 time records match"):
        load_recording(p, channel_map="a1=1:3")
    # records of different lengths or rates cannot form one recording
    p2 = tmp_path / "mixed.uff"
    other = pyuff.prepare_58(binary=0, func_type=1, rsp_node=3, rsp_dir=3, ref_node=0, ref_dir=0, data=a2[:100],
                             x=t[:100], id1="x", abscissa_spacing=1, abscissa_spec_data_type=17,
                             ordinate_spec_data_type=12, orddenom_spec_data_type=0)
    pyuff.UFF(str(p2)).write_sets([rec58(a1, 1, 12, "m/s^2", "a"), other], mode="add")
    with pytest.raises(FormatError, match="dataset 2 has 100 samples, dataset 1 has 256"):
        load_recording(p2)


def test_uff_recording_mapped_to_a_pressure_is_refused(tmp_path):
    pyuff = pytest.importorskip("pyuff")
    t = np.arange(64) / 64.0
    p = tmp_path / "mic.uff"
    pyuff.UFF(str(p)).write_sets([pyuff.prepare_58(
        binary=0, func_type=1, rsp_node=0, rsp_dir=1, ref_node=0, ref_dir=0, data=np.sin(t), x=t, id1="mic",
        abscissa_spacing=1, abscissa_spec_data_type=17, ordinate_spec_data_type=15, orddenom_spec_data_type=0,
        ordinate_axis_units_lab="m/s", abscissa_axis_units_lab="s")], mode="add")
    assert list(load_recording(p).channels) == ["ch1"]
    with pytest.raises(FormatError, match="not an acceleration"):
        load_recording(p, channel_map="a1=#1")


# --- time simulation --------------------------------------------------------------
def test_simulation_is_seeded_band_limited_and_scaled():
    a = simulate_recording(4.0, 400.0, seed=1, band_hz=(30, 90), force_rms=2.0, excitation="multisine", ideal=True)
    b = simulate_recording(4.0, 400.0, seed=1, band_hz=(30, 90), force_rms=2.0, excitation="multisine", ideal=True)
    np.testing.assert_array_equal(a["acc2"], b["acc2"])
    assert np.sqrt(np.mean(a["force"] ** 2)) == pytest.approx(2.0)
    spec = np.abs(np.fft.rfft(a["force"]))
    f = np.fft.rfftfreq(a.n_samples, 1 / 400.0)
    assert spec[(f < 29) | (f > 91)].max() < 1e-9 * spec.max()  # periodic: no leakage at all


def test_default_recording_is_random_not_periodic_and_starts_at_rest():
    r = simulate_recording(20.0, 2000.0, seed=3)  # the defaults are the lab's: noise on every channel
    assert r.meta["excitation"] == "random" and r.meta["conditions"] == "lab"
    assert float(r.meta["noise"]) == pytest.approx(0.02) and float(r.meta["force_noise"]) == pytest.approx(0.01)
    lab_clean = simulate_recording(20.0, 2000.0, seed=3, noise=0.0, force_noise=0.0)
    assert np.std(r["acc1"] - lab_clean["acc1"]) == pytest.approx(0.02 * np.std(lab_clean["acc1"]), rel=0.1)
    # the shaker rolls the force off above the band (20-200 Hz): some force at 300 Hz, far less than in the band
    spec = np.abs(np.fft.rfft(lab_clean["force"])) ** 2
    f = np.fft.rfftfreq(lab_clean.n_samples, 1 / 2000.0)
    ratio = spec[(f > 280) & (f < 320)].mean() / spec[(f > 50) & (f < 150)].mean()
    assert 1e-4 < ratio < 0.3
    clean = simulate_recording(20.0, 2000.0, seed=3, ideal=True)
    assert clean.meta["conditions"] == "ideal" and float(clean.meta["noise"]) == 0.0
    r = simulate_recording(20.0, 2000.0, seed=3, ideal=True, noise=0.02)
    # at rest at t = 0: the absorber (no direct path from the force) starts from nothing
    assert abs(clean["acc2"][0]) < 0.02 * np.std(clean["acc2"])
    # not periodic in the record: the force's first and last samples do not join up
    spec = np.abs(np.fft.rfft(clean["force"]))
    f = np.fft.rfftfreq(clean.n_samples, 1 / 2000.0)
    leak = spec[(f > 5) & (f < 15)].max() / spec.max()
    assert 1e-6 < leak < 0.05
    # noise on every channel: the noisy force differs from the clean one by ~1 % of its RMS
    d = r["force"] - clean["force"]
    assert np.std(d) == pytest.approx(0.01 * np.sqrt(np.mean(clean["force"] ** 2)), rel=0.1)


def test_convolution_from_rest_reaches_the_exact_steady_state():
    """A periodic force repeated: once the transient has died, the response equals the exact steady state."""
    from satmd.simulation.timesim import _steady_state_multisine
    from satmd.physics.timemodel import LinearRig

    rng = np.random.default_rng(0)
    n, fs = 4000, 1000.0
    steady = _steady_state_multisine(n, fs, Rig(), (), 20.0, 200.0, rng)
    out = LinearRig(Rig(), (), 200.0).respond(np.tile(steady["force"], 5), fs)
    for name in ("acc1", "acc2"):
        err = np.abs(out[name][3 * n:4 * n] - steady[name]).max() / np.abs(steady[name]).max()
        assert err < 1e-9, name


@pytest.mark.parametrize("excitation", ["random", "sweep", "multisine"])
def test_lpm_recovers_the_model_at_full_resolution(excitation):
    """Noise-free: the LPM estimate equals the model to well below any realistic noise, peaks included (a sweep
    that has rung down by the record's end is one whole transient: its estimate is held to the same bound)."""
    rig = Rig(R=30.0)
    effects = [effect("time_delay", tau_s=2e-4)]
    r = simulate_recording(40.0, 1000.0, rig, effects, seed=2, band_hz=(20, 250), excitation=excitation, ideal=True)
    d = estimate_frf(r, band_hz=(40, 200))
    assert d.estimator["method"] == ("sweep" if excitation == "sweep" else "lpm")
    assert d.freq_hz[0] >= 40 and d.freq_hz[-1] <= 200
    model = frf(d.freq_hz, rig, effects, outputs=("a1", "a2"))
    for ch in ("a1", "a2"):
        err = np.abs(d[ch] - model.channel(ch)) / np.abs(model.channel(ch))
        assert np.max(err) < 3e-3, ch


def test_lpm_std_is_honest_with_noise_on_every_channel():
    """Standardised errors of the LPM estimate have unit variance with force and response noise."""
    z = []
    for seed in range(3):
        r = simulate_recording(60.0, 1000.0, noise=0.03, force_noise=0.02, seed=seed)
        d = estimate_frf(r)
        model = frf(d.freq_hz, outputs=("a1", "a2"))
        for ch in ("a1", "a2"):
            e = (d[ch] - model.channel(ch)) / d.std[ch]
            z += [e.real, e.imag]
    z = np.concatenate(z)
    assert 0.9 < z.var() < 1.1
    assert abs(z.mean()) < 0.05
    assert d.estimator["noise_dof"] > 100


def test_lpm_finds_the_excited_band_and_says_so():
    r = simulate_recording(30.0, 1000.0, noise=0.02, seed=1, band_hz=(30, 150), ideal=True)  # sharp band edges
    d = estimate_frf(r, band_hz=(10, 400))
    assert 30 <= d.freq_hz[0] < 31 and 149 < d.freq_hz[-1] <= 150
    names = [m["name"] for m in d.estimator["measurement"]]
    assert "unexcited_band" in names


def test_welch_resolution_bias_is_named_as_a_measurement_finding():
    r = simulate_recording(120.0, 1000.0, noise=0.02, seed=1, ideal=True)
    d = estimate_frf(r, nperseg=1024, band_hz=(30, 150))
    assert "resolution_bias" in [m["name"] for m in d.estimator["measurement"]]
    assert not estimate_frf(r, band_hz=(30, 150)).estimator["measurement"]
    with pytest.raises(DataError, match="inside"):
        simulate_recording(1.0, 100.0, band_hz=(10, 60))


def test_noise_free_estimate_matches_the_model_in_phase_and_magnitude():
    """Guards the classic sign error (conjugated FRFs): the estimate must equal the analytic model."""
    rig = Rig(R=30.0)
    effects = [effect("time_delay", tau_s=2e-4)]
    r = simulate_recording(10.0, 1000.0, rig, effects, seed=2, band_hz=(20, 250), ideal=True)
    d = estimate_frf(r, nperseg=2048, band_hz=(40, 200))
    model = frf(d.freq_hz, rig, effects, outputs=("a1", "a2"))
    for ch in ("a1", "a2"):  # what is left is the window's resolution bias at the peaks
        err = np.abs(d[ch] - model.channel(ch)) / np.abs(model.channel(ch))
        assert np.median(err) < 5e-3, ch
        # the phase itself, where a conjugation error would flip its sign (errors of radians)
        dphi = np.angle(d[ch] / model.channel(ch))
        assert np.median(np.abs(dphi)) < 5e-3


def test_phase_sign_of_a_pure_delay():
    """acc1(t) = force(t - τ): H = exp(-iωτ) in the e^{+iωt} convention, so the phase falls with f."""
    rng = np.random.default_rng(0)
    x = rng.standard_normal(20000)
    shift = 3
    r = Recording(1000.0, {"force": x, "acc1": np.roll(x, shift)})
    d = estimate_frf(r, nperseg=256, band_hz=(10, 100))
    expected = np.exp(-2j * np.pi * d.freq_hz * shift / 1000.0)
    np.testing.assert_allclose(d["a1"], expected, atol=0.02)
    assert np.all(np.angle(d["a1"]) < 0)


def test_coherence_based_std_is_honest():
    """Standardised errors (estimate - model) / std have unit variance (Bendat & Piersol)."""
    z = []
    for seed in range(4):
        r = simulate_recording(20.0, 500.0, noise=0.05, seed=seed)
        d = estimate_frf(r, nperseg=1024, band_hz=(35, 140))
        model = frf(d.freq_hz, outputs=("a1", "a2"))
        for ch in ("a1", "a2"):
            e = (d[ch] - model.channel(ch)) / d.std[ch]
            z += [e.real, e.imag]
    z = np.concatenate(z)
    assert 0.8 < z.var() < 1.3
    assert abs(z.mean()) < 0.1
    assert 0.0 <= d.coherence["a1"].min() and d.coherence["a1"].max() <= 1.0


def test_h2_is_unbiased_with_noise_on_the_force():
    r = simulate_recording(20.0, 500.0, seed=4)
    rng = np.random.default_rng(1)
    noisy = Recording(r.fs_hz, {**r.channels, "force": r["force"] + 0.5 * rng.standard_normal(r.n_samples)})
    band = (60, 90)  # away from the peaks: resolution bias is negligible, noise bias is not
    h1, h2 = (estimate_frf(noisy, nperseg=1024, band_hz=band, estimator=e) for e in ("H1", "H2"))
    model = np.abs(frf(h1.freq_hz, outputs=("a2",)).a2)
    assert np.median(np.abs(h1["a2"]) / model) < 0.9  # H1 biased low by 1/(1 + noise/force)
    assert np.median(np.abs(h2["a2"]) / model) == pytest.approx(1.0, abs=0.02)


def test_estimate_frf_option_errors(rec):
    with pytest.raises(DataError, match="nperseg"):
        estimate_frf(rec, nperseg=10**7)
    with pytest.raises(DataError, match="at least 2 averages"):
        estimate_frf(rec, nperseg=rec.n_samples)
    with pytest.raises(DataError, match="estimator"):
        estimate_frf(rec, estimator="H3")
    with pytest.raises(DataError, match="overlap"):
        estimate_frf(rec, overlap=1.0)
    with pytest.raises(DataError, match="window"):
        estimate_frf(rec, window="no-such-window")
    with pytest.raises(DataError, match="holds no frequency bin"):
        estimate_frf(rec, band_hz=(300, 400))


def test_default_nperseg():
    assert default_nperseg(1000.0, 60000) == 2048
    assert default_nperseg(3200.0, 222400) == 8192
    assert default_nperseg(500.0, 3000) == 256  # shortened for 16 averages


def test_transmissibility_matches_the_model(rec):
    oo = Recording(rec.fs_hz, {"acc1": rec["acc1"], "acc2": rec["acc2"]})
    t = transmissibility(oo, nperseg=1024, band_hz=(40, 130))
    model = model_transmissibility(t.freq_hz)
    assert np.median(np.abs(t.value - model) / np.abs(model)) < 0.02
    np.testing.assert_allclose(t.model(), model)
    assert t.coherence.shape == t.value.shape and np.all(t.std > 0)


def test_recording_to_identification_end_to_end(rec):
    """The chain recording -> FRF -> identify recovers the rig with an honest χ²."""
    identify = pytest.importorskip("satmd.identification").identify
    d = estimate_frf(rec, band_hz=(30, 150))
    fit = identify(d)
    true = Rig()
    for name in ("m2", "kp", "R", "L"):
        assert fit.values[name] == pytest.approx(getattr(true, name), rel=0.01), name
    assert 0.7 <= fit.chi2_reduced <= 1.5

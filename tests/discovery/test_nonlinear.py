"""Nonlinear detection, location and naming (issue 26): fast checks on short records and exact FRFs."""
from __future__ import annotations

import numpy as np
import pytest

from satmd import simulate
from satmd.conventions import ACCEL_CHANNELS
from satmd.discovery.nonlinear.distortion import NonlinearReport, distortion_test
from satmd.discovery.nonlinear.findings import analyse_frfs, analyse_recordings
from satmd.discovery.nonlinear.naming import element_for
from satmd.discovery.nonlinear.periodic import detection_lines_test, one_mode_fit
from satmd.signal.periodic import multisine_bla
from satmd.discovery.nonlinear.stats import band_scan, distortion_regressors, level_dependence, linearity_test
from satmd.physics import Rig
from satmd.physics.nonlinear import element


def _filtered_noise(n, rng, lo=0.05, hi=0.3):
    X = np.fft.rfft(rng.standard_normal(2 * n))
    f = np.fft.rfftfreq(2 * n)
    X[(f < lo) | (f > hi)] = 0
    return np.fft.irfft(X, 2 * n)[:n]


def _resonator(x, f0=0.12, zeta=0.03):
    """A lightly damped second-order filter (a one-mode 'structure', normalised frequency)."""
    from scipy.signal import lfilter

    w = 2 * np.pi * f0
    r = np.exp(-zeta * w)
    return lfilter([1.0], [1.0, -2 * r * np.cos(w), r * r], x)


@pytest.mark.parametrize("shape", ["square", "cube", "absv", "sign"])
def test_regressors_are_uncorrelated_with_the_signal(shape):
    rng = np.random.default_rng(0)
    s = rng.standard_normal(4000)
    z = distortion_regressors({"s": s}, (shape,))[f"s:{shape}"]
    assert abs(np.dot(z, s - s.mean())) < 1e-8 * np.linalg.norm(z) * np.linalg.norm(s)
    assert abs(z.mean()) < 1e-12


def test_linear_record_passes_and_cubic_output_fails():
    rng = np.random.default_rng(1)
    n = 32768
    x = _filtered_noise(n, rng)
    y_lin = _resonator(x)
    y_lin = y_lin / y_lin.std()
    for cubic, expect in ((0.0, False), (0.05, True)):
        y = y_lin + cubic * _resonator(y_lin ** 3) / _resonator(y_lin ** 3).std() * 3
        y = y + 0.02 * rng.standard_normal(n)
        regs = distortion_regressors({"y": y}, ("square", "cube"))
        t = linearity_test(x, {"y": y}, 1.0, regs, band_hz=(0.06, 0.29))
        assert t.significant is expect, t.report()


def test_linear_satmd_recording_is_not_flagged_and_a_hard_host_spring_is():
    lin = simulate(time=True, level=1.0, duration_s=10, fs_hz=1024, noise=0.02, seed=3)
    assert not distortion_test(lin).significant
    hard = simulate(time=True, nonlinear=[element("cubic_host_spring", k3=8e13)], level=1.0, duration_s=10,
                    fs_hz=1024, noise=0.02, seed=3)
    t = distortion_test(hard)
    assert t.significant
    assert any(a <= 60 and b >= 40 for a, b in t.bands_hz), t.bands_hz  # at the first resonance (~50 Hz)


def test_band_scan_locates_a_hot_band():
    rng = np.random.default_rng(2)
    freq = np.linspace(10, 100, 300)
    score = rng.chisquare(4, freq.size)
    p, bands, _, _ = band_scan(freq, score, 4, 1e-3)
    assert p > 1e-3 and bands == []
    score[140:150] += 40
    p, bands, _, _ = band_scan(freq, score, 4, 1e-3)
    assert p < 1e-6 and len(bands) == 1 and bands[0][0] <= freq[145] <= bands[0][1]


def _frf(rig, freq, rel=0.002, seed=0):
    data = simulate(freq_hz=freq, rig=rig, noise=(rel, 0.0002), seed=seed)
    return data


def test_level_dependence_calibrated_and_sensitive():
    freq = np.linspace(40, 130, 200)
    a, b = _frf(Rig(), freq, seed=1), _frf(Rig(), freq, seed=2)
    t = level_dependence(freq, [a.channels, b.channels], [a.std, b.std])
    assert not t.significant
    c = _frf(Rig().replace(kp=111e3 * 1.03), freq, seed=3)
    t = level_dependence(freq, [a.channels, c.channels], [a.std, c.std])
    assert t.significant and t.bands_hz


@pytest.mark.parametrize("parameter, direction, name", [
    ("kp", "up", "cubic_absorber_spring"), ("k1", "down", "cubic_host_spring"), ("cp", "down", "absorber_friction"),
    ("cp", "up", "quadratic_damping"), ("L", "down", "inductor_saturation"), ("L", "up", None)])
def test_element_for_reads_the_direction(parameter, direction, name):
    cls = element_for(parameter, direction)
    assert (cls.name if cls else None) == name


@pytest.mark.parametrize("change, name", [({"kp": 111e3 * 1.08}, "cubic_absorber_spring"),
                                          ({"cp": 2.5}, "absorber_friction"),
                                          ({"L": 0.064 * 0.93}, "inductor_saturation")])
def test_levels_as_frfs_name_the_element(change, name):
    freq = np.linspace(40, 130, 120)
    low = _frf(Rig(), freq, seed=4)
    high = _frf(Rig().replace(**change), freq, seed=5)
    rep = analyse_frfs([low, high], levels=[0.1, 1.0])
    assert rep.detected
    f = rep.findings[0]
    assert f["name"] == name
    p = next(iter(f["equivalent_linear"]))
    assert p in change and len(f["equivalent_linear"][p]) == 2
    d = rep.to_dict()
    assert set(d) >= {"detected", "tests", "findings"}
    assert set(d["findings"][0]) >= {"name", "parameters", "ci95", "equivalent", "equivalent_linear", "explanation"}


def test_repeats_of_a_linear_rig_are_one_system():
    recs = [simulate(time=True, level=1.0, duration_s=8, fs_hz=1024, noise=0.02, seed=s) for s in (11, 12)]
    rep = analyse_recordings(recs)
    assert isinstance(rep, NonlinearReport)
    assert not rep.detected and rep.findings == []
    assert [t.name for t in rep.tests] == ["distortion#1", "distortion#2", "level_dependence",
                                          "level_dependence_parameters"]


def test_multisine_bla_and_detection_lines():
    rng = np.random.default_rng(6)
    N, P, M = 1024, 4, 3
    k = np.arange(N // 2)
    lines = k[(k % 2 == 1) & (k > 10) & (k < 200) & (k % 8 != 7)]  # odd lines, some left out for detection
    u = np.zeros((M, P, N))
    for m in range(M):
        U = np.zeros(N // 2 + 1, complex)
        U[lines] = np.exp(2j * np.pi * rng.random(lines.size))
        u[m] = np.fft.irfft(U, N)[None]
    u /= u.std()
    for cubic in (0.0, 0.2):
        y = np.stack([[_periodic_resonator(p) for p in r] for r in u])
        y = y + cubic * y ** 3 + 0.01 * rng.standard_normal(y.shape)
        b = multisine_bla(u, y, lines, 1.0)
        assert b["bla"].shape == lines.shape and np.all(np.isfinite(b["var_total"]))
        t = detection_lines_test(u, y, lines, 1.0, band_hz=(0.0, 0.25))
        assert t.significant is (cubic > 0), t.report()
        if cubic:
            assert t.details["odd_ratio"] > 3 * max(t.details["even_ratio"], 1.0)


def _periodic_resonator(x, f0=0.1, zeta=0.05):
    X = np.fft.rfft(x)
    f = np.fft.rfftfreq(x.size)
    H = 1.0 / (f0 ** 2 - f ** 2 + 2j * zeta * f0 * f)
    return np.fft.irfft(X * H * f0 ** 2, x.size)


def test_one_mode_fit_is_exact_on_a_one_mode_frf():
    f = np.linspace(40, 100, 400)
    w, wn, z = 2 * np.pi * f, 2 * np.pi * 68.5, 0.047
    H = 3.0 / (wn ** 2 - w ** 2 + 2j * z * wn * w) + 1e-6
    m = one_mode_fit(f, H, np.full(f.size, 1e-9))
    assert m["f_n_hz"] == pytest.approx(68.5, rel=1e-6) and m["zeta"] == pytest.approx(0.047, rel=1e-5)


def test_report_json_block_and_text():
    freq = np.linspace(40, 130, 120)
    rep = analyse_frfs([_frf(Rig(), freq, seed=7), _frf(Rig(), freq, seed=8)], levels=[0.1, 1.0])
    assert rep.to_dict()["detected"] is False and rep.to_dict()["findings"] == []
    assert "no nonlinearity detected" in rep.report()
    assert ACCEL_CHANNELS[0] in rep.tests[0].details["worst"]


def test_cli_takes_several_recordings(tmp_path, capsys):
    import json

    from satmd.cli import main
    from satmd.io import save_recording

    paths = []
    for level, seed in ((0.1, 21), (1.0, 22)):
        rec = simulate(time=True, level=level, duration_s=8, fs_hz=1024, noise=0.02, seed=seed)
        paths.append(str(save_recording(rec, tmp_path / f"rec{seed}.csv")))
    assert main(["discover", *paths, "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["nonlinear"]["detected"] is False
    assert "level_dependence" in [t["name"] for t in doc["nonlinear"]["tests"]]


def test_sweeps_at_several_levels_are_judged_not_refused():
    """A sine sweep cannot carry the distortion test (no broadband force at each moment): with several levels
    the test says it did not run and the levels are still compared (it refused, blaming the user for not
    recording two levels, which they had)."""
    import json

    from satmd import discover, simulate

    recs = [simulate(time=True, excitation="sweep", level=lv, duration_s=16.0, fs_hz=1024.0, noise=0.01, seed=i)
            for i, lv in enumerate((1.0, 4.0))]
    doc = json.loads(json.dumps(discover(recs).to_dict(), allow_nan=False))
    tests = {t["name"]: t for t in doc["nonlinear"]["tests"]}
    assert tests["distortion#1"]["p_value"] is None and "sweep" in tests["distortion#1"]["not_run"]
    assert tests["level_dependence"]["p_value"] is not None
    assert doc["nonlinear"]["detected"] is False and doc["effects"] == []


def test_nonlinear_findings_are_typed_and_read_as_their_json():
    """Nonlinear findings are typed (issue 36: untyped dicts beside the typed EffectFinding), read by their JSON
    keys as before, and their JSON leaves out what a finding does not have."""
    from satmd.discovery.findings import NonlinearFinding

    f = NonlinearFinding("nonlinear_unexplained", modes=[{"trend": "softening"}], explanation="x")
    assert f.modes == f["modes"] == f.get("modes") and "character" not in f and f.get("character") is None
    assert f.to_dict() == {"name": "nonlinear_unexplained", "parameters": {}, "ci95": {}, "equivalent": [],
                           "equivalent_linear": {}, "modes": [{"trend": "softening"}], "explanation": "x"}
    with pytest.raises(KeyError):
        f["moving"]


def test_tests_that_could_not_run_for_one_reason_are_said_once():
    """Four levels' "distortion_lines#k: not run (same reason)" read as one line; a test that ran, or another
    reason, keeps its own (the JSON keeps every test)."""
    from satmd.discovery.nonlinear.stats import NonlinearTest

    why = "no detection lines: the force reaches every line up to 1.5x the band"
    tests = [NonlinearTest(f"distortion_lines#{k}", np.nan, [], 1e-3, {"reason": why}) for k in (1, 2, 3, 4)]
    tests += [NonlinearTest("distortion#5", np.nan, [], 1e-3, {"reason": "a sweep"}),
              NonlinearTest("level_dependence", 0.0, [(7.0, 7.4)], 2.5e-4)]
    rep = NonlinearReport(True, tests, [], [])
    lines = [x for x in rep.report().splitlines() if x.startswith("    test ")]
    assert lines[0] == f"    test distortion_lines#1–#4: not run ({why})"
    assert lines[1] == "    test distortion#5: not run (a sweep)" and lines[2].startswith("    test level_dependence: p = 0")
    assert len(lines) == 3 and len(rep.to_dict()["tests"]) == 6

"""`satmd.tune` on a Rig, a FitResult and a DiscoveryReport; the SPEC §10 document."""
import json
import math

import numpy as np
import pytest

import satmd
from satmd import DataError, Rig, effect, identify, simulate
from satmd.tuning import TuneResult, tune

SPEC_KEYS = ["objective", "output", "band_hz", "design", "value", "current", "attenuation_db", "model", "robust"]


@pytest.fixture(scope="module")
def paper():
    return tune(Rig())


def test_paper_rig_matches_spec_example(paper):
    # SPEC §10: value 3.50e-5, current 9.51e-5, 8.68 dB vs current, 16.26 dB vs open circuit
    assert isinstance(paper, TuneResult)
    assert paper.value == pytest.approx(3.50e-5, rel=2e-3)
    assert paper.current_value == pytest.approx(9.51e-5, rel=1e-3)
    assert paper.attenuation_db["vs_current"] == pytest.approx(8.68, abs=0.01)
    assert paper.attenuation_db["vs_open_circuit"] == pytest.approx(16.26, abs=0.01)
    assert paper.design["R"] == pytest.approx(46.9, rel=0.02) and paper.design["L"] == pytest.approx(0.214, rel=0.01)
    assert paper.current_design == {"R": 22.0, "L": 0.064}
    assert len(paper.peaks_hz) == 2  # equal peaks either side


def test_json_has_exactly_the_spec_keys_and_no_nan(paper):
    d = paper.to_dict()
    assert list(d) == SPEC_KEYS
    assert d["model"] == {"parameters": {"m2": 0.518, "kp": 111000.0}, "effects": []}
    assert d["robust"] is None and d["band_hz"] == [20.0, 200.0]
    json.dumps(d, allow_nan=False)
    json.dumps(paper.to_dict(details=True), allow_nan=False)
    assert "Shunt tuning" in paper.report() and "equal-peak" in paper.report()


def test_exported_from_satmd_and_plot(tmp_path, paper):
    assert satmd.tune is tune and satmd.TuneResult is TuneResult
    out = paper.plot(tmp_path / "tune.png")
    assert out.exists() and out.stat().st_size > 1000
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary file left
    r = paper.response()
    assert set(r) == {"freq_hz", "tuned", "current", "open circuit"}
    assert np.abs(r["tuned"]).max() <= paper.value * (1 + 1e-6)


def test_fit_and_discovery_models():
    data = simulate(effects=[effect("extra_mode", f_hz=75.0, zeta=0.01, mass_ratio=0.02)], noise=0.01, seed=2)
    rep = satmd.discover(data)
    assert rep.significant_mismatch and "extra_mode" in rep.effect_names
    res = tune(rep, objective="h2", output="a1", band_hz=(40.0, 130.0))
    assert res.model_source.startswith("augmented model")
    assert [e["name"] for e in res.to_dict()["model"]["effects"]] == ["extra_mode"]
    assert any("augmented" in n for n in res.notes)
    assert any(n.startswith("tuned on the nominal model instead") for n in res.notes)
    # the nominal fit of the same data is tuned on the wrong model
    nominal = tune(rep.nominal_fit, objective="h2", output="a1", band_hz=(40.0, 130.0))
    assert nominal.model_source == "identified model" and nominal.to_dict()["model"]["effects"] == []


def test_robust_tuning_is_deterministic_and_reports_the_guarantee():
    fit = identify(simulate(noise=0.05, seed=3))
    kw = dict(robust=True, n_draws=32, n_search=256, n_starts=1, closed_form_check=False)
    a, b = tune(fit, **kw), tune(fit, **kw)
    assert a.design == b.design  # common random numbers: the same draws every time
    r = a.robust
    assert r["parameters"] == ["m2", "kp"] and r["n_draws"] == 32 and r["quantile"] == 0.95
    assert r["value_quantile"] <= r["nominal_optimum"]["value_quantile"] * (1 + 1e-9)
    assert 0 < r["guaranteed_attenuation_db"]["vs_current"] <= a.attenuation_db["vs_current"] + 0.5
    json.dumps(a.to_dict(), allow_nan=False)
    assert "Robust tuning" in a.report()


def test_robust_with_given_uncertainty_on_a_rig():
    res = tune(Rig(), robust=True, uncertainty={"kp": 5e3}, n_draws=32, n_search=256, n_starts=1,
               closed_form_check=False)
    assert res.robust["source"] == "given standard deviations"
    assert res.robust["value_quantile"] <= res.robust["nominal_optimum"]["value_quantile"] * (1 + 1e-9)


def test_on_bound_is_noted_and_current_override():
    res = tune(Rig(), bounds={"R": (0.1, 20.0)}, current={"R": 10.0}, closed_form_check=False)
    assert res.design["R"] == pytest.approx(20.0, rel=1e-4)
    assert any("bound" in n for n in res.notes)
    assert res.current_design["R"] == 10.0


@pytest.mark.parametrize("kw, match", [
    (dict(design=("F0",)), "design"), (dict(design=("R", "R")), "design"), (dict(bounds={"kp": (1, 2)}), "not design"),
    (dict(bounds={"R": (0, 10)}), "0 < lo"), (dict(design=("c1",), model=Rig(c1=0.0)), "give its bounds"),
    (dict(robust=True), "uncertainty"), (dict(quantile=1.0, robust=True), "quantile"),
    (dict(objective="max"), "objective"), (dict(model="rig.csv"), "Rig, a FitResult"),
])
def test_bad_arguments_are_refused(kw, match):
    model = kw.pop("model", Rig())
    with pytest.raises(DataError, match=match):
        tune(model, **kw)


def test_design_beyond_the_shunt(paper):
    res = tune(Rig(), design=("R", "L", "kp"), n_search=256, n_starts=2, closed_form_check=False)
    assert res.value <= paper.value * (1 + 1e-6)  # one more knob never hurts
    assert math.isfinite(res.attenuation_db["vs_current"])


def test_band_is_spelt_band_hz_and_the_old_keyword_still_works_with_a_warning():
    """One spelling per name (issue 36): every band in Hz is band_hz; band= is kept for old scripts."""
    import warnings

    from satmd import Rig

    new = tune(Rig(), band_hz=(40.0, 130.0), n_search=64, n_starts=1, closed_form_check=False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = tune(Rig(), band=(40.0, 130.0), n_search=64, n_starts=1, closed_form_check=False)
    assert any(issubclass(w.category, DeprecationWarning) and "band_hz" in str(w.message) for w in caught)
    assert old.design == new.design and old.band_hz == new.band_hz == (40.0, 130.0)

"""Where a joint acts (issue 47, SPEC §11): ranked over every pair of sensors and the ground, on an independent
chain and on the F-16 ground vibration test."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.errors import DataError, SatmdError
from satmd.io import Recording
from satmd.io.shared import real_data
from satmd.structure import LAWS, locate_joint
from satmd.structure.spectra import periodic_spectra
from tests.conftest import needs_real
from tests.structure.chain import simulate_chain


@pytest.fixture(scope="module")
def cubic_between_3_and_4():
    return simulate_chain(joint=(2, 3), law=lambda d, v: 3e9 * d ** 3, seed=1)


def test_a_cubic_joint_between_two_masses_is_placed_and_named(cubic_between_3_and_4):
    loc = locate_joint(cubic_between_3_and_4)
    assert loc.detected and loc.between == ("acc3", "acc4") and loc.law == "cubic"
    assert loc.location[1]["delta_bic"] > 100  # the next place is far behind
    assert {tuple(e["between"]) for e in loc.location} == {  # every pair and every sensor to the ground
        *[(f"acc{i}", f"acc{j}") for i in range(1, 6) for j in range(i + 1, 6)], *[(f"acc{i}", "ground") for i in range(1, 6)]}
    d = loc.to_dict()
    assert d["name"] == "joint" and d["between"] == ["acc3", "acc4"] and d["location"][0]["delta_bic"] == 0.0


def test_the_joints_paths_share_the_modes_of_the_measured_column(cubic_between_3_and_4):
    """A force on mode r reaches channel o in proportion to its reference residue A_or: with every mode's input
    κ_r = 1 the shared columns are the reference FRF's modal part, the same coefficients for every channel."""
    from satmd.structure.locate import prepare

    ref, _, names, rows, H, transfer, modal = prepare(cubic_between_3_and_4)
    n = len(modal.modes)
    fitted = modal.predict(ref.freq_hz[rows[id(ref)]])
    for c in names:
        shared, own = transfer[c]
        assert shared.shape[1] == 2 * n and own.shape[1] == 6
        rebuilt = shared @ np.tile([1.0, 0.0], n) + own @ modal.coefficients[c][2 * n:]  # κ = 1 + 0i everywhere
        assert np.linalg.norm(rebuilt - fitted[c]) < 1e-12 * np.linalg.norm(fitted[c]), c


def test_a_saturating_mount_is_named_softening():
    """A spring that gives way beyond 0.2 mm (ks·g·tanh(d/g)), between masses 2 and 3: placed, and named as the
    saturating spring it is, not as a cubic."""
    recs = simulate_chain(joint=(1, 2), law=lambda d, v: 2e4 * 2e-4 * np.tanh(d / 2e-4), seed=6)
    loc = locate_joint(recs)
    assert loc.between == ("acc2", "acc3") and loc.law == "softening", loc.laws


def test_a_joint_to_the_ground_is_placed_there():
    recs = simulate_chain(joint=(1, None), law=lambda d, v: 3e9 * d ** 3, levels=(1.0, 4.0), seed=2)
    loc = locate_joint(recs)
    assert loc.between == ("acc2", "ground")


def test_a_friction_joint_is_placed(cubic_between_3_and_4):
    recs = simulate_chain(joint=(3, 4), law=lambda d, v: 0.4 * np.tanh(v / 1e-3), seed=3)
    assert locate_joint(recs).between == ("acc4", "acc5")


def test_a_linear_structure_has_no_joint():
    """No joint: the change between levels is noise; no place explains it better than none."""
    for seed in (4, 5):
        loc = locate_joint(simulate_chain(joint=(2, 3), law=lambda d, v: 0.0 * d, levels=(1.0, 4.0), seed=seed))
        assert not loc.detected, loc.evidence
        assert loc.report().startswith("no joint") and loc.to_dict()["detected"] is False


def test_refusals_name_what_is_wrong(cubic_between_3_and_4):
    low, high = cubic_between_3_and_4[0], cubic_between_3_and_4[2]
    with pytest.raises(DataError, match="two or more levels"):
        locate_joint([low])
    fewer = Recording(low.fs_hz, {c: high[c] for c in ("force", "acc1", "acc2")}, meta={"source": "fewer.csv"})
    with pytest.raises(DataError, match="fewer.csv: no channel acc3"):
        locate_joint([low, fewer], channels=["acc1", "acc2", "acc3"])
    noise = Recording(low.fs_hz, {"force": np.random.default_rng(0).standard_normal(low.n_samples),
                                  "acc1": low["acc1"]}, meta={"source": "random.csv"})
    with pytest.raises(DataError, match="random.csv: the force is random, not periodic"):
        periodic_spectra(noise)
    cut = Recording(low.fs_hz, {c: low[c][:300] for c in low.channels}, meta={"source": "cut.csv"})
    with pytest.raises(DataError, match=r"cut.csv: the force is \w+, not periodic \(300 samples"):
        periodic_spectra(cut)  # a level cut short of its periods: its length said, the cut seen
    with pytest.raises(DataError, match="unknown joint law"):
        from satmd.structure import law
        law("glue")
    assert set(LAWS) == {"cubic", "softening", "clearance", "friction", "quadratic_damping", "sparse"}


@needs_real("f16", "F16Data_FullMSine_Level7.mat")
def test_f16_joint_is_between_the_wing_and_the_payload():
    """The F-16's nonlinear interface joins the wing (acc2) and the payload (acc3) (the benchmark's own
    description): levels 1, 3, 5, 7, the lowest the linear reference."""
    import warnings

    from satmd.io import load_recording

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        recs = [load_recording(real_data("f16", f"F16Data_FullMSine_Level{level}.mat"),
                               channel_map="force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]")
                for level in (1, 3, 5, 7)]
    loc = locate_joint(recs, band_hz=(2.5, 14.5))
    assert loc.between == ("acc2", "acc3")
    assert loc.location[1]["delta_bic"] > 1000


def test_discover_says_where_the_joint_acts(cubic_between_3_and_4, monkeypatch):
    """`discover` on the levels of a structure with five accelerometers: the SATMD model is not adequate, the
    change with level is told per resonance and placed between the two sensors the joint joins (SPEC §11).
    ``fit_joint=False`` (the CLI's ``--locate-only``) places and names it without a model, and claims none; each
    level's force is read once, at the door; no SATMD element's strength is fitted in time for a structure (12 s
    of a 32 s `discover`, thrown away). The fitted path: `tests/cli/test_cli_predict.py`."""
    from satmd import discover
    from satmd.discovery.nonlinear import findings
    from tests.signal.test_memo import count_detections

    calls = count_detections(monkeypatch)
    fitted: list = []
    monkeypatch.setattr(findings, "_time_domain_strength", lambda *a: fitted.append(a[1]))
    rep = discover(cubic_between_3_and_4, fit_joint=False)
    assert len(calls) == len(cubic_between_3_and_4) and fitted == []
    d = rep.to_dict()["nonlinear"]
    assert d["detected"] and [f["name"] for f in d["findings"]] == ["joint"]
    joint = d["findings"][0]
    assert joint["between"] == ["acc3", "acc4"] and joint["law"] == "cubic" and "fit" not in joint
    assert joint["location"][0]["between"] == ["acc3", "acc4"] and "modes" in joint
    assert "joint between acc3 and acc4" in rep.report()
    assert rep.model is None and "modelled" not in rep.report()
    fig = rep.figure()  # the structure's figure, not the SATMD rig's FRF panels; no fit, no fit panel
    assert len(fig.axes) == 2 and "a joint between acc3 and acc4 (cubic)" in fig.texts[0].get_text()
    with pytest.raises(SatmdError, match="fit_joint=False .* two or more levels"):
        discover(cubic_between_3_and_4[0], fit_joint=False)  # one recording: no joint to place


def _clipped(recording, channel, share=0.6):
    """``recording`` with ``channel`` clipped at ``share`` of its peak, as a sensor past its range reads."""
    v = np.asarray(recording[channel], float)
    top = share * np.abs(v).max()
    return Recording(recording.fs_hz, {**{c: recording[c] for c in recording.channels}, channel: np.clip(v, -top, top)},
                     meta={"source": "top.csv"})


def test_a_clipped_sensor_is_the_measurement_chain_not_a_joint(cubic_between_3_and_4):
    """A sensor clipped at the top level changes with level as a joint does, harmonics and all. On a linear chain
    it was placed as a joint (acc3 and acc4, quadratic damping); it is left out and said to be the measurement
    chain's, and no joint is claimed. With a joint, the joint is still placed among the others."""
    from satmd import discover
    from satmd.discovery.nonlinear.modes import untrusted_channels

    low, high = simulate_chain(joint=(2, 3), law=lambda d, v: 0.0 * d, levels=(1.0, 8.0), seed=1)
    rep = discover([low, _clipped(high, "acc2")], fit_joint=False)
    d = rep.to_dict()["nonlinear"]
    assert [f["name"] for f in d["findings"]] == ["nonlinear_unexplained"]
    assert "acc2 left out (clipped in top.csv" in d["findings"][0]["explanation"]
    levels = [*cubic_between_3_and_4[:2], _clipped(cubic_between_3_and_4[2], "acc1")]
    joint = discover(levels, fit_joint=False).to_dict()["nonlinear"]["findings"][0]
    assert joint["between"] == ["acc3", "acc4"] and "acc1 left out (clipped" in joint["explanation"]
    dead = Recording(low.fs_hz, {**{c: low[c] for c in low.channels}, "acc5": 0.0 * low["acc5"]}, meta={})
    assert untrusted_channels([high, dead], ["acc1", "acc5"]) == {
        "acc5": "constant in recording 2: the sensor recorded nothing"}


def test_discover_refuses_a_sensor_missing_at_one_level(cubic_between_3_and_4):
    from satmd import discover

    low, mid, high = cubic_between_3_and_4
    fewer = Recording(high.fs_hz, {c: high[c] for c in high.channels if c != "acc5"}, meta={"source": "L3.csv"})
    with pytest.raises(DataError, match="L3.csv: its channels differ from level 1's \\(no acc5\\)"):
        discover([low, mid, fewer])


def test_the_figure_draws_the_joint_and_the_evidence(cubic_between_3_and_4, tmp_path):
    loc = locate_joint(cubic_between_3_and_4, laws=["cubic"])
    out = loc.plot(tmp_path / "joint.png", title="chain")
    assert out.is_file() and out.stat().st_size > 10_000


def test_the_true_place_and_law_leave_the_least_of_the_change_unexplained(cubic_between_3_and_4):
    """`unexplained`: the share of the levels' change a law at a place leaves, as `locate_joint` weighs it."""
    from satmd.structure.locate import unexplained

    true = unexplained(cubic_between_3_and_4, ("acc3", "acc4"), "cubic")
    elsewhere = unexplained(cubic_between_3_and_4, ("acc1", "acc2"), "cubic")
    assert 0.0 <= true < 0.5 * elsewhere <= 0.5

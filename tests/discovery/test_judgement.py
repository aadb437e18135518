"""One judgement (issue 36): every candidate a discovery meets ends as one `Judged` with one status and its
reasons; the report's effects, set-aside candidates and measurement entries are read from that one list."""
import pytest

from satmd import discover, effect
from satmd.discovery.findings import STATUSES, EffectFinding, Judged
from satmd.identification.adequacy import Reason
from satmd.simulation.frf import simulate

FINDING = EffectFinding("time_delay", {"tau_s": 1e-4}, [], 50.0, "a delay")


def test_a_verdict_other_than_named_needs_a_reason_and_a_known_status():
    assert Judged("time_delay", finding=FINDING).status == "named"
    with pytest.raises(ValueError, match="needs a reason"):
        Judged("time_delay", "set_aside", (), FINDING)
    with pytest.raises(ValueError, match="status"):
        Judged("time_delay", "dropped", (Reason("x", "y"),), FINDING)
    assert set(STATUSES) == {"named", "set_aside", "measurement", "withdrawn"}


def test_the_report_reads_every_verdict_from_one_list():
    d = simulate(effects=[effect("time_delay", tau_s=3e-4)], noise=(0.01, 0.002), seed=1)
    rep = discover(d)
    assert rep.effect_names == [j.name for j in rep.judged if j.status == "named"] == ["time_delay"]
    why = Reason("distortion", "the record is distorted")
    aside = rep.rejudged(lambda j: True, "set_aside", [why])
    assert aside.effects == [] and aside.set_aside == {}  # set aside for nonlinearity: told in the nonlinear block
    assert [(j.name, j.status, j.reasons) for j in aside.judged] == [("time_delay", "set_aside", (why,))]
    stretched = rep.rejudged(lambda j: True, "set_aside", [Reason("implausible", "R at its bound")])
    assert list(stretched.set_aside) == ["time_delay"]
    assert stretched.to_dict()["set_aside"][0]["reasons"][0]["kind"] == "implausible"


def test_a_distorted_recording_sets_its_linear_effects_aside_with_a_reason():
    """The rule `check_one` applies: a named linear effect of a distorted record is set aside, for distortion."""
    from satmd.discovery.nonlinear.levels import check_one
    from satmd.physics.nonlinear import element

    rep = discover(simulate(effects=[effect("time_delay", tau_s=3e-4)], noise=(0.01, 0.002), seed=1))
    rec = simulate(time=True, nonlinear=[element("quadratic_damping", c2=40.0)], level=1.0, duration_s=30,
                   fs_hz=2048, noise=0.02, seed=2)
    out = check_one(rep, rec)
    assert out.nonlinear.detected and out.effects == []
    assert [(j.name, j.status, [r.kind for r in j.reasons]) for j in out.judged] == [
        ("time_delay", "set_aside", ["distortion"])]
    assert out.nonlinear.set_aside == ["time_delay"] and out.to_dict()["nonlinear"]["set_aside"] == ["time_delay"]

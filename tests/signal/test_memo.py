"""Each recording is analysed once (issue 36, item 0): the memo of `satmd.signal.memo` behind `lpm` and the
force's excited band answers a question asked before, by the data's content, never with a stale or shared
answer."""
from __future__ import annotations

import numpy as np

import satmd
from satmd.signal import lpm as lpm_module
from satmd.signal.lpm import excited_band, lpm
from satmd.signal.memo import ContentMemo, fingerprint
from satmd.simulation.timesim import simulate_recording
from satmd.physics import Rig


def _recording(seed=0):
    return simulate_recording(20.0, 1000.0, rig=Rig(R=30.0, L=0.15), noise=0.02, seed=seed)


def _count_fits(monkeypatch):
    calls = {"band": 0, "lpm": 0}
    find, fit = lpm_module._find_excited, lpm_module._lpm

    def counted_find(*a):
        calls["band"] += 1
        return find(*a)

    def counted_fit(*a):
        calls["lpm"] += 1
        return fit(*a)

    monkeypatch.setattr(lpm_module, "_find_excited", counted_find)
    monkeypatch.setattr(lpm_module, "_lpm", counted_fit)
    lpm_module._EXCITED.clear()
    lpm_module._LPM.clear()
    return calls


def test_a_recording_asked_twice_is_analysed_once(monkeypatch):
    calls = _count_fits(monkeypatch)
    rec = _recording()
    first = lpm(rec, band_hz=(30.0, 150.0))
    second = lpm(rec, band_hz=(30.0, 150.0))
    excited_band(rec["force"], rec.fs_hz)
    assert calls == {"band": 1, "lpm": 1}
    for c in first.frf:
        np.testing.assert_array_equal(first.frf[c], second.frf[c])
        np.testing.assert_array_equal(first.std[c], second.std[c])
    lpm(rec, band_hz=(30.0, 150.0), degree=3)  # other settings: another question
    assert calls["lpm"] == 2


def test_a_changed_recording_or_an_edited_answer_is_never_reused(monkeypatch):
    calls = _count_fits(monkeypatch)
    rec = _recording(1)
    est = lpm(rec)
    est.frf["a1"][:] = 0.0  # the caller edits what it got: the next caller's answer is not edited
    again = lpm(rec)
    assert calls["lpm"] == 1 and np.all(np.abs(again.frf["a1"]) > 0)
    rec["acc1"][:] *= 2.0  # arrays shared with the caller, changed in place: a new question
    doubled = lpm(rec)
    assert calls["lpm"] == 2
    np.testing.assert_allclose(doubled.frf["a1"], 2.0 * again.frf["a1"], rtol=1e-9)


def test_discover_estimates_each_recording_once_per_setting(monkeypatch):
    calls = _count_fits(monkeypatch)
    asked = []
    answer = lpm_module._LPM.answer
    monkeypatch.setattr(lpm_module._LPM, "answer", lambda key, compute: asked.append(key) or answer(key, compute))
    satmd.discover([_recording(2), _recording(3)])
    assert calls["band"] == 2  # one force each: found once, asked for by every stage (15 times before)
    assert len(asked) > calls["lpm"] == len(set(asked))  # the estimate, its model error, the distortion test's


def test_the_fingerprint_tells_data_apart_and_the_memo_stays_small():
    x = np.arange(10.0)
    assert fingerprint(x) == fingerprint(x.copy())
    assert fingerprint(x) != fingerprint(x.astype(np.float32))
    assert fingerprint(x) != fingerprint(x.reshape(2, 5))
    assert fingerprint(x, settings=(1.0,)) != fingerprint(x, settings=(1.0 + 1e-15,))
    memo = ContentMemo(size=2)
    for k in range(5):
        assert memo.answer(bytes([k]), lambda k=k: [k]) == [k]
    assert len(memo._answers) == 2


def test_bands_that_differ_in_the_last_digit_are_two_questions(monkeypatch):
    calls = _count_fits(monkeypatch)
    rec = _recording(4)
    lpm(rec, band_hz=(np.float64(30.0), np.float64(150.0)))
    lpm(rec, band_hz=(30.0, 150.0 + 1e-9))
    assert calls["lpm"] == 2
    lpm(rec, band_hz=[30.0, 150.0])  # the same band, as floats in a list: the same question
    assert calls["lpm"] == 2


def count_detections(monkeypatch) -> list:
    """Every call of `detect_excitation` (the force read for its kind and layout), recorded."""
    from satmd.signal import excitation as excitation_module

    calls: list = []
    detect = excitation_module.detect_excitation
    monkeypatch.setattr(excitation_module, "detect_excitation", lambda *a, **k: calls.append(1) or detect(*a, **k))
    return calls


def test_discover_reads_each_force_once_at_the_door(monkeypatch):
    """A recording's walk through `discover` goes down the floors once: its excitation is read when it comes in
    (`signal.excitation.received`) and every later stage (estimators, the distortion test, the level ladder)
    reads what it carries."""
    calls = count_detections(monkeypatch)
    satmd.discover([_recording(4), _recording(5)])
    assert len(calls) == 2

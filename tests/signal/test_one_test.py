"""One test saved in several files gives one FRF (issue 49 item 5): hits one per file, periodic realisations,
repeats; levels and mismatched files are refused with a line that says why."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.cli import main
from satmd.errors import DataError
from satmd.io import Recording, load_frf, save_recording
from satmd.physics import Rig, frf
from satmd.physics.timemodel import LinearRig
from satmd.signal import estimate_frf
from satmd.signal.several import one_test

FS = 1000.0


def _record(force, seed, noise=0.02, name="rec"):
    rng = np.random.default_rng(seed)
    out = LinearRig(Rig()).respond(force, FS)
    chans = {c: out[c] + noise * np.std(out[c]) * rng.standard_normal(out[c].size) for c in ("force", "acc1", "acc2")}
    return Recording(FS, chans, meta={"source": name})


def _hit_file(seed, height=1.0, n=6000):
    """Two hammer hits, each left to ring down (a file of one or two hits, as a hammer test saves them)."""
    x = np.zeros(n)
    w = 6
    for t in (0.5, 3.2):
        i = int(t * FS)
        x[i:i + w] += height * 50.0 * np.sin(np.pi * np.arange(w) / w)
    return _record(x, seed, noise=0.005, name=f"hit{seed}.csv")


def _realisation(seed, period=2000, periods=6, lo=20.0, hi=200.0, scale=1.0):
    rng = np.random.default_rng(100 + seed)
    k = np.arange(period // 2 + 1)
    f = k * FS / period
    one = np.fft.irfft(np.where((f >= lo) & (f <= hi), np.exp(2j * np.pi * rng.random(k.size)), 0), period)
    return _record(scale * np.tile(one / np.std(one), periods), seed, name=f"real{seed}.csv")


def _error(data):
    truth = frf(data.freq_hz, Rig())
    return max(float(np.median(np.abs(data[c] - getattr(truth, c)) / np.abs(getattr(truth, c)))) for c in data.channels)


def test_hits_saved_one_per_file_give_h1_over_every_hit():
    files = [_hit_file(s) for s in range(4)]
    one = one_test(files)
    assert one.estimator["method"] == estimate_frf(files[0]).estimator["method"]
    assert one.estimator["pooled_records"] == 4
    assert _error(one) < _error(estimate_frf(files[0])) + 1e-3  # more hits: no worse
    assert _error(one) < 0.05


def test_periodic_realisations_give_the_best_linear_approximation():
    files = [_realisation(s) for s in range(4)]
    bla = one_test(files)
    assert bla.estimator["realisations"] == 4 and bla.estimator["pooled_records"] == 4
    single = estimate_frf(files[0])
    assert np.allclose(bla.freq_hz, single.freq_hz)
    assert np.median(bla.std["a1"] / single.std["a1"]) < 0.75  # four realisations: about half the std
    assert _error(bla) < 0.05


def test_levels_are_refused_not_averaged():
    files = [_realisation(0), _realisation(1, scale=1.5)]
    with pytest.raises(DataError, match="levels, not repeats"):
        one_test(files)


def test_files_of_another_test_are_refused():
    a = _realisation(0)
    b = Recording(FS, {"force": a["force"], "acc1": a["acc1"]}, meta={"source": "other.csv"})
    with pytest.raises(DataError, match="other.csv: channels"):
        one_test([a, b])
    c = Recording(2 * FS, dict(a.channels), meta={"source": "fast.csv"})
    with pytest.raises(DataError, match="fast.csv: sampled at 2000"):
        one_test([a, c])


def test_estimate_frf_takes_the_files_discover_takes(tmp_path, capsys):
    paths = []
    for s in range(3):
        path = tmp_path / f"hit{s}.csv"
        save_recording(_hit_file(s), path)
        paths.append(path)
    out = tmp_path / "H.csv"
    rc = main(["estimate-frf", *map(str, paths), "-o", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and out.is_file() and "one FRF from 3 files" in text
    assert _error(load_frf(out)) < 0.05


def test_estimate_frf_refuses_levels_in_one_line(tmp_path, capsys):
    paths = []
    for s, scale in ((0, 1.0), (1, 2.0)):
        path = tmp_path / f"L{s}.csv"
        save_recording(_realisation(s, scale=scale), path)
        paths.append(path)
    rc = main(["estimate-frf", *map(str, paths), "-o", str(tmp_path / "H.csv")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "levels, not repeats" in err[0] and "satmd discover" in err[0]
    assert not (tmp_path / "H.csv").exists()


def test_a_refusal_about_one_of_several_unnamed_recordings_counts_it_from_the_first():
    """Without a source, the level at fault is named by its place among all the recordings given, also when a
    stage looks at the levels after the first alone."""
    from satmd.signal.several import each_named

    def refuse(r):
        raise DataError("the force is constant")

    rec = Recording(100.0, {"force": np.ones(32), "acc1": np.zeros(32)}, meta={})
    with pytest.raises(DataError, match="^recording 2: the force is constant$"):
        each_named([rec, rec][1:], refuse, start=2)
    with pytest.raises(DataError, match="^recording 1: "):
        each_named([rec], refuse)

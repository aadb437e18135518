"""The floor every package stands on (issue 25): conventions, shared numerics, typed warnings."""
from __future__ import annotations

import pickle
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from satmd.conventions import ACCEL_CHANNELS, DEFAULT_FREE, RECORDING_CHANNELS, SPEC_RANGES, TINY
from satmd.errors import DataWarning, PinnedParameterWarning, PoorFitWarning, WarningRecord
from satmd.numerics import distinct_best, lag1_autocorrelation, side_by_side, threaded_differences


def test_conventions_agree_with_each_other_and_the_rig():
    from satmd import Rig

    assert tuple(SPEC_RANGES) == DEFAULT_FREE and set(DEFAULT_FREE) <= set(Rig.names())
    assert tuple(RECORDING_CHANNELS.values()) == ACCEL_CHANNELS
    assert all(lo < hi for lo, hi in SPEC_RANGES.values()) and 0 < TINY < 1e-200


def _reference_pick(values, coords, n, min_dist, finite_only):
    """The loops distinct_best replaced (identification, discovery, tuning), written out once more."""
    picked = []
    for i in np.argsort(values):
        if finite_only and not np.isfinite(values[i]):
            continue
        if all(np.max(np.abs(coords[i] - coords[j])) > min_dist for j in picked):
            picked.append(i)
        if len(picked) == n:
            break
    return picked


@settings(max_examples=40, deadline=None)
@given(arrays(float, st.tuples(st.integers(1, 40), st.integers(1, 3)), elements=st.floats(0, 1)),
       st.integers(1, 6), st.sampled_from([0.02, 0.1, 0.3]), st.booleans(), st.integers(0, 2**31))
def test_distinct_best_is_the_loop_it_replaced(coords, n, min_dist, finite_only, seed):
    rng = np.random.default_rng(seed)
    values = rng.normal(size=coords.shape[0])
    values[rng.random(values.size) < 0.2] = np.inf
    got = distinct_best(values, coords, n, min_dist, finite_only)
    assert got == [int(i) for i in _reference_pick(values, coords, n, min_dist, finite_only)]
    assert len(got) <= n and got == sorted(got, key=lambda i: values[i])
    for a in got:  # picked points are pairwise farther apart than min_dist
        assert all(a == b or np.max(np.abs(coords[a] - coords[b])) > min_dist for b in got)


@settings(max_examples=40, deadline=None)
@given(arrays(complex, st.integers(0, 200), elements=st.complex_numbers(max_magnitude=1e6, allow_nan=False)))
def test_lag1_matches_the_concatenated_form_bit_for_bit(v):
    """discovery.locate's former formula: centred Re and Im concatenated (now one shared function)."""
    from satmd.discovery.locate import _lag1

    if v.size < 3:
        expected = 0.0
    else:
        x = np.concatenate([v.real - v.real.mean(), v.imag - v.imag.mean()])
        lagged = np.concatenate([v.real[:-1] - v.real.mean(), v.imag[:-1] - v.imag.mean()])
        ahead = np.concatenate([v.real[1:] - v.real.mean(), v.imag[1:] - v.imag.mean()])
        power = np.sum(x * x)
        expected = float(np.sum(lagged * ahead) / power) if power > 0 else 0.0
    assert _lag1(v) == expected


def _rosenbrock(x):
    return np.array([10 * (x[1] - x[0] ** 2), 1 - x[0], 0.5 * x[2] * x[0], np.sin(x[2])])


@pytest.mark.parametrize("bounds", [(-np.inf, np.inf), ([-2.0, -1.0, 0.0], [1.2, 2.0, 1.0])])
def test_threaded_differences_take_least_squares_own_steps(bounds):
    """The output-error fits' Jacobian on threads: the same steps as `least_squares`' own ``'2-point'`` (turned back
    at a bound), so the same fit, and the same numbers on one thread or many."""
    from scipy.optimize import least_squares

    x0 = np.array([-1.2, 0.0, 0.999999])  # the second at zero; the third within a step of its upper bound
    own = least_squares(_rosenbrock, x0, diff_step=1e-6, bounds=bounds, max_nfev=30)
    fun, jac = threaded_differences(_rosenbrock, 1e-6, bounds, workers=3)
    ours = least_squares(fun, x0, jac=jac, bounds=bounds, max_nfev=30)
    assert np.allclose(ours.x, own.x, rtol=1e-12, atol=1e-13) and ours.nfev == own.nfev  # round-off apart
    x = np.array([0.3, -0.7, 0.9999999])
    serial = threaded_differences(_rosenbrock, 1e-6, bounds, workers=1)[1](x)
    assert np.array_equal(jac(x), serial)
    exact = np.array([[-20 * x[0], 10, 0], [-1, 0, 0], [0.5 * x[2], 0, 0.5 * x[0]], [0, 0, np.cos(x[2])]])
    assert np.allclose(serial, exact, atol=1e-4)


def test_side_by_side_runs_the_calls_at_once_in_the_caller_s_context(monkeypatch):
    """A structure's law fits on threads: their results in the order given, each call at once with the others (a
    barrier two must reach breaks if they run one after the other), the caller's progress listener heard by each."""
    import threading

    from satmd._progress import stage, stages

    monkeypatch.setattr("satmd.numerics.cores", lambda: 2)
    met = threading.Barrier(2, timeout=10)
    told: list = []

    def call(i):
        met.wait()
        stage(f"call {i}")
        return i * i

    with stages(told.append):
        assert side_by_side([lambda: call(3), lambda: call(4)]) == [9, 16]
    assert sorted(told) == ["call 3", "call 4"]
    monkeypatch.setattr("satmd.numerics.cores", lambda: 1)  # one core: one after the other, in the caller's thread
    assert side_by_side([lambda: threading.get_ident()] * 2) == [threading.get_ident()] * 2


def test_lag1_of_white_noise_and_of_a_smooth_curve():
    rng = np.random.default_rng(0)
    assert abs(lag1_autocorrelation(rng.normal(size=(2, 4000)))) < 0.05
    assert lag1_autocorrelation(np.sin(np.linspace(0, 3, 500))) > 0.99
    assert lag1_autocorrelation(np.zeros((2, 10))) == 0.0 and lag1_autocorrelation([1.0, 2.0]) == 0.0


def test_warning_records_are_strings_with_a_category():
    w = WarningRecord("poor fit: something", PoorFitWarning)
    assert w == "poor fit: something" and isinstance(w, str) and w.category is PoorFitWarning
    again = pickle.loads(pickle.dumps(w))
    assert again == w and again.category is PoorFitWarning
    assert WarningRecord("x").category is DataWarning
    with pytest.warns(PinnedParameterWarning, match="pinned"):
        WarningRecord("m2 is pinned", PinnedParameterWarning).emit()
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataWarning)  # one filter catches every kind
        with pytest.raises(PoorFitWarning):
            w.emit()

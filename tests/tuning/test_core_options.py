"""`tune`, `identify` and `discover`: every keyword validated from one table (issue 25).

A newcomer adds a validated option by one keyword in the signature and one entry in the table
(`validate_params`); these tests hold that line: a keyword without a constraint fails here, and
every constraint refuses a generated invalid value with one line naming the argument.
"""
from __future__ import annotations

import inspect

import pytest

from satmd import Rig
from satmd.errors import DataError
from satmd.tuning import tune
from satmd.tuning.core import TUNE_CONSTRAINTS, Robustness, SearchPlan
from satmd.tuning.source import ResolvedModel, resolve_model
from satmd.validation import invalid_values


def _functions():
    from satmd.discovery import discover
    from satmd.identification import identify

    return {"tune": tune, "identify": identify, "discover": discover}


@pytest.mark.parametrize("name", ["tune", "identify", "discover"])
def test_every_keyword_has_a_constraint(name):
    fn = _functions()[name]
    params = list(inspect.signature(fn).parameters)[1:]  # the first is the data / model itself
    missing = [p for p in params if p not in fn.parameter_constraints]
    assert not missing, f"{name}: keywords without a constraint: {missing}"


TUNE_CASES = [(p, bad) for p, allowed in TUNE_CONSTRAINTS.items() for bad in invalid_values(allowed)]


@pytest.mark.parametrize("param, bad", TUNE_CASES, ids=[f"{c[0]}-{i}" for i, c in enumerate(TUNE_CASES)])
def test_tune_refuses_every_invalid_value_in_one_line(param, bad):
    # the model is a Rig: the error must come from the table, before any work
    with pytest.raises(DataError, match=rf"^(tune: {param} must|unknown {param} )") as err:
        tune(Rig(), **{param: bad})
    assert "\n" not in str(err.value)


def test_tune_defaults_pass_their_constraints():
    from satmd.validation import check

    sig = inspect.signature(tune)
    for p, allowed in TUNE_CONSTRAINTS.items():
        check(p, sig.parameters[p].default, allowed, "tune")
        assert invalid_values(allowed), p


def test_a_new_option_needs_one_keyword_and_one_constraint():
    """What a newcomer writes: the keyword and its entry; the decorator does the rest."""
    from numbers import Real

    from satmd.validation import Interval, validate_params

    @validate_params({**TUNE_CONSTRAINTS, "margin_db": [Interval(Real, 0)]})
    def tune_with_margin(model, objective="hinf", output="u1", band_hz=(20.0, 200.0), bounds=None,
                         design=("R", "L"), robust=False, quantile=0.95, *, band=None, effects=(), current=None,
                         uncertainty=None, n_draws=128, n_search=None, n_starts=3, closed_form_check=True, seed=0,
                         force=False, margin_db=0.0):
        return margin_db

    assert tune_with_margin(Rig(), margin_db=1.5) == 1.5
    with pytest.raises(DataError, match=r"^tune_with_margin: margin_db must be a number >= 0, got -1$"):
        tune_with_margin(Rig(), margin_db=-1)


def test_positional_and_numpy_arguments_still_work():
    import numpy as np

    res = tune(Rig(), "h2", "u1", np.array([30.0, 150.0]), None, ["R", "L"], np.bool_(False), n_search=np.int64(64),
               n_starts=1, closed_form_check=False, seed=np.int64(1))
    assert res.band_hz == (30.0, 150.0) and set(res.design) == {"R", "L"}


def test_parameter_objects():
    assert SearchPlan.make(None, 3, 0, "hinf", 2).n_search == 1024
    assert SearchPlan.make(None, 3, 0, "h2", 4).n_search == 2048
    assert SearchPlan.make(None, 3, 0, "hinf", 5) == SearchPlan(4096, 3, 0)
    assert Robustness() == Robustness(0.95, None, 128)
    resolved = resolve_model(Rig())
    assert isinstance(resolved, ResolvedModel) and resolved.source == "the given rig" and resolved.span is None
    rig, effects, source, params, uncertain, notes, span = resolved  # the former 7-tuple still unpacks
    assert effects == [] and uncertain is None and notes == [] and set(params) == {"m2", "kp", "R", "L"}
    with pytest.raises(AttributeError):
        resolved.source = "x"  # frozen

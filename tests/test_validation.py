"""One validation vocabulary (issue 25): every constraint refuses what it should, with one line naming the argument.

As scikit-learn's ``test_param_validation``: for every function validated with
`satmd.validation.validate_params` (and `InverseModel`'s table), an invalid value is generated for each
constraint and must be refused with a `SatmdError` that names the parameter; the defaults must pass.
"""
from __future__ import annotations

import argparse
import inspect
from numbers import Integral, Real

import numpy as np
import pytest

from satmd.errors import DataError, SatmdError
from satmd.validation import Grid, Interval, Options, Whole, check, invalid_values, validate, validate_params


def _validated():
    """(name, function) of every validated public function."""
    from satmd.discovery import discover
    from satmd.identification import identify
    from satmd.signal.lpm import lpm

    return [("identify", identify), ("lpm", lpm), ("discover", discover)]


CASES = [(name, fn, p, bad) for name, fn in _validated() for p, allowed in fn.parameter_constraints.items()
         for bad in invalid_values(allowed)]


@pytest.mark.parametrize("name, fn, param, bad", CASES, ids=[f"{c[0]}-{c[2]}-{i}" for i, c in enumerate(CASES)])
def test_every_constraint_refuses_an_invalid_value(name, fn, param, bad):
    # validation runs before any work: the data argument is never looked at
    with pytest.raises(DataError, match=rf"^({name}: {param} must|unknown {param} )") as err:
        fn(None, **{param: bad})
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("name, fn", _validated())
def test_defaults_satisfy_the_constraints(name, fn):
    sig = inspect.signature(fn)
    for p, allowed in fn.parameter_constraints.items():
        default = sig.parameters[p].default
        check(p, default, allowed, name)  # raises if a default is refused
        assert invalid_values(allowed), f"{name}: no invalid value generated for {p}"


def test_inverse_table_refuses_an_invalid_value_for_every_constraint():
    pytest.importorskip("torch")
    from satmd.inverse import InverseModel
    from satmd.inverse.params import validate as validate_inverse

    model = InverseModel()
    params = model.get_params()
    validate_inverse(params, model._parameter_constraints)  # the defaults pass
    for p, allowed in model._parameter_constraints.items():
        for bad in invalid_values(allowed):
            with pytest.raises(SatmdError, match=rf"{p}"):
                validate_inverse({**params, p: bad}, {p: allowed})


def test_tune_quantile():
    from satmd import Rig, tune

    for q in (0.4, 1.0, float("nan"), "0.9x"):
        with pytest.raises(DataError, match="^tune: quantile must be a number in \\[0.5, 1\\)"):
            tune(Rig(), quantile=q, robust=True)


def test_vocabulary_in_words():
    assert Interval(Real, 0, 1, "hi").describe() == "a number in [0, 1)"
    assert Interval(Integral, 1).describe() == "an integer >= 1"
    assert Interval(Whole, 1, 1 << 20).describe() == "an integer in [1, 1048576]"
    assert Interval(Real, None, 5, "hi").describe() == "a number < 5"
    assert Interval(Real).describe() == "a finite number"
    assert Options(("a", "b")).describe() == "one of a, b"
    with pytest.raises(DataError, match=r"^f: n must be None or an integer >= 1, got 0$"):
        check("n", 0, [None, Interval(Whole, 1)], "f")
    with pytest.raises(SatmdError, match=r"^unknown kind 'x' for M; choose from a, b$"):
        validate({"kind": "x"}, {"kind": [Options(("a", "b"))]}, "M")
    with pytest.raises(SatmdError, match="an array of shape"):
        validate({"f": np.array([2.0, 1.0])}, {"f": [Grid()]})


def test_interval_kinds():
    whole = Interval(Whole, 1)
    assert whole.accepts(4096) and whole.accepts(4096.0) and whole.accepts(np.int64(3))
    assert not whole.accepts(2.5) and not whole.accepts(True) and not whole.accepts(float("inf"))
    strict = Interval(Integral, 1)
    assert strict.accepts(np.int32(2)) and not strict.accepts(2.0)
    real = Interval(Real, 0, 1, "both")
    assert real.accepts(np.float32(0.5)) and not real.accepts(0.0) and not real.accepts(1.0)


def test_decorator_keeps_the_function_and_refuses_unknown_names():
    @validate_params({"n": [Interval(Integral, 1)]})
    def f(x, n=1):
        """Doc."""
        return x * n

    assert f(2, n=3) == 6 and f.__doc__ == "Doc." and list(inspect.signature(f).parameters) == ["x", "n"]
    with pytest.raises(DataError, match="^f: n must be"):
        f(2, 0)
    with pytest.raises(TypeError, match="no parameter"):
        validate_params({"m": [None]})(f)


def test_cli_types_use_the_vocabulary():
    from satmd.cli._common import integer, real

    assert real(0, 1, lo_open=True)("0.5") == 0.5 and integer(0, 10)("3") == 3
    for parse, text, message in [(real(0, 1, lo_open=True), "0", "0 must be in (0, 1]"),
                                 (real(0), "-1", "-1 must be >= 0"), (integer(1), "0", "0 must be >= 1"),
                                 (integer(0, 10), "11", "11 must be in [0, 10]"), (real(), "nan", "not a finite")]:
        with pytest.raises(argparse.ArgumentTypeError, match=message.replace("(", r"\(").replace("[", r"\[")):
            parse(text)

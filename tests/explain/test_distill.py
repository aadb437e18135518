import time

import numpy as np
import pytest
import sympy as sp

from satmd.errors import SatmdError
from satmd.explain import distill, node_count, paper_complexity
from satmd.explain.distill import pareto_front
from satmd.explain.symbolic import compact, parse, polish


def test_node_count_rule():
    x0, x1 = sp.symbols("x0 x1")
    assert node_count(x0) == 1
    assert node_count(x0 * x1 + 2) == 5  # Add(Mul(x0, x1), 2)
    assert node_count(x0 / x1) == 5  # Mul(x0, Pow(x1, -1))
    assert paper_complexity() == 21


def test_compact_and_polish():
    e = parse("2.0*(x0 + 1.0)*(x0 - 1.0)", 1)
    assert node_count(compact(e)) <= node_count(e)
    Z = np.linspace(-1, 1, 50)[:, None]
    y = 3.0 * Z[:, 0] ** 2 + 0.5
    p = polish(parse("1.0*x0**2 + 0.1", 1), Z, y)
    consts = sorted(float(c) for c in p.atoms(sp.Float))
    np.testing.assert_allclose(consts, [0.5, 3.0], atol=1e-6)


def test_operon_recovers_a_simple_law():
    rng = np.random.default_rng(0)
    X = rng.uniform(-2, 2, (400, 2))
    y = X[:, 0] * X[:, 1] + 2
    t0 = time.perf_counter()
    res = distill(X, y, backend="operon", zscore=False, generations=30, population_size=200, max_length=10)
    assert time.perf_counter() - t0 < 20
    assert res.r2_test > 0.99
    x0, x1 = sp.symbols("x0 x1", real=True)
    assert sp.simplify(res.expression - (x0 * x1 + 2)) == 0
    assert res.complexity == 5
    assert res.pareto and all(a["complexity"] < b["complexity"] for a, b in zip(res.pareto, res.pareto[1:]))
    d = res.to_dict()
    assert d["backend"] == "operon" and isinstance(d["expression"], str)
    np.testing.assert_allclose(res.predict(X[:5]), y[:5], atol=1e-6)


def test_sindy_baseline_on_a_polynomial():
    rng = np.random.default_rng(1)
    X = rng.uniform(-1, 1, (300, 3))
    y = 1.5 * X[:, 0] ** 2 - X[:, 1] * X[:, 2] + 0.3
    res = distill(X, y, backend="sindy", zscore=False, degree=2)
    assert res.r2_test > 0.999
    assert res.complexity <= 15


def test_pysr_without_julia_is_one_line(monkeypatch):
    monkeypatch.setenv("PATH", "/nonexistent")
    for var in ("PYTHON_JULIAPKG_EXE", "JULIA_EXE", "JULIA_BINDIR"):
        monkeypatch.delenv(var, raising=False)
    with pytest.raises(SatmdError) as info:
        distill(np.random.rand(20, 2), np.random.rand(20), backend="pysr")
    msg = str(info.value)
    assert "\n" not in msg and "Julia" in msg and "operon" in msg


def test_unknown_backend_and_bad_shapes():
    with pytest.raises(SatmdError):
        distill(np.random.rand(20, 2), np.random.rand(20), backend="nope")
    with pytest.raises(SatmdError):
        distill(np.random.rand(20, 2), np.random.rand(19), backend="sindy")


def test_pareto_front_keeps_non_dominated():
    e = [{"complexity": 3, "r2_train": 0.5}, {"complexity": 5, "r2_train": 0.4},
         {"complexity": 7, "r2_train": 0.9}, {"complexity": 7, "r2_train": 0.8}]
    front = pareto_front(e)
    assert [(p["complexity"], p["r2_train"]) for p in front] == [(3, 0.5), (7, 0.9)]

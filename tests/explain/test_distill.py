import time

import numpy as np
import pytest
import sympy as sp

from satmd.errors import SatmdError
from satmd.explain import distill, node_count, paper_complexity
from satmd.explain.distillation import pareto_front
from satmd.explain.symbolic import compact, parse, polish, prune


def test_node_count_rule():
    x0, x1 = sp.symbols("x0 x1")
    assert node_count(x0) == 1
    assert node_count(x0 * x1 + 2) == 5  # Add(Mul(x0, x1), 2)
    assert node_count(x0 / x1) == 5  # Mul(x0, Pow(x1, -1))
    # the paper's printed form, 1.69 + 0.02*(x3 - x1 - 2.77 - 0.28*x2)*((x1 - 3.14)**2 + x0):
    # Add(1.69, Mul(0.02, Add(x3, -x1, -2.77, -0.28*x2), Add(Pow(Add(x1, -3.14), 2), x0)))
    assert paper_complexity() == 20


def test_compact_and_polish():
    e = parse("2.0*(x0 + 1.0)*(x0 - 1.0)", 1)
    assert node_count(compact(e)) <= node_count(e)
    Z = np.linspace(-1, 1, 50)[:, None]
    y = 3.0 * Z[:, 0] ** 2 + 0.5
    p = polish(parse("1.0*x0**2 + 0.1", 1), Z, y)
    consts = sorted(float(c) for c in p.atoms(sp.Float))
    np.testing.assert_allclose(consts, [0.5, 3.0], atol=1e-6)


def test_compact_pulls_a_coefficient_out_of_a_sum_in_a_product():
    e = parse("(0.5*x1 + 0.25)*exp(x0) + x1", 2)  # sympy keeps the sum expanded
    c = compact(e)
    assert node_count(c) == node_count(e) - 1
    assert sp.simplify(c - e) == 0
    x0, x1 = sp.symbols("x0 x1", real=True)
    assert c.has(sp.Add(x1, sp.Float(0.5)))  # 0.5*(x1 + 0.5)*exp(x0)


def test_prune_drops_absorbable_constants_and_keeps_the_fit():
    rng = np.random.default_rng(2)
    Z = rng.uniform(-1, 1, (400, 2))
    y = (Z[:, 1] + 2.0) * (Z[:, 0] - 1.0) ** 2
    # an over-parameterised tree of the same function: 0.5*(2*x1 + 4)*(1.0*x0 - 1.0)**2 + 0*x0
    e = parse("0.5*(2.0*x1 + 4.0)*(1.0*x0 - 1.0)**2 + 0.3*x0", 2)
    e = polish(e, Z, y)
    p = prune(e, Z, y)
    assert node_count(p) < node_count(e)
    assert not p.has(sp.Symbol("x0", real=True) * sp.Float(0.3))
    np.testing.assert_allclose(sp.lambdify(sp.symbols("x0 x1", real=True), p)(*Z.T), y, atol=1e-6)
    # a constant that matters stays
    q = prune(parse("2.5*x0 + 1.0", 1), Z[:, :1], 2.5 * Z[:, 0] + 1.0)
    assert sorted(float(c) for c in q.atoms(sp.Float)) == pytest.approx([1.0, 2.5])


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

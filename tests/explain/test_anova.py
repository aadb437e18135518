import numpy as np
import pytest

from satmd.errors import DataError
from satmd.explain.anova import grid_anova, grid_ceiling, structure_ceiling


def _grid(*levels):
    mesh = np.meshgrid(*levels, indexing="ij")
    return np.stack([m.ravel() for m in mesh], axis=1)


def test_shares_of_a_known_function():
    rng = np.random.default_rng(0)
    X = _grid(np.linspace(-1, 1, 5), np.linspace(-1, 1, 4), np.linspace(0, 2, 3))
    x0, x1, x2 = X.T
    # centred, mutually orthogonal terms on this balanced grid
    main0, main1, pair01 = x0 ** 2 - np.mean(np.unique(x0) ** 2), x1, x0 * x1
    y = 3.0 + main0 + 2 * main1 + 0.5 * pair01
    order = rng.permutation(len(y))  # the order of rows must not matter
    a = grid_anova(X[order], y[order], ("a", "b", "c"))
    total = np.var(y)
    assert a.main["a"] == pytest.approx(np.var(main0) / total)
    assert a.main["b"] == pytest.approx(np.var(2 * main1) / total)
    assert a.main["c"] == pytest.approx(0.0, abs=1e-15)
    assert a.pairs[("a", "b")] == pytest.approx(np.var(0.5 * pair01) / total)
    assert a.r2_main == pytest.approx(1 - np.var(0.5 * pair01) / total)
    assert a.r2_pairs == pytest.approx(1.0)
    assert a.r2_greedy[0][0] == "main effects" and a.r2_greedy[1][0] == "+a×b"
    assert a.r2_greedy[1][1] == pytest.approx(1.0)
    assert "a×b" in a.report() and a.to_dict()["pairs"]["axb"] > 0


def test_three_way_interaction_is_left_over():
    X = _grid([-1.0, 1.0], [-1.0, 1.0], [-1.0, 1.0])
    y = X[:, 0] * X[:, 1] * X[:, 2]
    a = grid_anova(X, y)
    assert a.r2_pairs == pytest.approx(0.0, abs=1e-12)
    assert grid_ceiling(X, y, (0, 1, 2)) == pytest.approx(1.0)


def test_rejects_what_is_not_a_full_grid():
    X = _grid([0.0, 1.0], [0.0, 1.0, 2.0])
    with pytest.raises(DataError, match="full-factorial"):
        grid_anova(X[:-1], np.ones(5))
    with pytest.raises(DataError, match="full-factorial"):
        grid_anova(np.vstack([X[:-1], X[:1]]), np.arange(6.0))
    with pytest.raises(DataError, match="finite"):
        grid_anova(X, np.array([1.0, 2, 3, np.nan, 5, 6]))
    with pytest.raises(DataError, match="constant"):
        grid_anova(X, np.ones(6))


def test_structure_ceiling_of_main_effects_is_the_additive_anova():
    """Free one-variable shapes, summed: exactly the ANOVA's additive R²."""
    rng = np.random.default_rng(1)
    X = _grid(np.linspace(-1, 1, 5), np.linspace(0, 2, 4), np.linspace(-2, 1, 3))
    y = np.sin(2 * X[:, 0]) * X[:, 1] + np.exp(X[:, 2]) + 0.3 * rng.standard_normal(len(X))
    ceiling = structure_ceiling(X, y, [(0,), (1,), (2,)])
    assert ceiling == pytest.approx(grid_anova(X, y).r2_main, abs=1e-9)


def test_structure_ceiling_is_one_on_its_own_structure_and_lower_without_it():
    """y = 1 + 0.5 a + F(b) G(c) H(a), arbitrary shapes: reached exactly by that structure only."""
    rng = np.random.default_rng(2)
    la, lb, lc = np.linspace(-1, 1, 5), np.linspace(0, 1, 4), np.linspace(-1, 2, 4)
    X = _grid(la, lb, lc)
    F, G, H = (dict(zip(lv, rng.uniform(0.5, 2.0, lv.size))) for lv in (lb, lc, la))
    y = 1 + 0.5 * X[:, 0] + np.array([F[b] * G[c] * H[a] for a, b, c in X])
    names = ("a", "b", "c")
    assert structure_ceiling(X, y, [("b", "c", "a")], ("a",), names) == pytest.approx(1.0, abs=1e-9)
    assert structure_ceiling(X, y, [("b", "c")], ("a",), names) < 0.99
    with pytest.raises(DataError, match="unknown input 'd'"):
        structure_ceiling(X, y, [("d",)], (), names)

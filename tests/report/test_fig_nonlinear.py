"""The linear-vs-nonlinear figure per drive level (issue 27 item 3) writes an image a user can open."""
from __future__ import annotations

import pytest

from satmd.errors import DataError
from satmd.report.fig_nonlinear import nonlinear_comparison_figure

ROWS = [{"level": 1.0, "held_out": False, "td_error": {"linear": 0.05, "nonlinear": 0.004},
         "frf_residual": {"linear": 0.08, "nonlinear": 0.01}},
        {"level": 10.0, "held_out": True, "td_error": {"linear": 0.3, "nonlinear": 0.005},
         "frf_residual": {"linear": 0.2, "nonlinear": 0.012}},
        {"level": 4.0, "held_out": False, "td_error": {"linear": 0.02, "nonlinear": 0.004},
         "frf_residual": {"linear": 0.04, "nonlinear": 0.01}}]


def test_writes_a_png(tmp_path):
    out = nonlinear_comparison_figure({"levels": ROWS, "nonlinear": {"model": "cubic_absorber_spring"}},
                                      tmp_path / "sub" / "fit.png")
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_returns_the_figure_without_a_path():
    fig = nonlinear_comparison_figure(ROWS)
    axes = fig.get_axes()
    assert len(axes) == 2
    labels = [t.get_text() for t in axes[1].get_xticklabels()]
    assert labels[0].startswith("1 N") and "held out" in labels[2]  # sorted by level, the held-out one marked
    texts = [t.get_text() for t in axes[1].texts]
    assert "60.0×" in texts  # the ratio linear / nonlinear of the held-out level


def test_bad_input():
    with pytest.raises(DataError, match="compare_models"):
        nonlinear_comparison_figure({"levels": []})
    with pytest.raises(DataError, match="td_error"):
        nonlinear_comparison_figure([{"level": 1.0, "frf_residual": {}}])

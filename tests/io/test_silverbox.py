"""Silverbox loader and the level verdict on the real data (../shared; skipped when absent)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from satmd.errors import FormatError
from satmd.io.silverbox import load_silverbox_level, load_silverbox_snls, silverbox_levels

from tests.conftest import needs_real
from satmd.io.shared import real_data

DATA = real_data("silverbox") or Path("absent")
needs_data = needs_real("silverbox")


def test_missing_folder_is_a_one_line_format_error(tmp_path):
    assert silverbox_levels(tmp_path) == []
    with pytest.raises(FormatError, match="no such file"):
        load_silverbox_level(tmp_path, 5)
    with pytest.raises(FormatError, match="no such file"):
        load_silverbox_snls(tmp_path)


@needs_data
def test_levels_load_with_periods_and_lines():
    assert silverbox_levels(DATA) == [5, 20, 50, 100, 150]
    rec = load_silverbox_level(DATA, 5)
    assert set(rec.channels) == {"force", "y"} and rec.n_samples == 245760
    assert rec.fs_hz == pytest.approx(2441.40625)
    assert int(rec.meta["periods"]) * int(rec.meta["period_samples"]) == rec.n_samples
    assert len(rec.meta["lines"].split(",")) == 1007


@needs_data
def test_snls_splits_arrow_and_multisine():
    arrow, ms = load_silverbox_snls(DATA)
    assert 38000 < arrow.n_samples < 42000
    assert ms["u"].shape == (10, 1, 8192)
    U = np.abs(np.fft.rfft(ms["u"][0, 0])) ** 2
    excited = np.flatnonzero(U > 1e-3 * U.max())
    assert np.mean(excited % 2 == 1) > 0.99  # an odd multisine: its steady-state period is cut right


@needs_data
def test_lowest_and_highest_level_show_hardening_at_the_resonance():
    from satmd.discovery.nonlinear.periodic import one_mode_fit
    from satmd.signal.periodic import multisine_bla, periodic_blocks
    from satmd.discovery.nonlinear.stats import level_dependence

    frfs, stds, fn = [], [], []
    for level in (5, 150):
        rec = load_silverbox_level(DATA, level)
        n = int(rec.meta["period_samples"])
        lines = np.array([int(k) for k in rec.meta["lines"].split(",")])
        b = multisine_bla(periodic_blocks(rec["force"], n)[None], periodic_blocks(rec["y"], n)[None], lines,
                          rec.fs_hz)
        frfs.append({"y": b["bla"]})
        stds.append({"y": b["std"]})
        fn.append(one_mode_fit(b["freq_hz"], b["bla"], b["std"])["f_n_hz"])
    assert 68.0 < fn[0] < 69.2  # the literature: 68.5-68.6 Hz at the lowest level
    assert fn[1] > fn[0] + 5  # hardening
    t = level_dependence(b["freq_hz"], frfs, stds)
    assert t.significant and any(a <= 75 and b_ >= 68 for a, b_ in t.bands_hz)

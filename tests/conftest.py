"""Suite-wide rules.

Real data: a test that reads ``../shared`` is marked with `needs_real` (skipped where the
shared folder is absent, as on a user's machine). Under CI (``CI`` set) such a skip is a
failure: CI has the shared folder beside the clone, and a real-data test that silently
skipped there would pass a change it never tried.
"""
from __future__ import annotations

import os
from pathlib import Path

import pytest

from satmd.io.shared import default_beside, real_data, shared_dir

default_beside(Path(__file__).resolve().parents[1])  # ../shared beside this checkout, unless SATMD_SHARED says


def needs_real(*parts: str):
    """Mark: skip unless ``shared/data/real/parts...`` exists (a failure under CI)."""
    return pytest.mark.real_data(reason=f"{'/'.join(('shared', 'data', 'real', *parts))} absent "
                                        f"(shared folder: {shared_dir()})", present=real_data(*parts) is not None)


def pytest_configure(config):
    config.addinivalue_line("markers", "real_data(reason, present): reads ../shared; skipped when absent, "
                                       "a failure under CI")


def pytest_runtest_setup(item):
    for mark in item.iter_markers("real_data"):
        if not mark.kwargs.get("present", False):
            if os.environ.get("CI"):
                pytest.fail(f"real data missing under CI: {mark.kwargs['reason']}", pytrace=False)
            pytest.skip(mark.kwargs["reason"])

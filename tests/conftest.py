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


#: modules whose tests take a minute or more together (``--durations=0`` on a 2-core AMD EPYC), handed to the workers
#: first (`pytest_collection_modifyitems`, with ``--no-loadscope-reorder``): xdist hands modules out by their number
#: of tests otherwise, and a module of two long tests (the F-16 report's, 43 s) came last and ran alone while the
#: other worker sat idle. A module missing here only runs later.
LONG_MODULES = ("tests/explain/test_skeletons.py", "tests/structure/test_model.py", "tests/discovery/test_discover.py",
                "tests/test_docs.py", "tests/structure/test_locate.py", "tests/cli/test_cli_predict.py",
                "tests/report/test_sec_f16.py", "tests/discovery/test_adequacy.py", "tests/structure/test_loop.py",
                "tests/cli/test_cli_fuzz.py")


def pytest_collection_modifyitems(config, items):
    """The `LONG_MODULES` first, longest first; every module's tests kept together and in their order."""
    rank = {name: i for i, name in enumerate(LONG_MODULES)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(rank)))  # stable: the rest as collected


def pytest_runtest_setup(item):
    for mark in item.iter_markers("real_data"):
        if not mark.kwargs.get("present", False):
            if os.environ.get("CI"):
                pytest.fail(f"real data missing under CI: {mark.kwargs['reason']}", pytrace=False)
            pytest.skip(mark.kwargs["reason"])

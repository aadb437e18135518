"""`satmd._compiled.njit_cached`: a compiled function's disk cache follows the files it calls into."""
import subprocess
import sys

import pytest

pytest.importorskip("numba")

CALLER = """
import numba
import callee
from satmd._compiled import njit_cached

g = numba.njit(cache=True)(callee.g)


def f(x):
    return g(x) * 2


f = njit_cached(numba, f, [__file__, callee.__file__])
print(f(1))
"""


def test_a_change_in_a_called_file_recompiles_the_caller(tmp_path):
    """numba alone keeps the caller's machine code when only the callee's file changes; with the guard the
    caller is compiled again (the joint kernel once ran a law's previous text this way)."""
    (tmp_path / "caller.py").write_text(CALLER)
    (tmp_path / "callee.py").write_text("def g(x):\n    return x + 1\n")

    def run():
        out = subprocess.run([sys.executable, "caller.py"], cwd=tmp_path, capture_output=True, text=True, check=True)
        return int(out.stdout.strip())

    assert run() == 4
    assert run() == 4  # from the cache
    (tmp_path / "callee.py").write_text("def g(x):\n    return x + 100\n")
    assert run() == 202

"""A fresh clone on any machine: no path of one machine in the code (issue 49 item 3).

Real data are found by `satmd.io.shared` (``../shared`` beside the checkout, or ``$SATMD_SHARED``);
an absolute path written into a module, test, benchmark or example works only where it was written
and elsewhere makes a real-data test skip in silence.
"""
from __future__ import annotations

import re
from pathlib import Path

from satmd.io import shared

ROOT = Path(__file__).resolve().parents[1]
#: A string literal that starts at a machine's root folder of users or of this workplace.
MACHINE_PATH = re.compile(r"""["'](/work|/home|/root|/Users|/mnt|/opt|/srv|[A-Za-z]:\\\\)[/\\]""")


def _code_files():
    for folder in ("satmd", "tests", "benchmarks", "examples", "docs"):
        yield from (ROOT / folder).rglob("*.py")


def test_no_absolute_machine_path_in_code():
    hits = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in _code_files()
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
            if MACHINE_PATH.search(line) and p.name != "test_portability.py"]
    assert not hits, "absolute machine paths (use satmd.io.shared):\n" + "\n".join(hits)


def test_the_rule_sees_a_machine_path():
    """The check above can fail: the pattern finds what it is meant to find."""
    assert MACHINE_PATH.search('DATA = Path("/work/shared/data/real/silverbox")')
    assert MACHINE_PATH.search("p = '/home/me/data.mat'")
    assert not MACHINE_PATH.search('p = Path("../shared") / "data"')


def test_shared_dir_from_the_environment_variable(tmp_path, monkeypatch):
    (tmp_path / "data" / "real" / "f16").mkdir(parents=True)
    monkeypatch.setenv(shared.ENV, str(tmp_path))
    assert shared.shared_dir() == tmp_path
    assert shared.real_data("f16") == tmp_path / "data" / "real" / "f16"
    assert shared.real_data("silverbox") is None


def test_shared_dir_set_but_absent_is_not_replaced_by_a_guess(tmp_path, monkeypatch):
    monkeypatch.setenv(shared.ENV, str(tmp_path / "nowhere"))
    assert shared.shared_dir() == tmp_path / "nowhere" and shared.real_data() is None


def test_shared_dir_found_above_the_working_directory(tmp_path, monkeypatch):
    monkeypatch.delenv(shared.ENV, raising=False)
    (tmp_path / "shared").mkdir()
    (tmp_path / "repo" / "examples").mkdir(parents=True)
    monkeypatch.chdir(tmp_path / "repo" / "examples")
    assert shared.shared_dir() == tmp_path / "shared"


def test_default_beside_a_checkout_only_when_unset(tmp_path, monkeypatch):
    monkeypatch.delenv(shared.ENV, raising=False)
    (tmp_path / "shared").mkdir()
    shared.default_beside(tmp_path / "repo")
    assert shared.shared_dir() == tmp_path / "shared"
    monkeypatch.setenv(shared.ENV, "elsewhere")
    shared.default_beside(tmp_path / "repo")
    assert shared.shared_dir() == Path("elsewhere")

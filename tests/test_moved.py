"""Module paths that moved in issue 48 still answer for one release, with a DeprecationWarning."""
from __future__ import annotations

import importlib
import sys

import pytest

from satmd import _moved


@pytest.mark.parametrize("old", sorted(_moved.MODULES))
def test_an_old_module_path_is_the_new_module_and_warns(old):
    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning, match=f"{old} is now {_moved.MODULES[old]}"):
        module = importlib.import_module(old)
    assert module is importlib.import_module(_moved.MODULES[old])
    assert module.__spec__.name == module.__name__ == _moved.MODULES[old]  # the new module is left as it was
    sys.modules.pop(old, None)


@pytest.mark.parametrize("name", sorted(_moved.NAMES["satmd.io"]))
def test_a_name_satmd_io_gave_is_the_moved_one_and_warns(name):
    import satmd.io

    satmd.io.__dict__.pop(name, None)
    with pytest.warns(DeprecationWarning, match=f"satmd.io.{name} is now"):
        value = getattr(satmd.io, name)
    assert value is getattr(importlib.import_module(_moved.NAMES["satmd.io"][name]), name)
    satmd.io.__dict__.pop(name, None)


def test_an_unknown_name_is_still_an_attribute_error():
    import satmd.io

    with pytest.raises(AttributeError, match="no attribute 'nothing_here'"):
        satmd.io.nothing_here  # noqa: B018


def test_the_public_names_did_not_move():
    import satmd
    from satmd.signal import estimate_frf
    from satmd.simulation import simulate

    assert satmd.estimate_frf is estimate_frf and satmd.simulate is simulate


def test_satmd_itself_uses_no_moved_path():
    """The aliases are for users' scripts: the package, tests, benchmarks and examples use the new paths."""
    import ast
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    moved_names = {(pkg, n) for pkg, names in _moved.NAMES.items() for n in names}
    bad = []
    for folder in ("satmd", "tests", "benchmarks", "examples"):
        for path in (root / folder).rglob("*.py"):
            if path.name in ("_moved.py", "test_moved.py"):
                continue
            parts = path.relative_to(root).with_suffix("").parts
            package = ".".join(parts[:-1] if parts[-1] == "__init__" else parts[:-1])
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.ImportFrom):
                    base = package.split(".")
                    target = ".".join(base[:len(base) - node.level + 1] + ([node.module] if node.module else [])) \
                        if node.level else node.module
                    if target in _moved.MODULES or any((target, a.name) in moved_names for a in node.names):
                        bad.append(f"{path.relative_to(root)}:{node.lineno}: from {target} import ...")
                elif isinstance(node, ast.Import):
                    bad += [f"{path.relative_to(root)}:{node.lineno}: import {a.name}" for a in node.names
                            if a.name in _moved.MODULES]
    assert not bad, "moved paths used (see satmd/_moved.py for the new ones):\n" + "\n".join(bad)

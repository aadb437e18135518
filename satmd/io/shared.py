"""Where the shared data lie: one rule for the tests, benchmarks, examples and the report.

The project's real third-party files and acceptance data live in a folder ``shared`` beside
the repository (``../shared`` from its root). `shared_dir` finds it:

1. the environment variable ``SATMD_SHARED``, when set (taken as given, even if absent, so
   a wrong setting is reported where it is used, not replaced by a guess);
2. ``shared`` in the working directory or one of its parents (from a checkout's root,
   ``../shared``; from its ``examples/``, ``../../shared``).

The package never looks at the folders around its own files (an installed package has no
repository around it): the tests, benchmarks and examples, which do live in the checkout, set
``SATMD_SHARED`` to ``../shared`` beside it when it is unset. No path of one machine is
written anywhere (a test fails on one).
"""
from __future__ import annotations

import os
from pathlib import Path

#: The environment variable that names the shared folder.
ENV = "SATMD_SHARED"


def shared_dir() -> Path | None:
    """The shared folder (module docstring), or None when there is none."""
    given = os.environ.get(ENV)
    if given:
        return Path(given).expanduser()
    here = Path.cwd().resolve()
    for root in (here, *here.parents):
        if (root / "shared").is_dir():
            return root / "shared"
    return None


def shared_path(*parts: str) -> Path | None:
    """``shared_dir() / parts...`` when that file or folder exists, else None."""
    root = shared_dir()
    if root is None:
        return None
    path = root.joinpath(*parts)
    return path if path.exists() else None


def default_beside(checkout) -> None:
    """Set ``SATMD_SHARED`` to ``shared`` beside ``checkout`` (a repository's root) when it is unset
    and that folder exists: for the code that lives in a checkout (tests, benchmarks, examples)."""
    beside = Path(checkout).resolve().parent / "shared"
    if not os.environ.get(ENV) and beside.is_dir():
        os.environ[ENV] = str(beside)


def real_data(*parts: str) -> Path | None:
    """A file or folder of ``shared/data/real`` (the third-party measurements), or None."""
    return shared_path("data", "real", *parts)

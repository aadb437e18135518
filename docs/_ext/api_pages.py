"""The API reference's pages, written from the package's ``__all__`` lists at the start of each build.

One page per public module: ``satmd`` (every name of ``satmd.__all__``) and each subpackage that has
an ``__all__``. A subpackage's page documents the names it adds; a name that is the same object as
one of ``satmd.__all__`` is listed there with a link to its page under ``satmd``. Each name gets its
own page through autosummary (``api/generated/``). Nothing here is typed by hand, so a new public
name appears in the reference without an edit, and `tests/test_docs.py` checks that none is missing.
"""
from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path

HEADER = ".. This page is written by docs/_ext/api_pages.py at every build: do not edit it.\n\n"


def public_modules():
    """[(module name, [public names])]: satmd first, then each subpackage with an ``__all__``."""
    import satmd

    out = [("satmd", list(satmd.__all__))]
    for info in sorted(pkgutil.iter_modules(satmd.__path__), key=lambda m: m.name):
        if not info.ispkg or info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"satmd.{info.name}")
        names = getattr(mod, "__all__", None)
        if names:
            out.append((mod.__name__, list(names)))
    return out


def _title(text: str, char: str = "=") -> str:
    return f"{text}\n{char * len(text)}\n"


def write(api_dir: Path) -> list[str]:
    """Write ``api_dir/<module>.rst`` for every public module; return the module names."""
    import satmd

    top = {id(getattr(satmd, n)): n for n in satmd.__all__ if not isinstance(getattr(satmd, n), (str, int, float))}
    api_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for modname, names in public_modules():
        mod = importlib.import_module(modname)
        own, shared = [], []
        for name in names:
            obj = getattr(mod, name)
            if modname != "satmd" and id(obj) in top:
                shared.append((name, top[id(obj)]))
            else:
                own.append(name)
        lines = [HEADER, _title(f"``{modname}``"), "", f".. automodule:: {modname}", "   :no-members:", "",
                 f".. currentmodule:: {modname}", ""]
        if shared:
            refs = ", ".join(f":py:obj:`{name} <satmd.{target}>`" for name, target in shared)
            lines += ["Also public here, documented under ``satmd``: " + refs + ".", ""]
        if own:
            lines += [_title("Public names", "-"), "", ".. autosummary::", "   :toctree: generated/", ""]
            lines += [f"   {name}" for name in own]
            lines.append("")
        path = api_dir / f"{modname}.rst"
        text = "\n".join(lines)
        if not path.is_file() or path.read_text(encoding="utf-8") != text:  # unchanged pages keep their mtime
            path.write_text(text, encoding="utf-8")
        written.append(modname)
    return written

"""`satmd reproduce`: the paper's results and satmd's extensions as one report.

Each module ``satmd/report/sec_*.py`` is a section: it defines ``ORDER``
(position), ``TITLE`` and ``build(ctx) -> markdown``. A new capability adds
its section as one new file. The report is written as ``index.md`` and
``index.html`` with figures under ``figures/``.
"""
from __future__ import annotations

import importlib
import json
import pkgutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from .html import markdown_to_html


@dataclass
class Context:
    out: Path
    quick: bool = False
    results: dict = field(default_factory=dict)  # numbers a section wants kept in results.json
    shared: dict = field(default_factory=dict)  # objects later sections may reuse (e.g. a trained net)

    @property
    def fig_dir(self) -> Path:
        return self.out / "figures"

    def figure(self, fig, name: str) -> str:
        """Save a matplotlib figure; returns the markdown image link."""
        from ..plots import save

        save(fig, self.fig_dir / name)
        return f"![{name}](figures/{name})"


def sections():
    mods = [importlib.import_module(f"{__name__}.{m.name}")
            for m in pkgutil.iter_modules(__path__) if m.name.startswith("sec_")]
    return sorted(mods, key=lambda m: m.ORDER)


def reproduce(out, only=None, quick=False, log=print) -> Path:
    """Build the report in folder ``out``; returns the path of index.md."""
    ctx = Context(Path(out), quick=quick)
    ctx.fig_dir.mkdir(parents=True, exist_ok=True)
    parts = ["# satmd report", "",
             "Produced by `satmd reproduce`: every number and figure below is computed by this run.", ""]
    for mod in sections():
        key = mod.__name__.rsplit(".sec_", 1)[-1]
        if only and key not in only:
            continue
        t0 = time.perf_counter()
        log(f"[satmd reproduce] {mod.TITLE} ...")
        body = mod.build(ctx)
        dt = time.perf_counter() - t0
        parts += [f"## {mod.TITLE}", "", body.strip(), "", f"*(section computed in {dt:.1f} s)*", ""]
        sys.stdout.flush()
    md = "\n".join(parts)
    index = ctx.out / "index.md"
    from ..io.atomic import all_or_none, atomic_write

    with all_or_none():
        for name, text in ((index.name, md), ("index.html", markdown_to_html(md, title="satmd report")),
                           ("results.json", json.dumps(ctx.results, indent=2, default=float))):
            with atomic_write(ctx.out / name, "w") as fh:
                fh.write(text)
    return index

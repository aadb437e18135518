"""`satmd reproduce`: the paper's results and satmd's extensions as one report.

Each module ``satmd/report/sec_*.py`` is a section: it defines ``ORDER``
(position), ``TITLE`` and ``build(ctx) -> markdown``. A new capability adds
its section as one new file. The report is written as ``index.md`` and
``index.html`` with figures under ``figures/``.
"""
from __future__ import annotations

import contextlib
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
    failed: dict = field(default_factory=dict)  # section key -> one-line reason it failed
    acceptance: Path | None = None  # a folder of independent acceptance data (e.g. discovery/), given by the caller

    fig_tmp: Path | None = None  # figures are written here and swapped in when the report is complete

    @property
    def fig_dir(self) -> Path:
        return self.fig_tmp if self.fig_tmp is not None else self.out / "figures"

    def figure(self, fig, name: str) -> str:
        """Save a matplotlib figure; returns the markdown image link."""
        from ..plots import save

        save(fig, self.fig_dir / name)
        return f"![{name}](figures/{name})"


def section_failure(exc: BaseException) -> str:
    """One line saying why a section failed: the error's type and the first line of its message,
    and where in satmd it was raised."""
    import traceback

    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "satmd" in f.filename]
    where = f" (in {Path(frames[-1].filename).name}:{frames[-1].lineno}, {frames[-1].name})" if frames else ""
    message = (str(exc).strip().splitlines() or [""])[0][:300]
    return f"{type(exc).__name__}: {message}{where}" if message else f"{type(exc).__name__}{where}"


def sections():
    """The report's sections (each module of `satmd.report.parts`), in report order."""
    from . import parts as package

    mods = [importlib.import_module(f"{package.__name__}.{m.name}") for m in pkgutil.iter_modules(package.__path__)]
    return sorted(mods, key=lambda m: m.ORDER)


def section_keys() -> list[str]:
    """The keys `reproduce(only=...)` takes, in report order."""
    return [m.__name__.rsplit(".", 1)[-1] for m in sections()]


def reproduce(out, only=None, quick=False, log=print, acceptance=None) -> Path:
    """Build the report in folder ``out``; returns the path of index.md.

    Parameters
    ----------
    out : str or Path
        The report folder (created when missing, with its parents).
    only : list of str, optional
        Section keys to compute (`section_keys`); an unknown key is refused.
    quick : bool
        Smaller runs (smoke tests).
    log : callable
        Progress lines.
    acceptance : str or Path, optional
        A folder of acceptance data made independently of satmd (with a
        ``discovery/`` folder of FRFs and ``truth.json``); sections that find
        their part in it report on it too. None: none (the package never looks
        for data outside itself).

    Returns
    -------
    Path
        ``out/index.md``. Nothing in ``out`` changes until every section is
        computed: figures are written to a temporary folder and swapped in with
        ``index.md``, ``index.html`` and ``results.json`` (all or none), so an
        interrupted run leaves the previous report intact. A section that fails
        says why in one line in its place; the others and the report are still
        written, and `IncompleteReport` is raised after.
    """
    from ..errors import DataError
    from ..io.atomic import all_or_none, atomic_dir, atomic_write

    keys = section_keys()
    if only is not None:
        only = [str(k).strip() for k in only]
        unknown = [k for k in only if k not in keys]
        if unknown or not only:
            raise DataError(f"only: unknown section {', '.join(map(repr, unknown)) or '(none given)'}; "
                            f"choose from {', '.join(keys)}")
    ctx = Context(Path(out), quick=quick, acceptance=None if acceptance is None else Path(acceptance))
    created = [p for p in [ctx.out, *ctx.out.parents] if not p.exists()]
    ctx.out.mkdir(parents=True, exist_ok=True)
    try:
        with all_or_none(), atomic_dir(ctx.out / "figures") as figs:
            ctx.fig_tmp = figs
            md = _build(ctx, only, log)
            if ctx.failed:
                ctx.results["failed_sections"] = dict(ctx.failed)
            for name, text in (("index.md", md), ("index.html", markdown_to_html(md, title="satmd report")),
                               ("results.json", json.dumps(ctx.results, indent=2, default=float))):
                with atomic_write(ctx.out / name, "w") as fh:
                    fh.write(text)
    except BaseException:
        for p in created:  # folders this run created, left empty
            with contextlib.suppress(OSError):
                p.rmdir()
        raise
    finally:
        ctx.fig_tmp = None
    if ctx.failed:
        raise IncompleteReport(ctx.out / "index.md", dict(ctx.failed))
    return ctx.out / "index.md"


class IncompleteReport(RuntimeError):
    """The report was written, but some sections failed (each says why in the report, in one line).

    Attributes
    ----------
    index : Path of the written ``index.md``
    failed : section key -> one-line reason
    """

    def __init__(self, index: Path, failed: dict):
        self.index, self.failed = index, failed
        lines = "; ".join(f"{k}: {v}" for k, v in failed.items())
        super().__init__(f"report written to {index}, but {len(failed)} section(s) failed: {lines}")


def _build(ctx, only, log) -> str:
    parts = ["# satmd report", "",
             "Produced by `satmd reproduce`: every number and figure below is computed by this run.", ""]
    for mod in sections():
        key = mod.__name__.rsplit(".", 1)[-1]
        if only and key not in only:
            continue
        t0 = time.perf_counter()
        log(f"[satmd reproduce] {mod.TITLE} ...")
        try:
            body = mod.build(ctx)
        except Exception as exc:  # one failing section must not lose the others (Ctrl-C still stops)
            reason = section_failure(exc)
            ctx.failed[key] = reason
            log(f"[satmd reproduce] {mod.TITLE} FAILED: {reason}")
            body = f"**This section failed:** {reason}"
        dt = time.perf_counter() - t0
        parts += [f"## {mod.TITLE}", "", body.strip(), "", f"*(section computed in {dt:.1f} s)*", ""]
        sys.stdout.flush()
    return "\n".join(parts)

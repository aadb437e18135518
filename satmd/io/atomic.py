"""Atomic output: every file satmd writes goes through `atomic_write`, several at once through `all_or_none`.

An interrupted or failed write never leaves a half-written file or a ``.tmp``
file behind, and a command with several outputs writes all of them or none.
"""
from __future__ import annotations

import contextlib
import contextvars
import os
from pathlib import Path

from ..errors import FormatError

# Inside `all_or_none()`, finished temporary files wait here and are renamed
# together at the end, so a command with several outputs writes all or none.
_PENDING = contextvars.ContextVar("satmd_pending_writes", default=None)


@contextlib.contextmanager
def atomic_write(path, mode: str = "wb"):
    """Open a temporary file next to ``path``; on success it replaces ``path``, on failure it is removed.

    Every satmd writer goes through here, so an interrupted or failed write
    never leaves a half-written file or a ``.tmp`` file behind.
    ``mode`` is "wb" or "w" (UTF-8 text).
    """
    path = Path(path)
    if path.is_dir():
        raise FormatError(path, "is a directory; give a file name")
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, mode, **({"encoding": "utf-8", "newline": "\n"} if "b" not in mode else {})) as fh:
            yield fh
        pending = _PENDING.get()
        if pending is None:
            os.replace(tmp, path)
        else:
            pending.append((tmp, path))
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError) and exc.errno is not None:  # name the output, not its temporary file
            raise OSError(exc.errno, exc.strerror, str(path)) from None
        raise


@contextlib.contextmanager
def all_or_none():
    """Defer the final renames of every `atomic_write` in the block: all outputs appear, or none."""
    if _PENDING.get() is not None:  # nested: the outer block commits
        yield
        return
    token = _PENDING.set([])
    pending = _PENDING.get()
    try:
        yield
    except BaseException:
        for tmp, _ in pending:
            with contextlib.suppress(OSError):
                tmp.unlink()
        raise
    else:
        try:
            for tmp, path in pending:
                os.replace(tmp, path)
        finally:
            for tmp, _ in pending:
                with contextlib.suppress(OSError):
                    tmp.unlink()
    finally:
        _PENDING.reset(token)


__all__ = ["all_or_none", "atomic_write"]

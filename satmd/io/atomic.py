"""Atomic output: every file satmd writes goes through `atomic_write`, several at once through `all_or_none`.

An interrupted or failed write never leaves a half-written file or a ``.tmp``
file behind, and a command with several outputs writes all of them or none:

- a temporary file (or folder, `atomic_dir`) is written next to its target
  and renamed over it only when complete;
- while temporary files exist, SIGTERM and SIGHUP raise `SystemExit` (as
  Ctrl-C raises `KeyboardInterrupt`), so the clean-up below runs on a kill
  too; the previous handlers come back when the last temporary file is gone;
- the final renames run with those signals blocked, so an interruption sees
  the old outputs or the new ones, never a mixture;
- temporary names stay within the file system's name limit (NAME_MAX),
  however long the target's name.
"""
from __future__ import annotations

import atexit
import contextlib
import contextvars
import hashlib
import os
import shutil
import signal
import threading
from pathlib import Path

from ..errors import FormatError

# Inside `all_or_none()`, finished temporary files wait here and are renamed
# together at the end, so a command with several outputs writes all or none.
_PENDING = contextvars.ContextVar("satmd_pending_writes", default=None)
_LIVE: dict = {}  # temporary path -> True while it may exist
_LOCK = threading.RLock()
_SIGNALS = tuple(getattr(signal, n) for n in ("SIGTERM", "SIGHUP") if hasattr(signal, n))
_SAVED: dict = {}  # signal -> handler before ours
NAME_MAX = 255


def _raise_exit(signum, frame):  # noqa: ARG001 - signal handler signature
    raise SystemExit(128 + signum)


def _track(tmp: Path):
    """Register a temporary path; the first one installs the signal handlers (main thread only)."""
    with _LOCK:
        _LIVE[tmp] = True
        if len(_LIVE) == 1 and threading.current_thread() is threading.main_thread():
            for sig in _SIGNALS:
                with contextlib.suppress(ValueError, OSError):
                    if signal.getsignal(sig) == signal.SIG_DFL:
                        _SAVED[sig] = signal.signal(sig, _raise_exit)


def _untrack(tmp: Path):
    with _LOCK:
        _LIVE.pop(tmp, None)
        if not _LIVE and threading.current_thread() is threading.main_thread():
            for sig, old in list(_SAVED.items()):
                with contextlib.suppress(ValueError, OSError):
                    if signal.getsignal(sig) is _raise_exit:
                        signal.signal(sig, old)
                _SAVED.pop(sig, None)


def _remove(tmp: Path):
    with contextlib.suppress(OSError):
        if tmp.is_dir() and not tmp.is_symlink():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink()
    _untrack(tmp)


@atexit.register
def _remove_all():
    """Whatever is still registered when the interpreter exits (an exception nobody caught)."""
    for tmp in list(_LIVE):
        _remove(tmp)


@contextlib.contextmanager
def _signals_blocked():
    """Block SIGINT, SIGTERM and SIGHUP around the final renames (main thread, where supported)."""
    block = {signal.SIGINT, *_SIGNALS}
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, block)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def temp_name(path: Path, tag: str = "tmp") -> Path:
    """``.NAME.PID.tmp`` next to ``path``, shortened (with a hash of the name) to fit NAME_MAX bytes."""
    path = Path(path)
    suffix = f".{os.getpid()}.{tag}"
    name = f".{path.name}{suffix}"
    if len(name.encode("utf-8", "surrogateescape")) > NAME_MAX:
        digest = hashlib.sha1(path.name.encode("utf-8", "surrogateescape")).hexdigest()[:12]
        keep = path.name.encode("utf-8", "surrogateescape")[:NAME_MAX - len(suffix) - 16]
        name = "." + keep.decode("utf-8", "ignore") + "~" + digest + suffix
    return path.with_name(name)


def _commit(tmp: Path, path: Path):
    """Put the finished ``tmp`` in place of ``path`` (a folder: the old one is swapped out, then removed)."""
    if tmp.is_dir():
        old = None
        if path.is_dir():
            old = temp_name(path, "old")
            os.replace(path, old)
        os.replace(tmp, path)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(tmp, path)
    _untrack(tmp)


@contextlib.contextmanager
def atomic_write(path, mode: str = "wb"):
    """Open a temporary file next to ``path``; on success it replaces ``path``, on failure it is removed.

    Every satmd writer goes through here, so an interrupted (Ctrl-C, SIGTERM)
    or failed write never leaves a half-written file or a ``.tmp`` file behind.
    ``mode`` is "wb" or "w" (UTF-8 text).
    """
    path = Path(path)
    if path.is_dir():
        raise FormatError(path, "is a directory; give a file name")
    tmp = temp_name(path)
    _track(tmp)
    try:
        text = "b" not in mode
        with open(tmp, mode, encoding="utf-8" if text else None, newline="\n" if text else None) as fh:
            yield fh
        _commit_or_defer(tmp, path)
    except BaseException as exc:
        _remove(tmp)
        if isinstance(exc, OSError) and exc.errno is not None:  # name the output, not its temporary file
            raise OSError(exc.errno, exc.strerror, str(path)) from None
        raise


def _commit_or_defer(tmp: Path, path: Path) -> None:
    """Move ``tmp`` onto ``path`` now (signals blocked), or inside `all_or_none` at its end."""
    pending = _PENDING.get()
    if pending is None:
        with _signals_blocked():
            _commit(tmp, path)
    else:
        pending.append((tmp, path))


@contextlib.contextmanager
def atomic_dir(path):
    """A temporary folder next to folder ``path``; on success it replaces ``path`` (old contents removed).

    Inside `all_or_none` the swap waits for the block's end with the other outputs.
    The parent folder must exist.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise FormatError(path, "exists and is not a folder")
    tmp = temp_name(path)
    _track(tmp)
    try:
        tmp.mkdir()
        yield tmp
        _commit_or_defer(tmp, path)
    except BaseException:
        _remove(tmp)
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
            _remove(tmp)
        raise
    else:
        try:
            with _signals_blocked():
                for tmp, path in pending:
                    _commit(tmp, path)
        finally:
            for tmp, _ in pending:
                if tmp in _LIVE:
                    _remove(tmp)
    finally:
        _PENDING.reset(token)


__all__ = ["NAME_MAX", "all_or_none", "atomic_dir", "atomic_write", "temp_name"]

"""Ctrl-C on the command line: one line on stderr, exit status 130, never a traceback.

Light on purpose (the standard library only): the ``satmd`` command installs
this before it imports numpy, scipy or any command, so an interruption while
they load is handled like any other.
"""
from __future__ import annotations

import _thread
import contextlib
import signal
import sys
import time

INTERRUPTED = 130  # 128 + SIGINT, the status a shell reports for a command ended by Ctrl-C
GRACE_S = 1.0  # a second Ctrl-C this soon after the first is not acted on: the clean-up the first started finishes

_first: list = [None]  # time.monotonic() of this command's first Ctrl-C, or None
_caller_hook: list = [sys.unraisablehook]  # the unraisable-exception hook ours stands in front of


def _on_sigint(signum, frame):  # noqa: ARG001 - signal handler signature
    now = time.monotonic()
    if _first[0] is not None and now - _first[0] < GRACE_S:
        return  # a double press: the first is already ending the command
    _first[0] = now
    raise KeyboardInterrupt


def _on_unraisable(unraisable):
    """A Ctrl-C raised where Python cannot raise (a weakref callback, a ``__del__``) is delivered again, not printed.

    Python would print it as "Exception ignored in ..." with a traceback and
    carry on, the press lost. Pressed again from another thread, it reaches
    the main thread's next steps (from this one it would land in this hook,
    where it cannot be raised either).
    """
    if unraisable.exc_type is not None and issubclass(unraisable.exc_type, KeyboardInterrupt):
        _first[0] = None  # not a second press: the first one never arrived
        _thread.start_new_thread(_thread.interrupt_main, (signal.SIGINT,))
        return
    _caller_hook[0](unraisable)


@contextlib.contextmanager
def catching_interrupts(exiting: bool = False):
    """Within the block, Ctrl-C raises `KeyboardInterrupt` once; another within `GRACE_S` s is ignored.

    Installed only from the main thread and only over Python's default
    handler (a SIGINT the caller ignores, e.g. a background job's, or handles
    itself is left to the caller). A `KeyboardInterrupt` that escapes the
    block is reported by `interrupted` and not raised further. When the block
    was not interrupted the caller's handler is put back. After an
    interruption ours stays (past `GRACE_S` it raises as Python's would), and
    with ``exiting`` (the ``satmd`` program itself, whose process ends next)
    the process ends here, by `_exit_now`: a press while the interpreter
    shuts down can then neither print a traceback nor kill it mid-way. With
    ``exiting`` and no interruption, a press after the work is done is
    ignored: CPython resets its own handler to the signal's default as it
    shuts down, and the press would kill the process by SIGINT, not with the
    command's status.
    """
    installed = None
    with contextlib.suppress(ValueError, OSError):  # ValueError: not the main thread, where no handler can be set
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            installed = signal.signal(signal.SIGINT, _on_sigint)
            _caller_hook[0], sys.unraisablehook = sys.unraisablehook, _on_unraisable
    _first[0] = None
    try:
        yield
    except KeyboardInterrupt:  # after the command's own `except`: still one line, no traceback
        interrupted()
    finally:
        if installed is not None:
            sys.unraisablehook = _caller_hook[0]
        if installed is not None and _first[0] is None:
            with contextlib.suppress(ValueError, OSError):
                signal.signal(signal.SIGINT, signal.SIG_IGN if exiting else installed)
        elif installed is not None and exiting:
            _exit_now()


def _exit_now():
    """End the process with status 130 now, Ctrl-C ignored: `atexit` callbacks run and the streams are flushed.

    The interpreter's own shutdown is skipped: after a Ctrl-C inside some
    compiled modules' import (scipy's) CPython takes the interrupt for an
    unhandled one, however it was handled, and ends the process by SIGINT
    instead of the status asked for.
    """
    import atexit
    import os

    with contextlib.suppress(ValueError, OSError):
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(Exception):
        atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(INTERRUPTED)


def interrupted() -> int:
    """Say ``satmd: interrupted`` on stderr (once, whatever stderr is) and return the exit status, 130."""
    if _first[0] is None:  # raised by other means than our handler: a press right after is still ignored
        _first[0] = time.monotonic()
    with contextlib.suppress(OSError, ValueError, AttributeError):
        sys.stderr.write("satmd: interrupted\n")
        sys.stderr.flush()
    return INTERRUPTED

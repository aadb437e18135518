"""Progress of long work on stderr: a tqdm bar on a terminal, a line every few seconds otherwise.

Logs and CI see periodic lines instead of nothing (a bar there would be one
endless line of carriage returns).
"""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from contextvars import ContextVar


class LineProgress:
    """The part of tqdm's interface satmd uses, printing ``desc: k/total unit (..)`` lines."""

    def __init__(self, total: int, desc: str, unit: str, every: float = 10.0):
        self.total, self.desc, self.unit, self.every = total, desc, unit, every
        self.n, self.postfix = 0, ""
        self.t0 = self.last = time.perf_counter()

    def set_postfix(self, values: dict, refresh: bool = False):
        self.postfix = ", ".join(f"{k}={v}" for k, v in values.items())

    def update(self, n: int = 1):
        self.n += n
        now = time.perf_counter()
        if now - self.last >= self.every or self.n == self.total:
            self.last = now
            extra = f", {self.postfix}" if self.postfix else ""
            print(f"{self.desc}: {self.n}/{self.total} {self.unit} ({now - self.t0:.0f} s{extra})",
                  file=sys.stderr, flush=True)

    def close(self):
        pass


def progress(total: int, desc: str, unit: str = "it", enabled: bool = True):
    """A progress object with update / set_postfix / close, or None when ``enabled`` is false."""
    if not enabled:
        return None
    if sys.stderr.isatty():
        try:
            from tqdm.auto import tqdm
        except ImportError:  # tqdm comes with the nn extra
            pass
        else:
            return tqdm(total=total, desc=desc, unit=unit, leave=False)
    return LineProgress(total, desc, unit)


# --- stages of long work, told to whoever listens (the CLI prints them on stderr) ----------------------
_SINK: ContextVar = ContextVar("satmd_stage_sink", default=None)


@contextmanager
def stages(sink):
    """Within the block, `stage` tells ``sink`` (callable(str)) what long work is doing; nothing otherwise, so a
    library call stays silent unless its caller asked (``satmd discover`` on a structure's levels does)."""
    token = _SINK.set(sink)
    try:
        yield
    finally:
        _SINK.reset(token)


def stage(text: str) -> None:
    """Tell the listener of `stages`, if any, what is being done now."""
    sink = _SINK.get()
    if sink is not None:
        sink(text)

"""Memory the forward model reuses: scratch buffers across chunks and calls, and output blocks.

Most of the NumPy forward model's time is spent moving complex arrays, and fresh memory costs the
kernel time before anything is written: every page of a new allocation is zeroed on first touch.
For 10⁴ rigs x 60 frequencies (issue 36) the five channels' 48 MB took 4-5 ms of a ~18 ms call that
way, the chunks' scratch buffers another ~0.5 ms. So:

* `Workspace`: the scratch buffers of one thread, kept from chunk to chunk;
* `kept_workspace`: a thread's workspace kept from one call to the next;
* `OutputPool`: the block that holds a call's results is taken back for a later call once the caller
  has let go of every array in it (the memory is then still mapped: no page is zeroed again). A
  result the caller still holds is never touched; at most four blocks and 512 MB are kept
  (`OUTPUTS.clear()` lets go of them).

Nothing here changes a value: every element of a reused buffer or block is written before it is read.
"""
from __future__ import annotations

import contextlib
import math
import sys
import threading

import numpy as np


class Workspace:
    """Scratch buffers of one worker thread, kept across chunks (and, through `kept_workspace`, across calls)."""

    def __init__(self):
        self._buffers = {}
        self._views = {}
        self._tiles = {}
        self._frequency_tiles = {}

    def get(self, name, shape, dtype=complex):
        """The scratch array ``name`` of ``shape`` (its contents are whatever was left there; a new
        buffer starts as zeros, so a complex one of which only ``.real`` is ever written stays real)."""
        view = self._views.get((name, shape))
        if view is None:
            size = math.prod(shape)
            buf = self._buffers.get(name)
            if buf is None or buf.size < size:
                if buf is not None:  # outgrown: let go of everything that still points into the old buffer
                    self._forget(name)
                buf = self._buffers[name] = np.zeros(size, dtype=dtype)
            view = self._views[name, shape] = buf[:size].reshape(shape)
        return view

    @property
    def nbytes(self) -> int:
        """Bytes held in scratch buffers."""
        return sum(b.nbytes for b in self._buffers.values())

    def _forget(self, name):  # kept tiles have a buffer per shape, which never grows: only views point here
        self._views = {k: v for k, v in self._views.items() if k[0] != name}

    def tile(self, name, shape, make, omega, *fields, dtype=complex):
        """``make()``, a function of ``omega`` and the rig's ``fields``, as an array of the chunk's ``shape``,
        made once and kept while ``omega`` (the same object) and the fields (scalars) stay the same: a
        frequency-only quantity costs nothing per chunk. A field that varies by row (an array) makes it
        vary by row: made each time, not kept. Exact."""
        if any(isinstance(x, np.ndarray) for x in fields):
            return make()
        kept = self._frequency_tiles.get((name, shape))
        if kept is None or kept[0] is not omega or kept[1] != fields:
            tiled = self.get(f"frequency {name} {shape}", shape, dtype)  # its own buffer: see `full`
            tiled[...] = make()
            kept = self._frequency_tiles[name, shape] = (omega, fields, tiled)  # omega held: its id stays its own
        return kept[2]

    def full(self, name, x, shape, dtype=complex):
        """``x`` as an array of the chunk's ``shape``. A quantity that
        varies along frequency only (the same in every chunk) is broadcast once
        and kept while it does not change: operations on whole contiguous
        arrays run several times faster than on broadcast ones. Exact."""
        if not isinstance(x, np.ndarray) or x.ndim != 1:
            return x
        key = (x.dtype.str, x.tobytes())  # ~1 KB: cheaper to compare than anything else
        cached = self._tiles.get((name, shape))
        if cached is None or cached[0] != key:
            # a buffer of its own for each shape: views of one buffer in two shapes overlap, and a kept tile
            # would be overwritten by the other shape's (the last, shorter chunk; the next call's rows)
            cached = self._tiles[name, shape] = (key, self.get(f"{name} {shape}", shape, dtype))
            cached[1][...] = x
        return cached[1]


#: a thread keeps its workspace between calls only while it holds at most this many bytes (ordinary chunks
#: hold a few MB; a call with 10⁶ frequencies would otherwise keep hundreds) and buffers (kept tiles have one
#: per chunk shape: calls on many grids would otherwise pile them up)
_KEPT_BYTES = 32 * 2**20
_KEPT_BUFFERS = 512
_kept = threading.local()


@contextlib.contextmanager
def kept_workspace():
    """This thread's `Workspace`, kept from one `model.frf` call to the next: its scratch buffers are
    already allocated and in memory (a new workspace's first touch of them cost ~1 ms of a 10⁴ x 60 call).
    A call made while it is lent out (a call inside a call) gets a new one. The kernels' results do not
    depend on what a buffer held before (the same bits, tests/physics/test_plain_kernels.py)."""
    work = getattr(_kept, "work", None)
    _kept.work = None
    work = Workspace() if work is None else work
    try:
        yield work
    finally:
        if work.nbytes <= _KEPT_BYTES and len(work._buffers) <= _KEPT_BUFFERS:
            _kept.work = work


class OutputPool:
    """Spare result blocks, handed out again once nothing outside the pool refers to them.

    A block returned to a caller lives on in the pool; when a later call asks for an array that fits
    in it (at least as large, at most twice), the pool's reference count on the block says whether any
    array of the earlier result (or a view of one, or anything holding a view) is still alive. Only if
    none is, the block is reused: its pages are already mapped. At most `max_blocks` blocks and
    `max_bytes` bytes are kept, the least recently used let go first; `clear` lets go of them all.
    Thread-safe: a block is lent to one call at a time.
    """

    max_blocks = 4  # a Jacobian call uses two (values, Jacobian): two kinds of call alternating reuse all four
    max_bytes = 512 * 2**20
    min_bytes = 2**20  # smaller arrays come from the allocator's heap, already mapped: nothing to gain

    def __init__(self):
        self._lock = threading.Lock()
        self._spare: list = []  # flat blocks, least recently used first; the list's reference is the only one when free
        probe = [np.empty(1)]
        self._free_refs = sys.getrefcount(probe[0])  # this interpreter's count for "held by the list alone"

    def empty(self, shape, dtype=complex) -> np.ndarray:
        """An uninitialised array of ``shape`` (like `numpy.empty`): a view of a free spare block that fits,
        else of a new one. Give it back with `keep` once it is the caller's."""
        dtype = np.dtype(dtype)
        size = math.prod(shape)
        if size * dtype.itemsize < self.min_bytes:
            return np.empty(shape, dtype)
        with self._lock:
            fits = [i for i in range(len(self._spare))  # by index: a name bound to a block would count as a holder
                    if self._spare[i].dtype == dtype and size <= self._spare[i].size <= 2 * size
                    and sys.getrefcount(self._spare[i]) == self._free_refs]
            block = self._spare.pop(min(fits, key=lambda i: self._spare[i].size)) if fits else None
        if block is None:
            block = np.empty(size, dtype)
        return block[:size].reshape(shape)

    def keep(self, array: np.ndarray) -> None:
        """Keep the block under ``array`` (made by `empty`, now handed to a caller) as a spare."""
        block = array.base
        if block is None or block.ndim != 1 or not self.min_bytes <= block.nbytes <= self.max_bytes:
            return
        with self._lock:
            self._spare = [b for b in self._spare if b is not block] + [block]
            while len(self._spare) > self.max_blocks or sum(b.nbytes for b in self._spare) > self.max_bytes:
                self._spare.pop(0)

    def clear(self) -> None:
        """Let go of every spare block (memory of results no longer held goes back to the system)."""
        with self._lock:
            self._spare = []


#: the pool of `model.frf`'s value and Jacobian blocks
OUTPUTS = OutputPool()

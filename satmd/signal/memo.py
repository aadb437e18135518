"""Each recording analysed once: a small memo of the costly per-recording steps, keyed by content.

Several stages of `discover` read the same recording (its FRF estimate, the model error of that
estimate, the distortion test's linear prediction, the nonlinear fit's band): before this memo the
force's excited band was found 15 times and the local polynomial fit run 8 times on two recordings
(issue 36). The stages ask for what they need; the memo answers a question asked before.

The key is the data's bytes (a BLAKE2 digest) and the settings, not the objects: a `Recording` may
share its arrays with the caller, who may change them in place between two calls, and a changed
array is a new key. What is stored is never handed out: every answer is a deep copy, so a caller
that edits a result cannot edit the next caller's.
"""
from __future__ import annotations

import copy
import hashlib
import threading
from collections import OrderedDict
from typing import Any, Callable

import numpy as np


def fingerprint(*arrays, settings=()) -> bytes:
    """A digest of ``arrays`` (their dtype, shape and bytes) and ``settings``, whose repr must tell every two
    settings apart: Python and NumPy scalars, strings and tuples of them (not arrays: their repr rounds)."""
    h = hashlib.blake2b(digest_size=20)
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(f"{a.dtype.str}{a.shape}".encode())
        h.update(a.data.cast("B"))
    h.update(repr(settings).encode())
    return h.digest()


class ContentMemo:
    """The last ``size`` answers of a deterministic function, by a key of what it was asked."""

    def __init__(self, size: int = 16):
        self.size = size
        self._answers: OrderedDict[bytes, Any] = OrderedDict()
        self._lock = threading.Lock()

    def answer(self, key: bytes, compute: Callable[[], Any]):
        """``compute()``, or a copy of what it gave for ``key`` before."""
        with self._lock:
            known = key in self._answers
            if known:
                self._answers.move_to_end(key)
                kept = self._answers[key]
        if not known:
            kept = compute()  # outside the lock: another thread may compute the same; both are right
            with self._lock:
                self._answers[key] = kept
                while len(self._answers) > self.size:
                    self._answers.popitem(last=False)
        return copy.deepcopy(kept)

    def clear(self) -> None:
        with self._lock:
            self._answers.clear()

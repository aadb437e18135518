"""numba's on-disk cache, dropped when a file the compiled code calls into changes.

numba keys a function's cache by its own file and bytecode: a jitted function that calls another one, from
another file, keeps the machine code it was compiled with when only the callee's file changes. A structure's
joint kernel ran a law's previous text that way (a saturating spring, added to `satmd.structure.laws`, was
simulated as the term it replaced, and every fit of it ran away) until its cache was removed by hand.
"""
from __future__ import annotations

import hashlib
from pathlib import Path


def njit_cached(numba, func, sources):
    """``numba.njit(cache=True)`` of ``func``, its cache flushed when the text of ``sources`` (its own file and
    the files of the functions it calls) differs from what the cache holds code for.

    Parameters
    ----------
    numba : the numba module (imported by the caller, on first use)
    func : the Python function
    sources : paths of the files whose text the compiled code depends on

    Returns
    -------
    numba dispatcher
    """
    dispatcher = numba.njit(cache=True, fastmath=False, nogil=True)(func)  # threads run it side by side
    cache = getattr(dispatcher, "_cache", None)
    where = getattr(cache, "cache_path", None)
    if where:
        # this file too: numba's cache key holds no compile options, and code compiled with others would load
        digest = hashlib.sha256(b"".join(Path(s).read_bytes() for s in [*sources, __file__])).hexdigest()
        stamp = Path(where) / f"{func.__module__}.{func.__qualname__}.sources"
        try:
            if not stamp.exists() or stamp.read_text() != digest:
                cache.flush()  # numba compiles anew and saves (another process may do the same: harmless)
                stamp.write_text(digest)
        except OSError:  # a read-only cache: numba's own rules stand
            pass
    return dispatcher

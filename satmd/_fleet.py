"""One function over a fleet of inputs, in this process or on any executor.

`identify_many` and `discover_many` are this map with their own function. The
executor is anything with the `concurrent.futures.Executor` interface: a
``ProcessPoolExecutor`` spreads the fleet over this machine's cores, a Dask
``distributed.Client(...).get_executor()`` over a cluster. Results come back in
input order and are the serial results bit for bit: every task runs the same
deterministic code on the same input.
"""
from __future__ import annotations

from functools import partial
from typing import Callable, Sequence

from ._progress import progress as _progress


def _each(fn, batch):
    return [fn(x) for x in batch]


def fleet_map(fn: Callable, items: Sequence, executor=None, chunksize: int = 1, progress: bool = False,
              desc: str = "fleet", unit: str = "it") -> list:
    """``[fn(x) for x in items]``, on ``executor`` when one is given.

    ``fn`` must be picklable (a module-level function or a ``functools.partial``
    of one) when an executor runs it in other processes. ``chunksize`` items
    travel as one task, which saves scheduling overhead for quick ``fn``.
    """
    items = list(items)
    if chunksize < 1:
        raise ValueError(f"chunksize must be >= 1, got {chunksize}")
    bar = _progress(len(items), desc, unit, enabled=progress)
    if executor is None:
        results = (fn(x) for x in items)
    elif chunksize == 1:
        results = executor.map(fn, items)
    else:
        batches = [items[i:i + chunksize] for i in range(0, len(items), chunksize)]
        results = (r for batch in executor.map(partial(_each, fn), batches) for r in batch)
    out = []
    for r in results:
        out.append(r)
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    return out

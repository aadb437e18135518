"""Repeated optimisation: one global fit per FRF, spread over any executor."""
from __future__ import annotations

from concurrent.futures import Executor
from functools import partial
from typing import Sequence

from ..io.frfdata import FRFData
from .fit import identify


def _fit_one(data, kwargs):
    return identify(data, **kwargs)


def identify_many(datas: Sequence[FRFData], executor: Executor | None = None, progress: bool = False,
                  **kwargs) -> list:
    """Fit every FRF in ``datas`` (same keyword arguments as `identify`).

    ``executor`` is any `concurrent.futures.Executor`: a ProcessPoolExecutor
    spreads the fleet over cores, a Dask ``client.get_executor()`` over
    machines; None runs in this process. Results come back in input order.
    """
    fn = partial(_fit_one, kwargs=kwargs)
    if executor is None:
        it = map(fn, datas)
        if progress:
            it = _progress(it, len(datas))
        return list(it)
    return list(executor.map(fn, datas))


def _progress(it, total):
    try:
        from tqdm import tqdm
    except ImportError:  # tqdm comes with the nn extra; plain iteration without it
        return it
    return tqdm(it, total=total, desc="identify", unit="FRF")

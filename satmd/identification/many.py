"""Repeated optimisation: one global fit per FRF, spread over any executor."""
from __future__ import annotations

from functools import partial
from typing import TYPE_CHECKING, Sequence

from .._fleet import fleet_map
from ..validation import Interval, Whole, validate_params
from ..io.frfdata import FRFData, require_data
from .fit import identify

if TYPE_CHECKING:  # only for the annotation: concurrent.futures would cost start-up time
    from concurrent.futures import Executor


def _fit_one(data, kwargs):
    return identify(data, **{"warn": False, **kwargs})  # warnings stay on the results unless asked for


@validate_params({"progress": [bool], "chunksize": [Interval(Whole, 1)]})
def identify_many(datas: Sequence[FRFData], executor: Executor | None = None, progress: bool = False,
                  chunksize: int = 1, **kwargs) -> list:
    """Fit every FRF in ``datas`` (same keyword arguments as `identify`).

    Parameters
    ----------
    datas : sequence of FRFData
        The measurements, one fit each.
    executor : concurrent.futures.Executor or None
        A ProcessPoolExecutor spreads the fleet over cores, a Dask
        ``distributed.Client(address).get_executor()`` over machines; None runs
        in this process. The results are the serial ones bit for bit.
    progress : show progress on stderr.
    chunksize : FRFs sent to a worker as one task (more for quick fits).
    **kwargs :
        Passed to `identify`. Poor-fit warnings stay on each result unless
        ``warn=True`` is passed.

    Returns
    -------
    list of FitResult
        In input order.
    """
    datas = list(datas)
    for i, d in enumerate(datas):
        require_data(d, f"datas[{i}]")
    return fleet_map(partial(_fit_one, kwargs=kwargs), datas, executor, chunksize, progress, "identify", "FRF")

"""Fleets on executors: `identify_many` and `discover_many` on a process pool and on a Dask cluster
give the serial results bit for bit, in input order."""
from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from satmd import PAPER_GRID_HZ, Rig, discover_many, effect, identify_many, simulate

TRUTHS = [dict(m2=0.45, kp=8e4, R=30.0, L=0.1), dict(m2=0.7, kp=1.6e5, R=70.0, L=0.3),
          dict(m2=0.55, kp=1.2e5, R=12.0, L=0.05)]


def _fleet():
    return [simulate(PAPER_GRID_HZ, Rig().replace(**t), noise=0.01, seed=i) for i, t in enumerate(TRUTHS)]


def _same_fit(a, b):
    assert a.names == b.names
    for name in a.names:  # bit for bit: == on floats, not approx
        assert a.values[name] == b.values[name] or (math.isnan(a.values[name]) and math.isnan(b.values[name]))
    assert a.chi2 == b.chi2 and a.nfev == b.nfev
    np.testing.assert_array_equal(a.covariance, b.covariance)


def _same_report(a, b):
    da, db = a.to_dict(), b.to_dict()
    da.pop("wall_time", None), db.pop("wall_time", None)
    assert da == db


@pytest.fixture(scope="module")
def fleet():
    datas = _fleet()
    return datas, identify_many(datas, n_search=512, seed=3)


def test_process_pool_bit_for_bit_with_batches(fleet):
    datas, serial = fleet
    with ProcessPoolExecutor(max_workers=2) as pool:
        for chunksize in (1, 2):
            got = identify_many(datas, executor=pool, chunksize=chunksize, n_search=512, seed=3)
            assert len(got) == len(serial)
            for a, b in zip(serial, got):
                _same_fit(a, b)


def test_chunksize_must_be_positive(fleet):
    with pytest.raises(ValueError, match="chunksize"):
        identify_many(fleet[0], chunksize=0)


@pytest.fixture(scope="module")
def dask_executor():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(processes=True, n_workers=2, threads_per_worker=1, dashboard_address=None) \
            as cluster, distributed.Client(cluster) as client:
        yield client.get_executor()


def test_identify_many_on_dask_local_cluster(fleet, dask_executor):
    datas, serial = fleet
    got = identify_many(datas, executor=dask_executor, n_search=512, seed=3)
    assert len(got) == len(serial)
    for a, b in zip(serial, got):
        _same_fit(a, b)


def test_discover_many_on_dask_local_cluster(dask_executor):
    datas = [simulate(PAPER_GRID_HZ, Rig(), noise=(0.01, 0.002), seed=11),
             simulate(PAPER_GRID_HZ, Rig(), effects=[effect("time_delay", tau_s=3e-4)], noise=(0.01, 0.002), seed=1)]
    serial = discover_many(datas, candidates=("time_delay", "sensor_gain"))
    got = discover_many(datas, executor=dask_executor, chunksize=2, candidates=("time_delay", "sensor_gain"))
    assert [r.effect_names for r in got] == [r.effect_names for r in serial]
    assert "time_delay" in got[1].effect_names
    for a, b in zip(serial, got):
        _same_report(a, b)

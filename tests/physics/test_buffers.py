"""Memory the forward model reuses (`satmd.physics.buffers`): results a caller still holds are never
written again, results let go of are reused, and reuse changes no value."""
from __future__ import annotations

import threading

import numpy as np
import pytest

from satmd.physics import PAPER_GRID_HZ, Rig, frf
from satmd.physics.buffers import OUTPUTS, OutputPool, Workspace, kept_workspace

ROWS = 3000  # 3000 x 60 x 5 complex: 14 MB, well above the pool's smallest block


def _rig(seed, n=ROWS):
    rng = np.random.default_rng(seed)
    return Rig(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n), R=rng.uniform(5, 100, n),
               L=rng.uniform(0.02, 0.5, n))


def _address(a):
    return a.__array_interface__["data"][0]


def _channels(res):
    return np.stack([res.u1, res.u2, res.q, res.a1, res.a2])


@pytest.fixture(autouse=True)
def _empty_pool():
    OUTPUTS.clear()
    yield
    OUTPUTS.clear()


def test_a_result_let_go_of_is_reused_and_a_held_one_is_never_written():
    first = frf(PAPER_GRID_HZ, _rig(0))
    where = _address(first.u1)
    held = _channels(first).copy()
    second = frf(PAPER_GRID_HZ, _rig(1))  # ``first`` is held: a new block
    assert not np.shares_memory(first.u1, second.u1)
    np.testing.assert_array_equal(_channels(first), held)
    del first
    third = frf(PAPER_GRID_HZ, _rig(2))
    assert _address(third.u1) == where  # the block ``first`` lived in, taken back
    assert not np.shares_memory(third.u1, second.u1)


def test_a_view_or_one_channel_kept_holds_the_whole_block():
    part = frf(PAPER_GRID_HZ, _rig(0)).a2[10:20, ::3]  # the Response is gone; a slice of one channel stays
    kept = part.copy()
    for seed in (1, 2, 3):
        res = frf(PAPER_GRID_HZ, _rig(seed))
        assert not np.shares_memory(res.a2, part)
        del res
    np.testing.assert_array_equal(part, kept)
    view = memoryview(frf(PAPER_GRID_HZ, _rig(4)).q)  # anything holding the data holds the block
    snapshot = bytes(view)
    frf(PAPER_GRID_HZ, _rig(5))
    assert bytes(view) == snapshot


@pytest.mark.parametrize("wrt", [None, ("m2", "kp", "R", "L")])
def test_reused_memory_gives_the_same_bits(wrt):
    rig = _rig(7)
    OUTPUTS.max_blocks, blocks = 0, OUTPUTS.max_blocks
    try:
        fresh = frf(PAPER_GRID_HZ, rig, wrt=wrt)
    finally:
        OUTPUTS.max_blocks = blocks
    frf(PAPER_GRID_HZ, _rig(8), wrt=wrt)  # leaves other values in blocks the next call takes back
    again = frf(PAPER_GRID_HZ, rig, wrt=wrt)
    np.testing.assert_array_equal(_channels(again), _channels(fresh))
    for ch in fresh.jac:
        np.testing.assert_array_equal(again.jac[ch], fresh.jac[ch])


def test_the_pool_keeps_what_its_limits_allow():
    pool = OutputPool()
    pool.max_blocks, pool.max_bytes = 2, 6 * 2**20
    small = pool.empty((10, 10))
    assert small.base is None  # under min_bytes: plain numpy.empty, never kept
    pool.keep(small)
    blocks = [pool.empty((2**17 + k,)) for k in range(3)]  # 2 MB each
    for b in blocks:
        pool.keep(b)
    assert len(pool._spare) == 2  # the least recently used let go
    where = {_address(b) for b in blocks[1:]}
    del blocks, b
    assert _address(pool.empty((2**17,))) in where  # fits: at least as large, at most twice
    assert pool.empty((2**16,)).base.size == 2**16  # a block more than twice as large is not taken
    pool.clear()
    assert pool._spare == []
    big = pool.empty((2**20,))  # 16 MB: over max_bytes, handed out but not kept
    pool.keep(big)
    assert pool._spare == []


def test_threads_never_share_a_block():
    rigs = [_rig(s, 1000) for s in range(4)]
    want = [_channels(frf(PAPER_GRID_HZ, r)) for r in rigs]
    errors = []

    def worker(k):
        for _ in range(15):
            res = frf(PAPER_GRID_HZ, rigs[k])
            if not np.array_equal(_channels(res), want[k]):
                errors.append(k)
            del res

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []


def test_a_thread_keeps_its_workspace_and_a_call_inside_a_call_gets_another():
    with kept_workspace() as outer:
        outer.get("x", (4, 4))
        with kept_workspace() as inner:
            assert inner is not outer
    with kept_workspace() as again:
        assert again is outer  # the outer one was given back last
        again.get("big", (2**22,))  # 64 MB: more than a thread keeps
    with kept_workspace() as fresh:
        assert fresh is not again and fresh.nbytes == 0
        for n in range(600):  # many small buffers (a tile per chunk shape, calls on many grids)
            fresh.get(f"x{n}", (1, 3))
    with kept_workspace() as other:
        assert other is not fresh


def test_an_outgrown_buffer_lets_go_of_its_old_views():
    work = Workspace()
    small = work.get("x", (2, 3))
    large = work.get("x", (4, 5))
    assert not np.shares_memory(small, large)
    assert all(k[0] != "x" or k[1] == (4, 5) for k in work._views)


def test_kept_tiles_of_two_shapes_do_not_overlap():
    work, omega = Workspace(), np.array([1.0, 2.0, 3.0])
    wide = work.full("g", np.array([1.0, 2.0, 3.0]), (4, 3))
    work.full("g", np.array([7.0, 8.0, 9.0]), (1, 3))  # the last, shorter chunk; or the next call's rows
    np.testing.assert_array_equal(work.full("g", np.array([1.0, 2.0, 3.0]), (4, 3)), np.tile([1.0, 2.0, 3.0], (4, 1)))
    assert work.full("g", np.array([1.0, 2.0, 3.0]), (4, 3)) is wide
    tiled = work.tile("w", (4, 3), lambda: omega, omega)
    work.tile("w", (1, 3), lambda: -omega, omega)
    np.testing.assert_array_equal(tiled, np.tile(omega, (4, 1)))


def test_a_nan_left_in_a_kept_workspace_reaches_no_later_call():
    import warnings

    from satmd.physics import effect
    freq = np.concatenate([[5.0, 66.0], PAPER_GRID_HZ])
    before = _channels(frf(freq, Rig(), [effect("dielectric_loss", tan_delta=0.02)]))  # its tiles kept
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        frf(np.array([50.0, 66.0, 80.0]), Rig(), [effect("extra_mode", f_hz=66.0, zeta=0.0, mass_ratio=0.0)])
    got = frf(freq, Rig(), [effect("dielectric_loss", tan_delta=0.02)])
    np.testing.assert_array_equal(_channels(got), before)

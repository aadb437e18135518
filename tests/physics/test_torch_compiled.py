"""The compiled torch twin (opt-in on CUDA: SATMD_TORCH_COMPILE=1) against the eager twin, its reference."""
from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from satmd.physics import CHANNELS, PAPER_GRID_HZ, Rig, effect  # noqa: E402
from satmd.physics import torch as twin  # noqa: E402

cuda = pytest.mark.skipif(not torch.cuda.is_available(), reason="needs a CUDA device")


def _batch(n, device):
    rng = np.random.default_rng(7)
    return Rig(**{k: torch.tensor(rng.uniform(lo, hi, n), device=device)
                  for k, lo, hi in (("m2", 0.3, 0.8), ("kp", 5e4, 2e5), ("R", 5.0, 100.0), ("L", 0.02, 0.5))})


@cuda
@pytest.mark.parametrize("dtype, rtol", [(torch.complex128, 1e-12), (torch.complex64, 1e-5)])
@pytest.mark.parametrize("with_effects", [False, True])
def test_compiled_equals_eager_on_cuda(dtype, rtol, with_effects):
    effects = [effect("time_delay", tau_s=1.5e-4), effect("extra_mode", f_hz=66.0, zeta=0.01, mass_ratio=0.01)] \
        if with_effects else []
    rig = _batch(4096, "cuda")
    eager = twin.frf(PAPER_GRID_HZ, rig, effects, dtype=dtype, device="cuda", compiled=False)
    fused = twin.frf(PAPER_GRID_HZ, rig, effects, dtype=dtype, device="cuda", compiled=True)
    assert "failed" not in twin._COMPILED, twin._COMPILED.get("failed")
    for ch in CHANNELS:
        assert fused[ch].dtype == dtype and fused[ch].device.type == "cuda"
        err = float((fused[ch] - eager[ch]).abs().max() / eager[ch].abs().max())
        assert err <= rtol, (ch, err)


def test_cpu_default_is_eager(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("torch.compile must not run on CPU by default")

    monkeypatch.setattr(twin, "_compiled_closed_form", refuse)
    out = twin.frf(PAPER_GRID_HZ, _batch(8, "cpu"), dtype=torch.complex64)
    assert out["a1"].shape == (8, PAPER_GRID_HZ.size)


def test_compile_failure_falls_back_to_eager(monkeypatch):
    def broken(fn, **kwargs):
        raise RuntimeError("no compiler here")

    monkeypatch.setattr(twin, "_COMPILED", {})
    monkeypatch.setattr(torch, "compile", broken)
    rig = _batch(8, "cpu")
    with pytest.warns(RuntimeWarning, match="eagerly"):
        got = twin.frf(PAPER_GRID_HZ, rig, compiled=True)
    want = twin.frf(PAPER_GRID_HZ, rig, compiled=False)
    for ch in CHANNELS:
        torch.testing.assert_close(got[ch], want[ch], rtol=0, atol=0)

"""Issue 29: the Möbius map of the shunt impedance against the twin, and back-propagation by hand against autograd."""
import numpy as np
import pytest

torch = pytest.importorskip("torch")

from satmd import Rig
from satmd.inverse import BLIND_PAIRS, pairs_dataset
from satmd.inverse.dataset import BOUNDS
from satmd.inverse.nets import EnsembleNet
from satmd.inverse.objective import ShuntMobius, _complex_residuals, gauss_newton_step, physics_loss


def _problem(dtype=torch.complex128):
    ds = pairs_dataset(BLIND_PAIRS, per_pair=2, seed=4)
    y = torch.as_tensor(ds.labels_normalised(), dtype=torch.float64)
    target = torch.as_tensor(np.stack([ds.a1, ds.a2], axis=1)).to(dtype)
    s_n = torch.as_tensor(np.abs(np.stack([ds.a1, ds.a2], axis=1)).max(axis=(1, 2)))
    start = (y + torch.as_tensor(np.random.default_rng(1).normal(0, 0.05, y.shape))).clamp(0.01, 0.99)
    return ds, start, target, s_n


def test_moebius_map_reproduces_the_twin():
    ds, start, target, s_n = _problem()
    freq = torch.as_tensor(ds.freq_hz)
    mob = ShuntMobius.fit(freq, Rig(), BOUNDS, torch.complex128)
    assert mob is not None
    d, _, _ = mob.residuals(start, target, s_n)
    ref = _complex_residuals(start, target, s_n, freq, Rig(), BOUNDS)  # (n, 2F): [channel 1, channel 2]
    torch.testing.assert_close(d.reshape(ref.shape), ref, rtol=0, atol=1e-9 * float(ref.abs().max()))
    torch.testing.assert_close(mob.physics_loss(start, target, s_n), physics_loss(start, target, s_n, freq, Rig()),
                               rtol=1e-9, atol=0)
    # its exact Gauss-Newton step is the twin's one-difference step (h = 1e-6) up to that difference's error
    a, la = mob.gauss_newton_step(start, target, s_n)
    b, lb = gauss_newton_step(start, target, s_n, freq, Rig())
    torch.testing.assert_close(la, lb, rtol=1e-9, atol=0)
    torch.testing.assert_close(a, b, rtol=0, atol=1e-4 * float(b.abs().max()))


def test_moebius_map_in_single_precision_stays_close():
    ds, start, target, s_n = _problem(torch.complex64)
    freq = torch.as_tensor(ds.freq_hz, dtype=torch.float32)
    m64 = ShuntMobius.fit(freq, Rig(), BOUNDS, torch.complex64)
    m128 = ShuntMobius.fit(freq.double(), Rig(), BOUNDS, torch.complex128)
    a, la = m64.gauss_newton_step(start.float(), target, s_n.float())
    b, lb = m128.gauss_newton_step(start, target.to(torch.complex128), s_n)
    torch.testing.assert_close(la.double(), lb, rtol=1e-3, atol=1e-7)
    torch.testing.assert_close(a.double(), b, rtol=0, atol=1e-3 * float(b.abs().max()))


def test_a_rig_the_map_cannot_reproduce_gets_none(monkeypatch):
    monkeypatch.setattr(ShuntMobius, "TOL", -1.0)  # no map passes: the caller keeps the twin
    assert ShuntMobius.fit(torch.linspace(10, 40, 8, dtype=torch.float64), Rig()) is None


def test_backpropagation_by_hand_matches_autograd():
    gen = torch.Generator().manual_seed(0)
    net = EnsembleNet(3, (12, 16, 8, 2), generator=gen)
    x = torch.randn(3, 10, 12, generator=gen)
    g_out = torch.randn(3, 10, 2, generator=gen)
    out, acts = net.train_forward(x)
    torch.testing.assert_close(out, net(x).detach())
    net.set_grad(acts, out, g_out)
    by_hand = [p.grad.clone() for p in net.parameters()]
    net.zero_grad(set_to_none=True)
    (net(x) * g_out).sum().backward()
    for mine, ref in zip(by_hand, net.parameters()):
        torch.testing.assert_close(mine, ref.grad, rtol=1e-5, atol=1e-6)
    # one shared batch (n, d) broadcast to every member, as in the supervised warm start
    out2, acts2 = net.train_forward(x[0])
    net.set_grad(acts2, out2, g_out)
    by_hand = [p.grad.clone() for p in net.parameters()]
    net.zero_grad(set_to_none=True)
    (net(x[0]) * g_out).sum().backward()
    for mine, ref in zip(by_hand, net.parameters()):
        torch.testing.assert_close(mine, ref.grad, rtol=1e-5, atol=1e-6)


def test_direct_fused_adam_is_torch_adam_bit_for_bit(tiny_data, monkeypatch):
    from satmd.inverse import InverseModel
    from satmd.inverse.training import FusedAdam

    kw = dict(epochs=3, warm_start_epochs=1, n_members=2, seed=7, verbose=False, mc_samples=4)
    test = pairs_dataset(BLIND_PAIRS)
    direct = InverseModel("physics", **kw).fit(tiny_data)
    monkeypatch.setattr(FusedAdam, "available", staticmethod(lambda device: False))  # torch.optim.Adam(fused=True)
    torch_adam = InverseModel("physics", **kw).fit(tiny_data)
    for a, b in zip(direct.ensemble_.parameters(), torch_adam.ensemble_.parameters()):
        assert torch.equal(a, b)
    np.testing.assert_array_equal(direct.predict(test)["R"], torch_adam.predict(test)["R"])

"""The torch twin against the NumPy model: values in complex128 and complex64,
and autograd gradients against the analytic Jacobian."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

torch = pytest.importorskip("torch")

from satmd.physics import CHANNELS, PAPER_GRID_HZ, Rig, effect, frf  # noqa: E402
from satmd.physics import torch as twin  # noqa: E402

FREQ = np.concatenate([[2.0, 15.0], PAPER_GRID_HZ, [66.3, 180.0, 480.0]])

EFFECT_SPECS = [
    ("sensor_gain", dict(gain_a1=1.07, gain_a2=0.94)),
    ("time_delay", dict(tau_s=1.5e-4)),
    ("structural_damping", dict(eta=0.03)),
    ("dielectric_loss", dict(tan_delta=0.04)),
    ("shunt_capacitance", dict(Cs=3e-6)),
    ("extra_mode", dict(f_hz=66.0, zeta=0.01, mass_ratio=0.01)),
    ("parameter_offset:k1", dict(value=2.0e5)),
    ("parameter_offset:Cp", dict(value=25e-6)),
]


def all_effects():
    return [effect(n, **p) for n, p in EFFECT_SPECS]


def _max_rel(got, want):
    return float(np.max(np.abs(got - want)) / np.max(np.abs(want)))


@settings(max_examples=30, deadline=None)
@given(m2=st.floats(0.3, 0.8), kp=st.floats(5e4, 2e5), R=st.floats(1.0, 100.0), L=st.floats(0.01, 0.5),
       with_effects=st.booleans())
def test_complex128_equals_numpy(m2, kp, R, L, with_effects):
    rig = Rig(m2=m2, kp=kp, R=R, L=L)
    effects = all_effects() if with_effects else []
    want = frf(FREQ, rig, effects)
    got = twin.frf(FREQ, rig, effects, dtype=torch.complex128)
    assert set(got) == set(CHANNELS)
    for ch in CHANNELS:
        assert got[ch].dtype == torch.complex128
        g = got[ch].numpy()
        w = getattr(want, ch)
        assert g.shape == w.shape
        np.testing.assert_allclose(g, w, rtol=1e-12, atol=0, err_msg=ch)


def test_complex128_batched_tensors_equal_numpy_batch():
    rng = np.random.default_rng(5)
    n = 64
    params = dict(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n), R=rng.uniform(1, 100, n),
                  L=rng.uniform(0.01, 0.5, n))
    f3 = rng.uniform(40, 140, n)
    effects_np = all_effects()
    effects_np[5] = effect("extra_mode", f_hz=f3, zeta=0.01, mass_ratio=0.01)
    want = frf(FREQ, Rig(**params), effects_np)
    effects_t = all_effects()
    effects_t[5] = effect("extra_mode", f_hz=torch.tensor(f3), zeta=0.01, mass_ratio=0.01)
    got = twin.frf(FREQ, Rig(**{k: torch.tensor(v) for k, v in params.items()}), effects_t)
    for ch in CHANNELS:
        assert got[ch].shape == (n, FREQ.size)
        np.testing.assert_allclose(got[ch].numpy(), getattr(want, ch), rtol=1e-12, atol=0, err_msg=ch)


def test_complex64_close_to_numpy():
    rng = np.random.default_rng(6)
    n = 200
    params = dict(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n), R=rng.uniform(5, 100, n),
                  L=rng.uniform(0.02, 0.5, n))
    for effects in ([], all_effects()):
        want = frf(PAPER_GRID_HZ, Rig(**params), effects)
        got = twin.frf(PAPER_GRID_HZ, Rig(**params), effects, dtype=torch.complex64)
        for ch in CHANNELS:
            assert got[ch].dtype == torch.complex64
            g = got[ch].numpy().astype(complex)
            w = getattr(want, ch)
            # per rig, relative to that rig's peak on the grid
            err = np.max(np.abs(g - w), axis=-1) / np.max(np.abs(w), axis=-1)
            assert np.max(err) < 2e-5, (ch, float(np.max(err)))
            assert np.median(err) < 1e-5, (ch, float(np.median(err)))
            # and it really is single precision (not silently complex128)
            assert np.max(err) > 1e-9


def test_gradients_match_the_analytic_jacobian():
    """Autograd through the twin (complex128) gives NumPy's analytic d(channel)/d(parameter)."""
    rng = np.random.default_rng(7)
    rig_names = ["m2", "kp", "R", "L", "k1", "e", "Cp", "c1"]
    eff_names = ["extra_mode.f_hz", "extra_mode.zeta", "extra_mode.mass_ratio", "time_delay.tau_s",
                 "dielectric_loss.tan_delta", "shunt_capacitance.Cs", "structural_damping.eta",
                 "sensor_gain.gain_a1", "parameter_offset:Cp.value"]
    # leave parameter_offset:k1 out so that k1 has a non-zero derivative
    specs = [s for s in EFFECT_SPECS if s[0] != "parameter_offset:k1"]
    rig = Rig(m2=0.45, kp=1.3e5, R=18.0, L=0.09)
    effects = [effect(n, **p) for n, p in specs]
    jac = frf(FREQ, rig, effects, wrt=rig_names + eff_names)

    leaves = {n: torch.tensor(float(getattr(rig, n)), dtype=torch.float64, requires_grad=True) for n in rig_names}
    eff_t = []
    for e in effects:
        params = {p: torch.tensor(float(v), dtype=torch.float64, requires_grad=True) for p, v in e.params.items()}
        for p, t in params.items():
            leaves[e.qualified(p)] = t
        eff_t.append(e.replace(**params))
    out = twin.frf(FREQ, rig.replace(**{n: leaves[n] for n in rig_names}), eff_t)
    names = rig_names + eff_names
    for ch in CHANNELS:
        wr, wi = rng.standard_normal(FREQ.size), rng.standard_normal(FREQ.size)
        loss = (torch.tensor(wr) * out[ch].real + torch.tensor(wi) * out[ch].imag).sum()
        grads = torch.autograd.grad(loss, [leaves[n] for n in names], allow_unused=True, retain_graph=True)
        J = jac.jac[ch]
        for j, (name, g) in enumerate(zip(names, grads)):
            want = float(np.sum(wr * J[:, j].real + wi * J[:, j].imag))
            got = 0.0 if g is None else float(g)
            scale = float(np.sum(np.abs(wr) * np.abs(J[:, j]) + np.abs(wi) * np.abs(J[:, j])))
            assert abs(got - want) <= 1e-9 * scale + 1e-300, (ch, name, got, want)


def test_batched_gradients_match_the_analytic_jacobian():
    rng = np.random.default_rng(8)
    n = 16
    vals = dict(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n), R=rng.uniform(5, 100, n),
                L=rng.uniform(0.02, 0.5, n))
    wrt = list(vals)
    jac = frf(PAPER_GRID_HZ, Rig(**vals), wrt=wrt, outputs=("a1", "a2"))
    leaves = {k: torch.tensor(v, requires_grad=True) for k, v in vals.items()}
    out = twin.frf(PAPER_GRID_HZ, Rig(**leaves), outputs=("a1", "a2"))
    feats = twin.features(out)
    assert feats.shape == (n, 240)
    np.testing.assert_allclose(
        feats.detach().numpy(),
        np.concatenate([jac.a1.real, jac.a2.real, jac.a1.imag, jac.a2.imag], axis=-1), rtol=1e-12, atol=0)
    W = rng.standard_normal((n, 240))
    (feats * torch.tensor(W)).sum().backward()
    Jf = np.concatenate([jac.jac["a1"].real, jac.jac["a2"].real, jac.jac["a1"].imag, jac.jac["a2"].imag], axis=1)
    for j, k in enumerate(wrt):
        want = np.sum(W * Jf[:, :, j], axis=1)  # rows are independent rigs
        scale = np.sum(np.abs(W * Jf[:, :, j]), axis=1)
        np.testing.assert_array_less(np.abs(leaves[k].grad.numpy() - want), 1e-9 * scale)


def test_complex64_gradients_flow():
    R = torch.tensor(22.0, dtype=torch.float32, requires_grad=True)
    out = twin.frf(PAPER_GRID_HZ, Rig(R=R), dtype=torch.complex64, outputs=("a1",))
    out["a1"].abs().sum().backward()
    jac = frf(PAPER_GRID_HZ, Rig(), wrt=["R"], outputs=("a1",))
    a = jac.a1
    want = float(np.sum((a.conj() * jac.jac["a1"][:, 0]).real / np.abs(a)))
    assert R.grad.dtype == torch.float32
    assert abs(float(R.grad) - want) <= 1e-3 * abs(want)


def test_bad_dtype_is_refused():
    with pytest.raises(ValueError, match="complex128 or torch.complex64"):
        twin.frf(PAPER_GRID_HZ, Rig(), dtype=torch.float64)
    with pytest.raises(ValueError):
        twin.frf(PAPER_GRID_HZ, Rig(), outputs=("a3",))

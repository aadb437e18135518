import json

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from satmd import Rig, simulate
from satmd.errors import SatmdError
from satmd.inverse import BLIND_PAIRS, InverseModel, normalised_outputs, pairs_dataset
from satmd.inverse.nets import EnsembleNet, InverseNet
import dataclasses

from satmd.inverse.training import Scaler, gauss_newton_step, physics_loss, train_ensemble


def test_ensemble_members_are_plain_nets():
    net = EnsembleNet(3, generator=torch.Generator().manual_seed(0))
    x = torch.randn(7, 240)
    out = net(x)
    assert out.shape == (3, 7, 2)
    for k, member in enumerate(net.members()):
        assert isinstance(member, InverseNet)
        torch.testing.assert_close(member(x), out[k])
        assert member.latent(x).shape == (7, 64)
        assert torch.all((member(x) >= 0) & (member(x) <= 1))


def test_physics_loss_vanishes_at_the_truth(tiny_data):
    ds = tiny_data.train
    y = torch.as_tensor(ds.labels_normalised(), dtype=torch.float64)
    target = torch.as_tensor(np.stack([ds.a1, ds.a2], axis=1))
    s_n = torch.as_tensor(np.abs(np.stack([ds.a1, ds.a2], axis=1)).max(axis=(1, 2)))
    freq = torch.as_tensor(ds.freq_hz)
    loss = physics_loss(y, target, s_n, freq, Rig())
    assert loss.shape == (len(ds),)
    assert float(loss.max()) < 1e-20
    off = physics_loss(y + 0.01, target, s_n, freq, Rig())
    assert float(off.min()) > 1e-8


def test_short_physics_training_beats_the_mean(tiny_data):
    """A few epochs of the eq. 22 loss alone (no warm start) beat predicting the mean label."""
    ds = tiny_data
    scaler = Scaler.fit(ds.train.features())
    cfg = dataclasses.replace(InverseModel().train_config("physics"), epochs=12, warm_start_epochs=0, batch_size=32,
                              lr=3e-3, n_members=1, seed=0)
    net, hist = train_ensemble(ds.train, ds.val, cfg, scaler, verbose=False)
    assert hist["loss"][-1] < hist["loss"][0]
    with torch.no_grad():
        pred = net(torch.as_tensor(scaler.transform(ds.val.features())))[0].numpy()
    y = ds.val.labels_normalised()
    baseline = np.abs(y - ds.train.labels_normalised().mean(axis=0)).mean()
    assert np.abs(pred - y).mean() < 0.5 * baseline


def test_fit_predict_shapes_and_contract(tiny_physics, tiny_data):
    m = tiny_physics
    assert m.kind == "physics" and m.bounds == {"R": (0.0, 103.0), "L": (0.0, 0.5)}
    assert len(m.networks_) == 3 and all(isinstance(n, torch.nn.Module) for n in m.networks_)
    test = pairs_dataset(BLIND_PAIRS)
    p = m.predict(test)
    assert set(p) == {"R", "L", "R_std", "L_std", "residual", "residual_expected", "residual_ratio", "explained"}
    assert all(p[k].shape == (6,) for k in p)
    assert np.all(p["R_std"] > 0) and np.all(p["L_std"] > 0)
    X = m.features(test)
    assert X.shape == (6, 240) and X.dtype == np.float32
    assert m.latent(test).shape == (6, 64)
    # networks_ map scaled features to normalised outputs; their mean is the prediction
    with torch.no_grad():
        outs = torch.stack([net(torch.as_tensor(X)) for net in m.networks_]).mean(0).numpy()
    np.testing.assert_allclose(m.bounds["R"][1] * outs[:, 0], p["R"], rtol=1e-5)
    # every accepted input form gives the same answer
    d = test.frfdata(2)
    one = m.predict(d)
    np.testing.assert_allclose(one["R"], p["R"][2:3], rtol=1e-6)
    np.testing.assert_allclose(m.predict(np.stack([d["a1"], d["a2"]]))["L"], one["L"], rtol=1e-6)
    np.testing.assert_allclose(m.predict(test.features()[2])["L"], one["L"], rtol=1e-6)


def test_normalised_outputs_are_differentiable(tiny_physics):
    m = tiny_physics
    test = pairs_dataset(BLIND_PAIRS[:2])
    X = torch.as_tensor(m.features(test)).requires_grad_(True)
    y = normalised_outputs(m, X)
    assert y.shape == (2, 2)
    y[:, 0].sum().backward()
    assert X.grad.shape == (2, 240) and torch.any(X.grad != 0)
    raw = torch.as_tensor(test.features(), dtype=torch.float64).requires_grad_(True)
    y2 = normalised_outputs(m, raw, raw=True)
    torch.testing.assert_close(y2, y.detach(), rtol=1e-5, atol=1e-6)
    y2[:, 1].sum().backward()
    assert raw.grad.shape == (2, 240)


def test_save_load_roundtrip(tiny_physics, tmp_path):
    m = tiny_physics
    m.save(tmp_path / "m")
    meta = json.loads((tmp_path / "m" / "model.json").read_text())
    assert meta["schema"] == "satmd-inverse/2" and meta["kind"] == "physics"
    assert len(meta["freq_hz"]) == 60 and len(meta["scaler"]["mean"]) == 240
    m2 = InverseModel.load(tmp_path / "m")
    test = pairs_dataset(BLIND_PAIRS)
    a, b = m.predict(test), m2.predict(test)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])
    assert m2.latent(test).shape == (6, 64)
    # weights are plain tensors: loadable with weights_only=True
    state = torch.load(tmp_path / "m" / "weights.pt", weights_only=True)
    assert all(isinstance(v, torch.Tensor) for v in state.values())


def test_seeded_training_is_deterministic(tiny_data):
    kw = dict(epochs=2, warm_start_epochs=1, n_members=2, batch_size=64, seed=5, verbose=False, mc_samples=4)
    a = InverseModel("supervised", **kw).fit(tiny_data)
    b = InverseModel("supervised", **kw).fit(tiny_data)
    test = pairs_dataset(BLIND_PAIRS)
    np.testing.assert_array_equal(a.predict(test)["R"], b.predict(test)["R"])
    c = InverseModel("supervised", **{**kw, "seed": 6}).fit(tiny_data)
    assert not np.array_equal(a.predict(test)["R"], c.predict(test)["R"])


def test_calibration_gives_95_percent_on_validation(tiny_data):
    m = InverseModel("supervised", noise=0.01, epochs=3, n_members=2, batch_size=64, seed=0, verbose=False,
                     mc_samples=8).fit(tiny_data)
    assert 0.9 <= m.fit_info_["val_coverage_2sd"] <= 1.0
    assert m.std_scale_.shape == (2,)


def test_noise_std_from_data_raises_the_std(tiny_physics):
    m = tiny_physics
    clean = simulate(rig=Rig(R=30.0, L=0.15))
    noisy = simulate(rig=Rig(R=30.0, L=0.15), noise=0.02, seed=1)
    assert m.predict(noisy)["R_std"][0] > m.predict(clean)["R_std"][0]


def test_input_errors(tiny_physics):
    m = tiny_physics
    with pytest.raises(SatmdError, match="frequencies"):
        m.predict(np.zeros((2, 30), complex))
    with pytest.raises(SatmdError, match="features of length 240"):
        m.predict(np.zeros((3, 100)))
    with pytest.raises(SatmdError, match="not fitted"):
        InverseModel().predict(np.zeros(240))
    with pytest.raises(SatmdError, match="unknown kind"):
        InverseModel(kind="magic").fit()
    with pytest.raises(SatmdError, match="no network"):
        InverseModel("optimization").fit().latent(np.zeros(240))


def test_optimization_and_hybrid(tiny_physics, tmp_path):
    pytest.importorskip("satmd.identification")
    test = pairs_dataset(BLIND_PAIRS[[0, 5]])
    opt = InverseModel("optimization").fit()
    p = opt.predict(test)
    np.testing.assert_allclose(p["R"], test.R, rtol=1e-5)
    np.testing.assert_allclose(p["L"], test.L, rtol=1e-5)
    opt.save(tmp_path / "o")
    assert InverseModel.load(tmp_path / "o").kind == "optimization"

    hyb = InverseModel("hybrid", epochs=4, warm_start_epochs=2, n_members=3, batch_size=64, seed=3, verbose=False)
    hyb.set_ensemble(tiny_physics.ensemble_)  # reuse the fixture's nets: the hybrid only adds the refinement
    hyb.scaler_, hyb.fit_info_ = tiny_physics.scaler_, dict(tiny_physics.fit_info_)
    hyb.std_scale_ = tiny_physics.std_scale_
    q = hyb.predict(test)
    np.testing.assert_allclose(q["R"], test.R, rtol=1e-5)
    np.testing.assert_allclose(q["L"], test.L, rtol=1e-5)


def test_gauss_newton_step_solves_one_sample():
    """From a nearby point, one Gauss-Newton step of eq. 22 lands on the truth (the twin is smooth there)."""
    ds = pairs_dataset(BLIND_PAIRS[2:4])
    y = torch.as_tensor(ds.labels_normalised(), dtype=torch.float64)
    target = torch.as_tensor(np.stack([ds.a1, ds.a2], axis=1))
    s_n = torch.as_tensor(np.abs(np.stack([ds.a1, ds.a2], axis=1)).max(axis=(1, 2)))
    start = y + torch.tensor([0.002, -0.001], dtype=torch.float64)
    step, loss = gauss_newton_step(start, target, s_n, torch.as_tensor(ds.freq_hz), Rig())
    assert loss.shape == (2,) and float(loss.min()) > 0
    torch.testing.assert_close(start - step, y, atol=2e-5, rtol=0)


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs CUDA")
def test_cuda_training_matches_the_cpu_path(tiny_data):
    """The training loop on the GPU: data resident there, same objective, close to the CPU answer."""
    kw = dict(epochs=3, warm_start_epochs=1, n_members=2, batch_size=64, seed=2, verbose=False, mc_samples=4,
              twin_dtype="complex128")
    gpu = InverseModel("physics", device="cuda", **kw).fit(tiny_data)
    cpu = InverseModel("physics", device="cpu", **kw).fit(tiny_data)
    assert gpu.fit_info_["device"].startswith("cuda") and cpu.fit_info_["device"] == "cpu"
    test = pairs_dataset(BLIND_PAIRS)
    g, c = gpu.predict(test), cpu.predict(test)
    assert np.all(np.isfinite(g["R"])) and np.all(np.isfinite(g["L"]))
    # same seeds and objective; the devices round differently, so only the outcome is compared
    assert np.max(np.abs(g["R"] - c["R"])) < 0.05 * 103

"""Vectorised, seeded training of the inverse nets (needs torch).

One step pushes a whole mini-batch, for every ensemble member at once,
through the network and (for the physics objective) through the torch twin
``satmd.physics.torch.frf``: no Python loop over samples or members.

Objectives
----------
``physics`` (eq. 22)
    The predicted (R, L) are denormalised (eq. 20), sent back through the
    forward model with the rig's mechanical parameters, and the reconstructed
    accelerations are compared with the *noise-free* target FRFs:
    ``mean_n mean_j (|Â1 - A1|² + |Â2 - A2|²) / s_n²`` with
    ``s_n = max_{j, channel} |A_n|`` (|z|² = Re² + Im²); no labels in this phase.
    Its gradient is back-propagated through the twin and, by default,
    preconditioned per sample by the inverse 2x2 Gauss-Newton matrix of
    eq. 22 before it enters the network (`physics_objective`): the FRFs are
    far less sensitive to R than to L, and plain gradient steps leave R
    loose. A warm start of ``warm_start_epochs`` supervised epochs puts the
    nets near the solution first (the physics loss is flat far from it); it
    is reported in the model's ``fit_info_``.
``supervised``
    Mean squared error on the normalised labels (the paper's "conventional
    supervised regressor" baseline).

Noise (eq. 23) is drawn afresh for every batch and member, and added to the
network inputs only; the physics target stays noise-free.
"""
from __future__ import annotations

import contextlib
import math
import sys
import time
from dataclasses import asdict, dataclass

import numpy as np

try:
    import torch
except ImportError as exc:  # pragma: no cover
    raise ImportError("satmd.inverse needs torch: pip install 'satmd[nn]'") from exc

from ..physics import Rig
from ..physics.torch import frf as torch_frf
from .dataset import BOUNDS, InverseDataset
from .nets import EnsembleNet


@dataclass
class TrainConfig:
    objective: str = "physics"
    epochs: int = 90
    warm_start_epochs: int = 50
    batch_size: int = 64
    lr: float = 1e-3
    physics_lr: float | None = 3e-4  # peak lr of the physics phase (None: lr)
    lr_final: float = 1e-5
    weight_decay: float = 0.0
    n_members: int = 5
    noise: float = 0.0
    seed: int = 0
    device: str | None = None
    twin_dtype: str = "complex128"
    precondition: bool = True  # Gauss-Newton preconditioning of the eq. 22 gradient (physics phase)
    max_step: float = 0.05  # largest Gauss-Newton step per output (normalised units)
    threads: int | None = 1  # torch CPU threads while training (None: leave torch's setting)

    def to_dict(self):
        return asdict(self)


def pick_device(device=None) -> torch.device:
    """``None``/"auto": CUDA when present, else CPU."""
    if device in (None, "auto"):
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(device)


class Scaler:
    """Per-feature standardisation fitted on training features (stored in the model's metadata)."""

    def __init__(self, mean: np.ndarray, scale: np.ndarray):
        self.mean = np.asarray(mean, np.float64)
        self.scale = np.asarray(scale, np.float64)

    @classmethod
    def fit(cls, x: np.ndarray) -> "Scaler":
        x = np.asarray(x, np.float64)
        scale = x.std(axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        return cls(x.mean(axis=0), scale)

    def transform(self, x: np.ndarray) -> np.ndarray:
        return ((np.asarray(x, np.float64) - self.mean) / self.scale).astype(np.float32)

    def to_dict(self):
        return {"mean": self.mean.tolist(), "scale": self.scale.tolist()}

    @classmethod
    def from_dict(cls, d):
        return cls(np.array(d["mean"]), np.array(d["scale"]))


def _denormalised(out, bounds):
    r_lo, r_hi = bounds["R"]
    l_lo, l_hi = bounds["L"]
    return r_lo + out[..., 0] * (r_hi - r_lo), l_lo + out[..., 1] * (l_hi - l_lo)


def physics_loss(norm_out, target, s_n, freq_t, rig: Rig, bounds=BOUNDS, dtype=torch.complex128):
    """Eq. 22 for normalised outputs (..., n, 2) against complex targets (n, 2, F).

    Returns the per-(member, sample) loss, shape (..., n).
    """
    real = torch.float64 if dtype == torch.complex128 else torch.float32
    R, L = _denormalised(norm_out.to(real), bounds)
    pred = torch_frf(freq_t, rig.replace(R=R, L=L), dtype=dtype, device=freq_t.device, outputs=("a1", "a2"))
    d1 = pred["a1"] - target[:, 0]
    d2 = pred["a2"] - target[:, 1]
    err = (d1.real ** 2 + d1.imag ** 2 + d2.real ** 2 + d2.imag ** 2).mean(dim=-1)
    return err / (s_n * s_n)


def _residuals(norm_out, target, s_n, freq_t, rig, bounds, dtype):
    """Scaled real residual vector of eq. 22, (..., n, 4F)."""
    R, L = _denormalised(norm_out, bounds)
    pred = torch_frf(freq_t, rig.replace(R=R, L=L), dtype=dtype, device=freq_t.device, outputs=("a1", "a2"))
    d = torch.cat([pred["a1"] - target[:, 0], pred["a2"] - target[:, 1]], dim=-1) / s_n[:, None]
    return torch.cat([d.real, d.imag], dim=-1)


def gauss_newton_matrix(norm_out, target, s_n, freq_t, rig, bounds=BOUNDS, dtype=torch.complex128,
                        h: float = 1e-6, damping: float = 1e-3):
    """Per-sample 2x2 Gauss-Newton matrix of eq. 22 w.r.t. the normalised outputs, (..., n, 2, 2).

    J (d residual / d output) by forward differences of the twin (two extra
    evaluations, no graph); H = (2/F) JᵀJ with Levenberg-Marquardt damping.
    """
    real = torch.float64 if dtype == torch.complex128 else torch.float32
    with torch.no_grad():
        o = norm_out.detach().to(real)
        r0 = _residuals(o, target, s_n, freq_t, rig, bounds, dtype)
        cols = []
        for k in range(2):
            step = torch.zeros_like(o)
            step[..., k] = h
            cols.append((_residuals(o + step, target, s_n, freq_t, rig, bounds, dtype) - r0) / h)
        J = torch.stack(cols, dim=-1)  # (..., n, 4F, 2)
        H = (2.0 / freq_t.numel()) * J.transpose(-1, -2) @ J
        diag = torch.diagonal(H, dim1=-2, dim2=-1)
        H = H + torch.diag_embed(damping * diag + 1e-30)
    return H


def physics_objective(out, target, s_n, freq_t, rig, bounds=BOUNDS, dtype=torch.complex128,
                      precondition: bool = True, max_step: float = 0.05):
    """Mean eq. 22 loss of the network outputs ``out`` (..., n, 2), ready for ``backward()``.

    The gradient of eq. 22 is back-propagated through the torch twin. With
    ``precondition``, on its way into the network it is multiplied per sample
    by the inverse 2x2 Gauss-Newton matrix of eq. 22 (so every sample asks
    its outputs to move by its Gauss-Newton step, at most ``max_step``): the
    objective and its minimiser are unchanged, but R, to which the FRFs are
    far less sensitive than to L, converges as fast as L.
    """
    real = torch.float64 if dtype == torch.complex128 else torch.float32
    o = out.to(real)
    if precondition and o.requires_grad:
        H = gauss_newton_matrix(o, target, s_n, freq_t, rig, bounds, dtype)
        n_terms = o[..., 0].numel()
        cap = max_step / n_terms

        def hook(g):
            step = torch.linalg.solve(H, g.unsqueeze(-1)).squeeze(-1)
            return step.clamp(-cap, cap)

        o.register_hook(hook)
    return physics_loss(o, target, s_n, freq_t, rig, bounds, dtype).mean()


class _Batches:
    """Tensors of one partition on the training device."""

    def __init__(self, ds: InverseDataset, scaler: Scaler, bounds, device, dtype):
        real = torch.float64 if dtype == torch.complex128 else torch.float32
        feats = ds.features()
        self.n = len(ds)
        self.x = torch.as_tensor(scaler.transform(feats), device=device)
        # per-feature noise scale in standardised units: |A| / feature scale
        mag = np.abs(np.concatenate([ds.a1, ds.a2], axis=-1))
        self.noise_unit = torch.as_tensor(np.concatenate([mag, mag], axis=-1) / scaler.scale, dtype=torch.float32,
                                          device=device)
        self.y = torch.as_tensor(ds.labels_normalised(bounds), dtype=torch.float32, device=device)
        target = np.stack([ds.a1, ds.a2], axis=1)
        self.target = torch.as_tensor(target, dtype=dtype, device=device)
        self.s_n = torch.as_tensor(np.abs(target).max(axis=(1, 2)), dtype=real, device=device)


def train_ensemble(train: InverseDataset, val: InverseDataset | None, config: TrainConfig, scaler: Scaler,
                   rig: Rig | None = None, bounds=BOUNDS, verbose: bool = True):
    """Train a deep ensemble; returns (EnsembleNet on CPU, history dict).

    History holds per-epoch training loss and validation MAE of the ensemble
    mean (normalised units) when ``val`` is given, plus timings.
    """
    if config.objective not in ("physics", "supervised"):
        raise ValueError(f"objective must be 'physics' or 'supervised', got {config.objective!r}")
    rig = Rig() if rig is None else rig
    device = pick_device(config.device)
    dtype = getattr(torch, config.twin_dtype)
    gen = torch.Generator().manual_seed(int(config.seed))
    noise_gen = torch.Generator(device=device).manual_seed(int(config.seed) + 1)
    net = EnsembleNet(config.n_members, generator=gen).to(device)
    tr = _Batches(train, scaler, bounds, device, dtype)
    va = _Batches(val, scaler, bounds, device, dtype) if val is not None and len(val) else None
    freq_t = torch.as_tensor(train.freq_hz, dtype=torch.float64 if dtype == torch.complex128 else torch.float32,
                             device=device)

    epochs = int(config.epochs)
    warm = int(config.warm_start_epochs) if config.objective == "physics" else 0
    warm = min(warm, epochs)
    steps_per_epoch = max(1, math.ceil(tr.n / config.batch_size))
    opt = torch.optim.Adam(net.parameters(), lr=config.lr, weight_decay=config.weight_decay)

    def lr_at(step, phase_start, phase_steps, peak):
        # cosine from the peak to lr_final within each phase (warm start, then main)
        t = min(1.0, (step - phase_start) / max(1, phase_steps))
        return config.lr_final + 0.5 * (peak - config.lr_final) * (1 + math.cos(math.pi * t))

    physics_lr = config.lr if config.physics_lr is None else config.physics_lr

    history = {"loss": [], "val_mae": [], "epoch_s": [], "phase": []}
    bar = _progress(epochs, verbose, f"train {config.objective}")
    t_start = time.perf_counter()
    with _cpu_threads(config.threads if device.type == "cpu" else None):
        _epochs(net, opt, tr, va, freq_t, config, rig, bounds, dtype, device, gen, noise_gen, warm, epochs,
                       steps_per_epoch, physics_lr, lr_at, history, bar)
    if bar is not None:
        bar.close()
    history["train_s"] = time.perf_counter() - t_start
    history["device"] = str(device)
    history["warm_start_epochs"] = warm
    return net.cpu().eval(), history


@contextlib.contextmanager
def _cpu_threads(n):
    """Torch CPU threads set to ``n`` for the block (the net is small: one thread is fastest,
    more only spin, badly so on a busy machine)."""
    before = torch.get_num_threads()
    if n:
        torch.set_num_threads(int(n))
    try:
        yield
    finally:
        torch.set_num_threads(before)


def _epochs(net, opt, tr, va, freq_t, config, rig, bounds, dtype, device, gen, noise_gen, warm, epochs,
            steps_per_epoch, physics_lr, lr_at, history, bar):
    """The training loop proper (mini-batches of all members at once)."""
    step = 0
    for epoch in range(epochs):
        t0 = time.perf_counter()
        phase = "supervised" if (config.objective == "supervised" or epoch < warm) else "physics"
        if phase == "physics" and config.objective == "physics" and epoch == warm and warm:
            opt = torch.optim.Adam(net.parameters(), lr=physics_lr, weight_decay=config.weight_decay)
        peak = physics_lr if (phase == "physics" and warm) else config.lr
        phase_start = 0 if epoch < warm or not warm else warm * steps_per_epoch
        phase_steps = (warm if epoch < warm else epochs - warm) * steps_per_epoch
        perm = torch.randperm(tr.n, generator=gen).to(device)
        total = 0.0
        net.train()
        for i in range(0, tr.n, config.batch_size):
            idx = perm[i:i + config.batch_size]
            x = tr.x[idx]
            if config.noise:
                eps = torch.randn((config.n_members,) + tuple(x.shape), generator=noise_gen, device=device)
                x = x.unsqueeze(0) + config.noise * tr.noise_unit[idx].unsqueeze(0) * eps
            for g in opt.param_groups:
                g["lr"] = lr_at(step, phase_start, phase_steps, peak)
            out = net(x)
            if phase == "physics":
                loss = physics_objective(out, tr.target[idx], tr.s_n[idx], freq_t, rig, bounds, dtype,
                                         config.precondition, config.max_step)
            else:
                loss = ((out - tr.y[idx]) ** 2).mean()
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            total += float(loss.detach()) * idx.numel()
            step += 1
        history["loss"].append(total / tr.n)
        history["phase"].append(phase)
        if va is not None:
            net.eval()
            with torch.no_grad():
                pred = net(va.x).mean(dim=0)
                history["val_mae"].append((pred - va.y).abs().mean(dim=0).tolist())
        history["epoch_s"].append(time.perf_counter() - t0)
        if bar is not None:
            post = {"loss": f"{history['loss'][-1]:.3g}", "phase": phase[:4]}
            if history["val_mae"]:
                post["val"] = f"{max(history['val_mae'][-1]):.2e}"
            bar.set_postfix(post, refresh=False)
            bar.update(1)


def _progress(total, verbose, desc):
    if not verbose or not sys.stderr.isatty():
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:  # pragma: no cover
        return None
    return tqdm(total=total, desc=desc, unit="epoch", leave=False)


def per_sample_epoch(net: EnsembleNet, train: InverseDataset, scaler: Scaler, rig: Rig | None = None,
                     bounds=BOUNDS, batch_size: int = 256, lr: float = 1e-3, max_samples: int | None = None,
                     dtype=torch.complex128, precondition: bool = True) -> float:
    """Seconds for one epoch of the *naive* physics training: a Python loop over samples.

    Each sample goes alone through the net and the twin; its gradient is
    accumulated, with one optimiser step per mini-batch (same maths as the
    vectorised step). Used by the benchmark to measure the speed-up; with
    ``max_samples`` only that many samples are timed and the time is scaled.
    """
    rig = Rig() if rig is None else rig
    tr = _Batches(train, scaler, bounds, torch.device("cpu"), dtype)
    freq_t = torch.as_tensor(train.freq_hz, dtype=torch.float64)
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    n = tr.n if max_samples is None else min(tr.n, max_samples)
    t0 = time.perf_counter()
    opt.zero_grad()
    for i in range(n):
        out = net(tr.x[i:i + 1])
        loss = physics_objective(out, tr.target[i:i + 1], tr.s_n[i:i + 1], freq_t, rig, bounds, dtype,
                                 precondition) / batch_size
        loss.backward()
        if (i + 1) % batch_size == 0 or i == n - 1:
            opt.step()
            opt.zero_grad()
    return (time.perf_counter() - t0) * tr.n / n

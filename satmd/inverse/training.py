"""Vectorised, seeded training of the inverse nets (needs torch).

One step pushes a whole mini-batch, for every ensemble member at once
(stacked weights, `satmd.inverse.nets.EnsembleNet`), through the network
and (for the physics objective) through the torch twin
``satmd.physics.torch.frf``: no Python loop over samples or members. The
data live on the training device for the whole run.

Objectives
----------
``physics`` (eq. 22)
    The predicted (R, L) are denormalised (eq. 20), sent back through the
    forward model with the rig's mechanical parameters, and the reconstructed
    accelerations are compared with the *noise-free* target FRFs:
    ``mean_n mean_j (|Â1 - A1|² + |Â2 - A2|²) / s_n²`` with
    ``s_n = max_{j, channel} |A_n|`` (|z|² = Re² + Im²); no labels in this phase.
    With ``precondition`` (default) every sample asks its outputs to move by
    its Gauss-Newton step of eq. 22 (`gauss_newton_step`; at most
    ``MAX_STEP``), because the FRFs are far less sensitive to R than to L and
    plain gradient steps leave R loose. By default (``jacobian="mobius"``)
    the residuals and their exact Jacobian come from
    `satmd.inverse.objective.ShuntMobius`: each acceleration is a Möbius map
    of the shunt impedance, fitted once from the twin, so no twin call is made
    per step. ``jacobian`` "shunt" / "fd" call the twin every step and take the
    Jacobian by finite differences (the method before issue 29). Without
    ``precondition`` the plain gradient of eq. 22 is back-propagated. A warm
    start of ``warm_start_epochs`` supervised epochs puts the nets near the
    solution first (the physics loss is flat far from it).
``supervised``
    Mean squared error on the normalised labels (the paper's "conventional
    supervised regressor" baseline).

Speed
-----
What a step costs on a CPU: the net's forward and backward (all members in
one ``baddbmm`` / ``bmm`` per layer: most of the time), Adam (fused:
unfused, the update cost as much as the net), and in the physics phase the
Gauss-Newton step. The default step (`satmd.inverse.steps.step_by_hand`) gets
d objective / d outputs from the objective and back-propagates it by hand
(`satmd.inverse.nets.EnsembleNet.set_grad`, the same products autograd
takes, without its graph), and evaluates the Möbius map instead of the twin
(a third of the twin step's time, and exact where complex64 finite
differences were not). Training is *step*-limited, not sample-limited:
at equal epochs a batch of 256 took a quarter of the steps and gave a
Table 2 MAE ten times worse at a third of the preset's data, and saved only
~20 % per sample on a CPU, so the default batch stays 64. On a GPU, raise
``batch_size`` together with ``epochs``.

Learning rate
-------------
``lr`` and ``physics_lr`` are the peak rates at a batch of ``REFERENCE_BATCH``
(64) samples; a batch of B samples uses ``lr * sqrt(B / 64)`` (the square-root
rule for Adam). Within each phase the rate follows a cosine from the peak
down to ``lr_final``.

Noise (eq. 23) is drawn afresh for every batch and member, and added to the
network inputs only; the physics target stays noise-free.

Members on their own samples
----------------------------
With ``members`` (cross-fitting, `satmd.inverse.strategies`) each member draws
its mini-batch from its own training set: the step still runs all members at
once, with inputs (E, B, 240) and targets (E, B, 2, F) instead of one batch
broadcast to every member. An epoch is the largest member's set. Measured
per training step (5 members x 64 samples, one thread; `benchmarks/inverse.py
--once`), the stacked weights with ``baddbmm`` beat ``torch.func.vmap`` over
``functional_call`` and a loop over members.
"""
from __future__ import annotations

import contextlib
import math
import time
from typing import Any

import numpy as np

from ..errors import DataError

try:
    import torch
except ImportError as exc:  # pragma: no cover
    raise ImportError("satmd.inverse needs torch: pip install 'satmd[nn]'") from exc

from ..physics import Rig
from .dataset import BOUNDS, InverseDataset
from .nets import EnsembleNet
from .objective import ShuntMobius, gauss_newton_step, physics_loss, physics_objective, real_of  # noqa: F401 - re-exported
from .batches import Batches, Scaler
from .config import TrainConfig  # noqa: F401 - re-exported (satmd.inverse.training.TrainConfig)
from .steps import TrainingRun, run_phase

REFERENCE_BATCH = 64  # the batch at which ``lr`` is quoted (sqrt rule above)
_Batches = Batches  # the name before the batches moved to their own module (steps and training share them)


def pick_device(device=None) -> torch.device:
    """``None``/"auto": CUDA when present, else CPU."""
    if device in (None, "auto"):
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(device)


def check_device(device) -> None:
    """Refuse, before any work, a device other than "cpu", "cuda", "cuda:N" or None, or CUDA torch cannot see."""
    from ..errors import SatmdError

    if device is None or device == "cpu":
        return
    kind, _, index = str(device).partition(":")
    if kind != "cuda" or (index and not index.isdigit()):
        raise SatmdError(f"device {device!r}: use cpu, cuda or cuda:N")
    count = torch.cuda.device_count() if torch.cuda.is_available() else 0
    if count == 0:
        raise SatmdError(f"device {device}: torch sees no CUDA device here; use cpu")
    if index and int(index) >= count:
        raise SatmdError(f"device {device}: torch sees {count} CUDA device(s), cuda:0..cuda:{count - 1}")


def scaled_lr(lr: float, batch_size: int) -> float:
    """Peak learning rate for ``batch_size`` from the rate quoted at `REFERENCE_BATCH`."""
    return float(lr) * math.sqrt(int(batch_size) / REFERENCE_BATCH)


def train_ensemble(train: InverseDataset, val: InverseDataset | None, config: TrainConfig, scaler: Scaler,
                   rig: Rig | None = None, bounds=BOUNDS, verbose: bool = True, members=None):
    """Train a deep ensemble; returns (EnsembleNet on CPU, history dict).

    Parameters
    ----------
    train, val : training data and optional validation data (its MAE is recorded in the history)
    members : None (every member trains on every sample) or a boolean array (n_members, len(train)):
        the samples each member trains on (cross-fitting); the members still train together, one
        batched step for all, each on its own mini-batch
    config : resolved settings (`InverseModel.train_config`)
    scaler : input standardisation
    rig : fixed mechanical parameters (default: the paper's rig)
    bounds : output normalisation bounds (eq. 20)
    verbose : progress on stderr

    Returns
    -------
    (EnsembleNet, dict) : the nets and the history (loss per epoch, validation
        MAE in normalised units, timings, device, warm-start epochs).
    """
    if config.objective not in ("physics", "supervised"):
        raise DataError(f"objective must be 'physics' or 'supervised', got {config.objective!r}")
    rig = Rig() if rig is None else rig
    device = pick_device(config.device)
    dtype = getattr(torch, config.twin_dtype)
    gen = torch.Generator().manual_seed(int(config.seed))
    noise_gen = torch.Generator(device=device).manual_seed(int(config.seed) + 1)
    net = EnsembleNet(config.n_members, generator=gen).to(device)
    if members is not None and np.shape(members) != (config.n_members, len(train)):
        raise DataError(f"members must be a boolean array ({config.n_members}, {len(train)}), got {np.shape(members)}")
    if members is not None and not np.all(np.any(members, axis=1)):
        raise DataError("every ensemble member needs training samples")
    tr = Batches(train, scaler, bounds, device, dtype, members)
    va = Batches(val, scaler, bounds, device, dtype) if val is not None and len(val) else None
    freq_t = torch.as_tensor(train.freq_hz, dtype=real_of(dtype), device=device)

    warm = min(int(config.warm_start_epochs), int(config.epochs)) if config.objective == "physics" else 0
    phases = []  # (objective, epochs, peak lr at the reference batch)
    if warm:
        phases.append(("supervised", warm, config.lr))
    main_epochs = int(config.epochs) - warm
    main_lr = config.physics_lr if warm else config.lr
    if main_epochs:
        phases.append((config.objective, main_epochs, main_lr))

    history: dict[str, Any] = {"loss": [], "val_mae": [], "val_epoch": [], "epoch_s": [], "phase": []}
    total_epochs = sum(p[1] for p in phases)
    bar = _progress(total_epochs, verbose, f"train {config.objective}")
    t_start = time.perf_counter()
    mobius = ShuntMobius.fit(freq_t, rig, bounds, dtype) if config.jacobian == "mobius" else None
    if config.jacobian == "mobius":
        history["mobius"] = mobius is not None  # False: the twin's accelerations are not of that form here
    run = TrainingRun(net, tr, va, freq_t, config, rig, bounds, dtype, gen, noise_gen, total_epochs, history, bar,
                      mobius)
    with _cpu_threads(config.threads if device.type == "cpu" else None):
        for objective, n_epochs, peak in phases:
            # a fresh Adam per phase: the moment estimates of the other loss do not carry over
            opt = _adam(net, scaled_lr(peak, config.batch_size), device, direct=run.by_hand)
            run_phase(run, opt, objective, n_epochs, scaled_lr(peak, config.batch_size))
    if bar is not None:
        bar.close()
    history["train_s"] = time.perf_counter() - t_start
    history["device"] = str(device)
    history["warm_start_epochs"] = warm
    return net.cpu().eval(), history


class FusedAdam:
    """``torch.optim.Adam(fused=True)``'s update (the same kernel, ``torch._fused_adam_``, the same state, bit
    for bit) without `torch.optim.Optimizer`'s machinery: its first use imports ``torch._dynamo`` (about 1.6 s
    of CPU) and its per-step wrappers cost about as much as the kernel on this small net. Only ``lr`` in
    ``param_groups[0]`` may change between steps; betas, eps as torch's defaults, no weight decay."""

    def __init__(self, params, lr: float):
        self.params = [p for p in params if p.requires_grad]
        self.param_groups = [{"lr": float(lr)}]
        self.exp_avg = [torch.zeros_like(p, memory_format=torch.preserve_format) for p in self.params]
        self.exp_avg_sq = [torch.zeros_like(p, memory_format=torch.preserve_format) for p in self.params]
        self.steps = [torch.tensor(0.0, dtype=torch.float32, device=p.device) for p in self.params]

    @staticmethod
    def available(device) -> bool:
        """Whether this torch has the fused kernel for ``device`` (else `_adam` gives torch's Adam)."""
        return device.type in ("cpu", "cuda") and hasattr(torch, "_fused_adam_")

    def step(self) -> None:
        with torch.no_grad():
            torch._foreach_add_(self.steps, 1)
            torch._fused_adam_(self.params, [p.grad for p in self.params], self.exp_avg, self.exp_avg_sq, [],
                               self.steps, amsgrad=False, lr=float(self.param_groups[0]["lr"]), beta1=0.9,
                               beta2=0.999, weight_decay=0.0, eps=1e-8, maximize=False, grad_scale=None,
                               found_inf=None)


def _adam(net, lr, device, direct: bool = False):
    """Adam, fused where torch has it (one kernel for all parameters: the unfused update costs as much as
    the forward and backward passes of this small net on a CPU); ``direct``: `FusedAdam` where available
    (the by-hand step; the same numbers, less overhead)."""
    if direct and FusedAdam.available(device):
        return FusedAdam(net.parameters(), lr)
    try:
        return torch.optim.Adam(net.parameters(), lr=lr, fused=device.type in ("cpu", "cuda"))
    except (RuntimeError, TypeError):  # pragma: no cover - older torch or another device
        return torch.optim.Adam(net.parameters(), lr=lr)


@contextlib.contextmanager
def _cpu_threads(n):
    """Torch CPU threads set to ``n`` for the block (on a small shared machine more threads only spin)."""
    before = torch.get_num_threads()
    if n:
        torch.set_num_threads(int(n))
    try:
        yield
    finally:
        torch.set_num_threads(before)


def _progress(total, verbose, desc):
    from .._progress import progress  # a bar on a terminal, periodic lines otherwise

    return progress(total, desc, "epoch", enabled=verbose)


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
    tr = Batches(train, scaler, bounds, torch.device("cpu"), dtype)
    freq_t = torch.as_tensor(train.freq_hz, dtype=real_of(dtype))
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    n = tr.n if max_samples is None else min(tr.n, max_samples)
    t0 = time.perf_counter()
    opt.zero_grad()
    for i in range(n):
        out = net(tr.x[i:i + 1])
        obj, _ = physics_objective(out, tr.target[i:i + 1], tr.s_n[i:i + 1], freq_t, rig, bounds, dtype,
                                   precondition)
        (obj / batch_size).backward()
        if (i + 1) % batch_size == 0 or i == n - 1:
            opt.step()
            opt.zero_grad()
    return (time.perf_counter() - t0) * tr.n / n

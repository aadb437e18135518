"""One phase of training, step by step (`satmd.inverse.training.train_ensemble` runs the phases).

Two ways to take a step. `step_by_hand` (the default, ``jacobian="mobius"``)
asks the objective for d objective / d outputs and back-propagates it through
the net by hand (`satmd.inverse.nets.EnsembleNet.set_grad`), with the
residuals and the Gauss-Newton step from `satmd.inverse.objective.ShuntMobius`.
`autograd_step` (``jacobian`` "shunt" or "fd") is the step of the method before
issue 29, kept bit for bit: the surrogate objective through autograd and the
twin called every step.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import torch

from ..physics import Rig
from .batches import Batches
from .config import TrainConfig
from .nets import EnsembleNet
from .objective import MAX_STEP, ShuntMobius, gauss_newton_step, physics_loss, physics_objective

N_VAL_POINTS = 20  # validation MAE is recorded this many times per run (cheap history, not every epoch)


@dataclass
class TrainingRun:
    """What the phases of one training share (`run_phase`); `satmd.inverse.training.train_ensemble` builds it."""

    net: EnsembleNet
    tr: Batches
    va: Batches | None
    freq_t: torch.Tensor
    config: TrainConfig
    rig: Rig
    bounds: dict
    dtype: torch.dtype
    gen: torch.Generator
    noise_gen: torch.Generator
    total_epochs: int
    history: dict
    bar: Any  # `satmd._progress.progress`: a tqdm bar or a LineProgress; None: quiet
    mobius: ShuntMobius | None = None

    @property
    def by_hand(self) -> bool:
        """Back-propagation by hand (`EnsembleNet.set_grad`): the default ``jacobian="mobius"``; the other
        settings keep the autograd step of the method before issue 29, bit for bit."""
        return self.config.jacobian == "mobius"


def run_phase(run: TrainingRun, opt, objective: str, n_epochs: int, peak: float) -> None:
    """One phase of mini-batch epochs (all members at once), cosine learning rate from ``peak``."""
    net, tr, va, config, history = run.net, run.tr, run.va, run.config, run.history
    device = tr.x.device
    batch = int(config.batch_size)
    steps = n_epochs * max(1, math.ceil(tr.n_epoch / batch))
    val_every = max(1, math.ceil(run.total_epochs / N_VAL_POINTS))
    step = 0
    for _ in range(n_epochs):
        t0 = time.perf_counter()
        order = tr.epoch_order(run.gen)
        total = torch.zeros((), device=device)  # summed on the device: no host sync per step
        net.train()
        for i in range(0, tr.n_epoch, batch):
            idx = order[..., i:i + batch]  # (B,) shared by the members, or (E, B): one mini-batch per member
            x = tr.x[idx]
            if config.noise:
                eps = torch.randn(x.shape if x.ndim == 3 else (net.n_members,) + tuple(x.shape),
                                  generator=run.noise_gen, device=device)
                x = x + config.noise * tr.noise_unit[idx] * eps
            t = min(1.0, step / max(1, steps))
            for g in opt.param_groups:
                g["lr"] = config.lr_final + 0.5 * (peak - config.lr_final) * (1 + math.cos(math.pi * t))
            loss = (step_by_hand if run.by_hand else autograd_step)(run, opt, objective, x, idx)
            total += loss.detach().to(total.dtype) * idx.shape[-1]
            step += 1
        history["loss"].append(float(total) / tr.n_epoch)
        history["phase"].append(objective)
        epoch = len(history["loss"])
        if va is not None and (epoch % val_every == 0 or epoch == run.total_epochs):
            net.eval()
            with torch.no_grad():
                pred = net(va.x).mean(dim=0)
                history["val_mae"].append((pred - va.y).abs().mean(dim=0).tolist())
                history["val_epoch"].append(epoch)
        history["epoch_s"].append(time.perf_counter() - t0)
        if run.bar is not None:
            post = {"loss": f"{history['loss'][-1]:.3g}", "phase": objective[:4]}
            if history["val_mae"]:
                post["val"] = f"{max(history['val_mae'][-1]):.2e}"
            run.bar.set_postfix(post, refresh=False)
            run.bar.update(1)


def autograd_step(run: TrainingRun, opt, objective: str, x, idx):
    """One optimiser step through autograd (the method before issue 29); returns the batch's mean loss."""
    out = run.net(x)
    if objective == "physics":
        obj, loss = physics_objective(out, run.tr.target[idx], run.tr.s_n[idx], run.freq_t, run.rig, run.bounds,
                                      run.dtype, run.config.precondition, run.config.jacobian)
    else:
        obj = loss = ((out - run.tr.y[idx]) ** 2).mean()
    opt.zero_grad(set_to_none=True)
    obj.backward()
    opt.step()
    return loss


def step_by_hand(run: TrainingRun, opt, objective: str, x, idx):
    """One optimiser step with the gradient propagated by hand (`EnsembleNet.set_grad`); returns the mean loss.

    The objectives give d objective / d outputs directly: supervised ``2 (out - y) / size``; physics with
    ``precondition`` each sample's clipped Gauss-Newton step / (E n) (the gradient of `physics_objective`'s
    surrogate); physics without it the gradient of eq. 22 through the Möbius map (or the twin).
    """
    out, acts = run.net.train_forward(x)
    if objective == "physics":
        target, s_n = run.tr.target[idx], run.tr.s_n[idx]
        if run.config.precondition:
            if run.mobius is not None:
                step, loss = run.mobius.gauss_newton_step(out, target, s_n)
            else:
                step, loss = gauss_newton_step(out, target, s_n, run.freq_t, run.rig, run.bounds, run.dtype)
            grad = step.clamp(-MAX_STEP, MAX_STEP).to(out.dtype) * (1.0 / out[..., 0].numel())
            loss = loss.mean()
        else:
            o = out.detach().requires_grad_(True)
            with torch.enable_grad():
                per = (run.mobius.physics_loss(o, target, s_n) if run.mobius is not None else
                       physics_loss(o, target, s_n, run.freq_t, run.rig, run.bounds, run.dtype))
                loss = per.mean()
                (grad,) = torch.autograd.grad(loss, o)
    else:
        diff = out - run.tr.y[idx]
        loss = (diff * diff).mean()
        grad = diff * (2.0 / diff.numel())
    run.net.set_grad(acts, out, grad)
    opt.step()
    return loss

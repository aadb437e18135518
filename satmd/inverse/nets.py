"""Torch modules of the inverse model (imported on demand; needs torch).

``InverseNet`` is the network of SPEC §5: 240 -> 256 -> 128 -> 64 -> 2, ReLU
hidden layers, sigmoid output (normalised R, L in [0, 1]); its 64-wide layer
is the latent of use case III.

``EnsembleNet`` holds ``n_members`` such nets with stacked weights, so that a
deep ensemble is trained as one batched computation (``torch.baddbmm``),
never a Python loop over members or samples. ``EnsembleNet.member(k)``
returns member ``k`` as a plain ``InverseNet`` with a copy of its weights.
For training, `EnsembleNet.train_forward` and `EnsembleNet.set_grad` run the
pass and its back-propagation by hand (no autograd graph): the objectives
give the gradient with respect to the outputs directly, and on a CPU the
autograd engine cost about 15 % of a training step of this small net.
"""
from __future__ import annotations

import math

try:
    import torch
    from torch import nn
except ImportError as exc:  # pragma: no cover - exercised only without torch
    raise ImportError("satmd.inverse needs torch: pip install 'satmd[nn]'") from exc

SIZES = (240, 256, 128, 64, 2)


class InverseNet(nn.Module):
    """One inverse net: scaled features (n, 240) float32 -> normalised [r, l] (n, 2) in [0, 1]."""

    def __init__(self, sizes=SIZES):
        super().__init__()
        self.sizes = tuple(int(s) for s in sizes)
        self.layers = nn.ModuleList(nn.Linear(a, b) for a, b in zip(self.sizes[:-1], self.sizes[1:]))

    def latent(self, x: torch.Tensor) -> torch.Tensor:
        """Activations of the last hidden layer (n, 64)."""
        for layer in self.layers[:-1]:
            x = torch.relu(layer(x))
        return x

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(self.layers[-1](self.latent(x)))


class EnsembleNet(nn.Module):
    """``n_members`` InverseNets evaluated together: (n, d) or (E, n, d) -> (E, n, 2)."""

    def __init__(self, n_members: int = 5, sizes=SIZES, generator: torch.Generator | None = None):
        super().__init__()
        self.n_members = int(n_members)
        self.sizes = tuple(int(s) for s in sizes)
        self.weights = nn.ParameterList()
        self.biases = nn.ParameterList()
        for a, b in zip(self.sizes[:-1], self.sizes[1:]):
            # the default nn.Linear initialisation, member by member
            bound = 1.0 / math.sqrt(a)
            w = (torch.rand(self.n_members, a, b, generator=generator) * 2 - 1) * bound
            c = (torch.rand(self.n_members, 1, b, generator=generator) * 2 - 1) * bound
            self.weights.append(nn.Parameter(w))
            self.biases.append(nn.Parameter(c))

    def _broadcast(self, x):
        if x.ndim == 2:
            x = x.unsqueeze(0).expand(self.n_members, -1, -1)
        return x

    def latent(self, x: torch.Tensor) -> torch.Tensor:
        x = self._broadcast(x)
        for w, b in zip(list(self.weights)[:-1], list(self.biases)[:-1]):
            x = torch.relu(torch.baddbmm(b, x, w))
        return x

    def logits(self, x: torch.Tensor) -> torch.Tensor:
        return torch.baddbmm(self.biases[-1], self.latent(x), self.weights[-1])

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(self.logits(x))

    def train_forward(self, x: torch.Tensor):
        """Outputs (E, n, 2) and the layer inputs `set_grad` needs, without autograd."""
        ws, bs = list(self.weights), list(self.biases)
        with torch.no_grad():
            acts = [self._broadcast(x)]
            h = acts[0]
            for w, b in zip(ws[:-1], bs[:-1]):
                h = torch.baddbmm(b, h, w).relu_()
                acts.append(h)
            out = torch.baddbmm(bs[-1], h, ws[-1]).sigmoid_()
        return out, acts

    def set_grad(self, acts, out: torch.Tensor, grad_out: torch.Tensor) -> None:
        """Back-propagate d objective / d outputs (E, n, 2) through `train_forward`'s pass into each ``.grad``.

        The gradients are written (not accumulated) into buffers kept between calls.
        """
        ws, bs = list(self.weights), list(self.biases)
        with torch.no_grad():
            dz = torch.ops.aten.sigmoid_backward(grad_out, out)
            for k in range(len(ws) - 1, -1, -1):
                w, b, h = ws[k], bs[k], acts[k]
                if w.grad is None:
                    w.grad, b.grad = torch.empty_like(w), torch.empty_like(b)
                torch.bmm(h.transpose(1, 2), dz, out=w.grad)
                torch.sum(dz, dim=1, keepdim=True, out=b.grad)
                if k:
                    dz = torch.ops.aten.threshold_backward(torch.bmm(dz, w.transpose(1, 2)), h, 0.0)  # the ReLU

    def member(self, k: int) -> InverseNet:
        net = InverseNet(self.sizes)
        with torch.no_grad():
            for layer, w, b in zip(net.layers, self.weights, self.biases):
                layer.weight.copy_(w[k].T)
                layer.bias.copy_(b[k, 0])
        return net.eval()

    def members(self) -> list[InverseNet]:
        return [self.member(k) for k in range(self.n_members)]

"""Torch modules of the inverse model (imported on demand; needs torch).

``InverseNet`` is the network of SPEC §5: 240 -> 256 -> 128 -> 64 -> 2, ReLU
hidden layers, sigmoid output (normalised R, L in [0, 1]); its 64-wide layer
is the latent of use case III.

``EnsembleNet`` holds ``n_members`` such nets with stacked weights, so that a
deep ensemble is trained as one batched computation (``torch.baddbmm``),
never a Python loop over members or samples. ``EnsembleNet.member(k)``
returns member ``k`` as a plain ``InverseNet`` with a copy of its weights.
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

    def member(self, k: int) -> InverseNet:
        net = InverseNet(self.sizes)
        with torch.no_grad():
            for layer, w, b in zip(net.layers, self.weights, self.biases):
                layer.weight.copy_(w[k].T)
                layer.bias.copy_(b[k, 0])
        return net.eval()

    def members(self) -> list[InverseNet]:
        return [self.member(k) for k in range(self.n_members)]

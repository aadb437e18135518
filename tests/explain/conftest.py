"""A small stand-in for a trained inverse model, following the contract of
`satmd.inverse.InverseModel` that `satmd.explain` relies on (see
`satmd.explain.contract.ExplainableModel`): the SPEC §5 architecture (240 -> 256 -> 128 ->
64 -> 2, ReLU, sigmoid), briefly trained on labels so that the latent carries
R and L, with a per-feature standardisation ``scaler_``."""
import numpy as np
import pytest

torch = pytest.importorskip("torch")
torch.set_num_threads(1)

from satmd.physics import PAPER_GRID_HZ, Rig, frf  # noqa: E402
from satmd.inverse.dataset import features_to_complex  # noqa: E402

BOUNDS = {"R": (0.0, 103.0), "L": (0.0, 0.5)}


class Net(torch.nn.Module):
    def __init__(self, sizes=(240, 256, 128, 64, 2)):
        super().__init__()
        self.layers = torch.nn.ModuleList(torch.nn.Linear(a, b) for a, b in zip(sizes[:-1], sizes[1:]))

    def latent(self, x):
        for layer in self.layers[:-1]:
            x = torch.relu(layer(x))
        return x

    def forward(self, x):
        return torch.sigmoid(self.layers[-1](self.latent(x)))


class Scaler:
    def __init__(self, mean, scale):
        self.mean, self.scale = np.asarray(mean, float), np.asarray(scale, float)

    def transform(self, x):
        return ((np.asarray(x, float) - self.mean) / self.scale).astype(np.float32)


def simulate(R, L, freq=PAPER_GRID_HZ):
    """Raw features (n, 240) [Re A1, Re A2, Im A1, Im A2] and labels."""
    r = frf(freq, Rig(R=np.asarray(R, float), L=np.asarray(L, float)), outputs=("a1", "a2"))
    z = np.concatenate([r.a1, r.a2], axis=-1)
    return np.concatenate([z.real, z.imag], axis=-1)


class StandInModel:
    kind = "physics"
    preset = "paper"
    seed = 0

    def __init__(self, n_members=2, steps=150, seed=0):
        self.freq_hz = PAPER_GRID_HZ.copy()
        self.bounds = dict(BOUNDS)
        self.rig = Rig()
        rng = np.random.default_rng(seed)
        R = rng.uniform(3, 100, 400)
        L = rng.uniform(0.01, 0.49, 400)
        X = simulate(R, L)
        self.scaler_ = Scaler(X.mean(axis=0), X.std(axis=0))
        Xs = torch.as_tensor(self.scaler_.transform(X))
        Y = torch.as_tensor(np.stack([R / 103.0, L / 0.5], axis=1), dtype=torch.float32)
        torch.manual_seed(seed)
        self.networks_ = []
        for _ in range(n_members):
            net = Net()
            opt = torch.optim.Adam(net.parameters(), lr=3e-3)
            for _ in range(steps):
                opt.zero_grad()
                loss = ((net(Xs) - Y) ** 2).mean()
                loss.backward()
                opt.step()
            net.eval()
            for p in net.parameters():
                p.requires_grad_(False)
            self.networks_.append(net)

    def _raw(self, x):
        x = np.asarray(x)
        if np.iscomplexobj(x):
            z = x.reshape(x.shape[0], -1)
            return np.concatenate([z.real, z.imag], axis=-1)
        return x.reshape(-1, 240)

    def as_complex(self, x):
        if hasattr(x, "a1"):  # a dataset or a Response
            x = np.stack([x.a1, x.a2], axis=-2)
        x = np.asarray(x)
        if not np.iscomplexobj(x):
            x = features_to_complex(x.reshape(-1, 240))
        return x.reshape(-1, 2, x.shape[-1]), None

    def features(self, x):
        return self.scaler_.transform(self._raw(x))

    def latent(self, x, member=0):
        with torch.no_grad():
            return self.networks_[member].latent(torch.as_tensor(self.features(x))).numpy()

    def predict(self, x):
        with torch.no_grad():
            out = torch.stack([n(torch.as_tensor(self.features(x))) for n in self.networks_]).numpy()
        m, s = out.mean(0), out.std(0)
        return {"R": 103 * m[:, 0], "L": 0.5 * m[:, 1], "R_std": 103 * s[:, 0], "L_std": 0.5 * s[:, 1]}


@pytest.fixture(scope="session")
def standin():
    return StandInModel()


@pytest.fixture(scope="session")
def labelled():
    rng = np.random.default_rng(5)
    R = rng.uniform(5, 95, 120)
    L = rng.uniform(0.02, 0.45, 120)
    return {"a1a2_raw": simulate(R, L), "R": R, "L": L}

"""`InverseModel`: acceleration FRFs -> shunt R, L with standard deviations (use case II).

Kinds
-----
``physics``
    A deep ensemble of the SPEC §5 net trained through the torch twin with
    the physics-consistent loss of eq. 22 (predictions go back through the
    forward model). A supervised warm start precedes it by default
    (``warm_start_epochs`` of the ``epochs``; reported in ``fit_info_``), and
    the eq. 22 gradient is preconditioned per sample by its 2x2 Gauss-Newton
    matrix (``precondition``), because the FRFs are far less sensitive to R
    than to L (`satmd.inverse.training.physics_objective`).
``supervised``
    The same ensemble trained by MSE on normalised labels (the baseline the
    paper's discussion asks for).
``optimization``
    Repeated global least squares per FRF (`satmd.identify.identify_many`,
    free R and L); nothing to train.
``hybrid``
    The physics net's prediction refined by a few least-squares steps
    (`satmd.identify.identify`, start at the net's R, L, no global search).

Uncertainty (net kinds)
-----------------------
``std² = c² (σ_ens² + σ_noise²)`` per output, where σ_ens is the spread of
the ensemble members, σ_noise the spread of the ensemble mean when the input
is perturbed again by its measurement noise (Monte Carlo, ``mc_samples``
draws: the noise std columns of FRFData when given, else the training noise
level), and ``c`` a factor fitted on the validation pairs so that
``|error| <= 2 std`` holds for 95 % of them (``std_scale_``). With ``refit``
(default) the nets are then trained again on every pair, keeping ``c``. The
optimisation kinds report the Jacobian standard errors of their fit.

Contract for the explainability package
---------------------------------------
- ``model.networks_``: list of ``torch.nn.Module`` (``InverseNet``), each
  mapping float32 *scaled* features (n, 240) -- i.e. ``model.features(x)`` --
  to normalised outputs (n, 2) in [0, 1] (r, l of eq. 19-20).
- ``model.features(x)``: (n, 240) float32, raw features
  [Re A1, Re A2, Im A1, Im A2] (the ordering of
  ``satmd.physics.torch.features``) standardised per feature with the
  training mean / std (``model.scaler_``).
- ``model.latent(x, member=0)``: (n, 64) activations of member 0 (latent
  spaces of different members are not aligned, so they are not averaged).
- ``satmd.inverse.normalised_outputs(model, X)``: differentiable ensemble-mean
  normalised outputs for gradient attribution.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from ..errors import DataError, SatmdError
from ..physics import PAPER_GRID_HZ, Rig
from .dataset import BOUNDS, PRESETS, InverseDataset, complex_to_features, features_to_complex, make_dataset

KINDS = ("physics", "supervised", "optimization", "hybrid")
NET_KINDS = ("physics", "supervised", "hybrid")

#: Defaults per preset (a user of `satmd inverse train` gets these).
PRESET_DEFAULTS = {
    "paper": {"samples_per_pair": 150, "epochs": 90, "warm_start_epochs": 50},
    "box": {"n_samples": 6000, "epochs": 90, "warm_start_epochs": 50},
}


def _torch():
    try:
        import torch
    except ImportError as exc:
        raise ImportError("the inverse nets need torch: pip install 'satmd[nn]'") from exc
    return torch


class InverseModel:
    """Amortized inverse: acceleration FRFs (a1, a2) -> R, L with standard deviations.

    Parameters
    ----------
    kind : "physics", "supervised", "optimization" or "hybrid"
    preset : training data, "paper" (30 reference pairs) or "box" (R, L independent)
    noise : relative input noise (eq. 23) used in training, e.g. 0.01
    epochs, warm_start_epochs, batch_size, lr, physics_lr, lr_final, n_members : training
        (epochs in total, the first ``warm_start_epochs`` of them supervised for
        the physics kind; defaults per preset in ``PRESET_DEFAULTS``)
    samples_per_pair, n_samples, val_fraction : data (see `make_dataset`)
    refit : after calibrating the std on the validation pairs, train the nets
        again on all pairs (same settings; the calibration is kept). The
        validation figures in ``fit_info_`` are those of the first, held-out fit.
    precondition : physics kind: Gauss-Newton preconditioning of the eq. 22
        gradient (see `satmd.inverse.training.physics_objective`)
    mc_samples : Monte Carlo draws for the noise part of the std
    refine_nfev : least-squares evaluations of the hybrid refinement
    seed : every random number derives from it
    device : "cpu", "cuda" or None (CUDA when present)
    threads : torch CPU threads during training (default 1, the fastest for
        this small net; None leaves torch's setting)
    verbose : progress bar (only on a terminal)
    rig : fixed mechanical parameters (default: the paper's rig)
    freq_hz : frequency grid (default: the paper's 60 points)
    """

    def __init__(self, kind: str = "physics", preset: str = "paper", noise: float = 0.0, *,
                 epochs: int | None = None, warm_start_epochs: int | None = None, batch_size: int = 64,
                 lr: float = 1e-3, physics_lr: float = 3e-4, lr_final: float = 1e-5, n_members: int = 5,
                 precondition: bool = True, threads: int | None = 1,
                 samples_per_pair: int | None = None, n_samples: int | None = None, val_fraction: float = 0.2,
                 refit: bool = True, mc_samples: int = 64, refine_nfev: int | None = 20, seed: int = 0,
                 device: str | None = None, verbose: bool = True, rig: Rig | None = None, freq_hz=None):
        self.kind = kind
        self.preset = preset
        self.noise = noise
        self.epochs = epochs
        self.warm_start_epochs = warm_start_epochs
        self.batch_size = batch_size
        self.lr = lr
        self.physics_lr = physics_lr
        self.precondition = precondition
        self.threads = threads
        self.lr_final = lr_final
        self.n_members = n_members
        self.samples_per_pair = samples_per_pair
        self.n_samples = n_samples
        self.val_fraction = val_fraction
        self.refit = refit
        self.mc_samples = mc_samples
        self.refine_nfev = refine_nfev
        self.seed = seed
        self.device = device
        self.verbose = verbose
        self.rig = Rig() if rig is None else rig
        self.freq_hz = np.asarray(PAPER_GRID_HZ if freq_hz is None else freq_hz, float)
        self.bounds = {k: tuple(v) for k, v in BOUNDS.items()}
        self._validate()
        self.networks_: list = []
        self.ensemble_ = None
        self.scaler_ = None
        self.std_scale_ = np.ones(2)
        self.history_: dict = {}
        self.fit_info_: dict = {}

    # ------------------------------------------------------------------ setup
    def _validate(self):
        if self.kind not in KINDS:
            raise SatmdError(f"unknown kind {self.kind!r}; choose from {', '.join(KINDS)}")
        if self.preset not in PRESETS:
            raise SatmdError(f"unknown preset {self.preset!r}; choose from {', '.join(PRESETS)}")
        if not (np.isfinite(self.noise) and 0 <= self.noise < 1):
            raise SatmdError(f"noise must be a relative level in [0, 1), got {self.noise}")
        if int(self.n_members) < 1:
            raise SatmdError(f"n_members must be >= 1, got {self.n_members}")
        if self.rig.batch_shape != ():
            raise SatmdError("the inverse model takes a single rig")

    def _resolved(self, name):
        value = getattr(self, name)
        return PRESET_DEFAULTS[self.preset].get(name) if value is None else value

    @property
    def is_fitted(self) -> bool:
        return bool(self.fit_info_)

    def _check_fitted(self):
        if not self.is_fitted:
            raise SatmdError("this InverseModel is not fitted yet: call fit() or InverseModel.load()")

    # -------------------------------------------------------------------- fit
    def make_data(self) -> InverseDataset:
        """The training data of this model's preset (train and validation partitions)."""
        kw = {"samples_per_pair": self._resolved("samples_per_pair") or PRESET_DEFAULTS["paper"]["samples_per_pair"],
              "n_samples": self._resolved("n_samples") or PRESET_DEFAULTS["box"]["n_samples"]}
        return make_dataset(self.preset, val_fraction=self.val_fraction, seed=self.seed, freq_hz=self.freq_hz,
                            rig=self.rig, **kw)

    def fit(self, data: InverseDataset | None = None) -> "InverseModel":
        """Train (net kinds) or set up (optimization). Returns self.

        ``data``: an `InverseDataset` (default: built from the preset).
        """
        self._validate()
        t0 = time.perf_counter()
        c0 = time.process_time()
        info = {"kind": self.kind, "preset": self.preset, "noise": float(self.noise), "seed": int(self.seed)}
        if self.kind == "optimization":
            self.fit_info_ = {**info, "train_s": 0.0, "train_cpu_s": 0.0}
            return self
        torch = _torch()
        from .training import Scaler, TrainConfig, train_ensemble

        data = self.make_data() if data is None else data
        if not np.allclose(data.freq_hz, self.freq_hz):
            raise DataError("training data and model use different frequency grids")
        train, val = data.train, data.val
        if len(train) == 0:
            raise DataError("no training samples")
        config = TrainConfig(
            objective="supervised" if self.kind == "supervised" else "physics",
            epochs=int(self._resolved("epochs")), warm_start_epochs=int(self._resolved("warm_start_epochs")),
            batch_size=int(self.batch_size), lr=float(self.lr), physics_lr=float(self.physics_lr),
            lr_final=float(self.lr_final), precondition=bool(self.precondition), threads=self.threads,
            n_members=int(self.n_members), noise=float(self.noise), seed=int(self.seed), device=self.device)
        torch.manual_seed(int(self.seed))
        self.scaler_ = Scaler.fit(train.features())
        ensemble, history = train_ensemble(train, val if len(val) else None, config, self.scaler_, self.rig,
                                           self.bounds, verbose=self.verbose)
        self._set_ensemble(ensemble)
        self.history_ = history
        self.fit_info_ = {
            **info, "objective": config.objective, "config": config.to_dict(), "dataset": data.info,
            "n_train": len(train), "n_val": len(val), "device": history["device"],
            "warm_start_epochs": history["warm_start_epochs"], "refit": False,
        }
        if len(val):
            self.fit_info_.update(self._calibrate(val))
            if self.refit:
                # the calibration stays; the nets are trained again on every pair
                self.scaler_ = Scaler.fit(data.features())
                ensemble, history = train_ensemble(data, None, config, self.scaler_, self.rig, self.bounds,
                                                   verbose=self.verbose)
                self._set_ensemble(ensemble)
                self.history_["refit_loss"] = history["loss"]
                self.fit_info_.update(refit=True, n_final=len(data))
        self.fit_info_.update(train_s=time.perf_counter() - t0, train_cpu_s=time.process_time() - c0)
        return self

    def _set_ensemble(self, ensemble):
        self.ensemble_ = ensemble.eval()
        for p in self.ensemble_.parameters():
            p.requires_grad_(False)
        self.networks_ = ensemble.members()
        for net in self.networks_:
            for p in net.parameters():
                p.requires_grad_(False)

    def _calibrate(self, val: InverseDataset) -> dict:
        """Fit ``std_scale_`` so that 95 % of validation errors lie within 2 std."""
        rng = np.random.default_rng(int(self.seed) + 7)
        a = np.stack([val.a1, val.a2], axis=1)
        std = None
        if self.noise:
            std = self.noise * np.abs(a)
            a = a + std * (rng.standard_normal(a.shape) + 1j * rng.standard_normal(a.shape))
        self.std_scale_ = np.ones(2)
        mean, sd = self._net_predict(a, std, normalised=True)
        err = np.abs(mean - val.labels_normalised(self.bounds))
        z = err / np.maximum(sd, 1e-12)
        self.std_scale_ = np.maximum(np.quantile(z, 0.95, axis=0) / 2.0, 1e-6)
        return {"std_scale": self.std_scale_.tolist(),
                "val_mae": (err.mean(axis=0) * self._span()).tolist(),
                "val_coverage_2sd": float(np.mean(err <= 2 * sd * self.std_scale_))}

    # ---------------------------------------------------------------- inputs
    def _span(self):
        return np.array([self.bounds["R"][1] - self.bounds["R"][0], self.bounds["L"][1] - self.bounds["L"][0]])

    def _lo(self):
        return np.array([self.bounds["R"][0], self.bounds["L"][0]])

    def as_complex(self, x):
        """Inputs as (n, 2, F) complex [A1, A2] and noise std (n, 2, F) or None.

        Accepts FRFData (with channels a1, a2), a sequence of FRFData, an
        `InverseDataset`, a `satmd.physics.Response`, a dict with "a1", "a2",
        a complex array (2, F) or (n, 2, F), or raw real features (4F,) or (n, 4F).
        """
        from ..io import FRFData

        n_freq = self.freq_hz.size
        if isinstance(x, FRFData):
            x = [x]
        if isinstance(x, InverseDataset):
            self._check_grid(x.freq_hz, "the dataset")
            return np.stack([x.a1, x.a2], axis=1), None
        if isinstance(x, (list, tuple)) and x and all(isinstance(d, FRFData) for d in x):
            a, s = [], []
            for d in x:
                self._check_grid(d.freq_hz, "the data")
                a.append(np.stack([d["a1"], d["a2"]]))
                s.append(np.stack([d.std["a1"], d.std["a2"]]) if all(c in d.std for c in ("a1", "a2")) else None)
            std = np.stack(s) if all(v is not None for v in s) else None
            return np.stack(a), std
        if isinstance(x, dict) or hasattr(x, "a1"):
            get = (lambda c: x[c]) if isinstance(x, dict) else (lambda c: getattr(x, c))
            a = np.stack([np.asarray(get("a1")), np.asarray(get("a2"))], axis=-2)
            if hasattr(x, "freq_hz"):
                self._check_grid(x.freq_hz, "the response")
            a = a.reshape(-1, 2, a.shape[-1])
        else:
            arr = np.asarray(x)
            if np.iscomplexobj(arr):
                if arr.ndim < 2 or arr.shape[-2] != 2:
                    raise DataError(f"complex input must have shape (2, F) or (n, 2, F), got {arr.shape}")
                a = arr.reshape(-1, 2, arr.shape[-1])
            else:
                arr = np.asarray(arr, float)
                if arr.shape[-1] != 4 * n_freq:
                    raise DataError(f"real input must be features of length {4 * n_freq} "
                                    f"([Re A1, Re A2, Im A1, Im A2]), got shape {arr.shape}")
                a = features_to_complex(arr.reshape(-1, 4 * n_freq))
        if a.shape[-1] != n_freq:
            raise DataError(f"input has {a.shape[-1]} frequencies; the model uses {n_freq}")
        if not np.all(np.isfinite(a)):
            raise DataError("input contains NaN or infinite values")
        return a.astype(complex), None

    def _check_grid(self, f, what):
        f = np.asarray(f, float)
        if f.shape != self.freq_hz.shape or not np.allclose(f, self.freq_hz, rtol=1e-9, atol=1e-9):
            raise DataError(f"{what} has {f.size} frequencies ({f[0]:g}..{f[-1]:g} Hz); the model was trained on "
                            f"{self.freq_hz.size} points {self.freq_hz[0]:g}..{self.freq_hz[-1]:g} Hz: "
                            f"resample the data to that grid")

    def features(self, x) -> np.ndarray:
        """Scaled network inputs (n, 240) float32: what ``networks_`` take."""
        self._check_net()
        a, _ = self.as_complex(x)
        return self.scaler_.transform(complex_to_features(a))

    def _check_net(self):
        self._check_fitted()
        if self.kind not in NET_KINDS:
            raise SatmdError(f"kind {self.kind!r} has no network")

    # --------------------------------------------------------------- predict
    def _net_predict(self, a, std, normalised=False):
        """Ensemble mean and std (n, 2), normalised units; std already calibrated."""
        torch = _torch()
        feats = complex_to_features(a)
        x = torch.as_tensor(self.scaler_.transform(feats))
        with torch.no_grad():
            out = self.ensemble_(x).double()  # (E, n, 2)
            mean = out.mean(dim=0)
            var = out.var(dim=0, unbiased=False) if out.shape[0] > 1 else torch.zeros_like(mean)
            if std is None and self.noise:
                std = self.noise * np.abs(a)
            if std is not None and self.mc_samples:
                unit = complex_to_features(std + 1j * std) / self.scaler_.scale
                unit = torch.as_tensor(unit, dtype=torch.float32)
                gen = torch.Generator().manual_seed(int(self.seed) + 11)
                draws = []
                for _ in range(int(self.mc_samples)):
                    eps = torch.randn(x.shape, generator=gen)
                    draws.append(self.ensemble_(x + unit * eps).double().mean(dim=0))
                var = var + torch.stack(draws).var(dim=0)
        sd = var.sqrt().numpy() * self.std_scale_
        mean = mean.numpy()
        if normalised:
            return mean, sd
        return self._lo() + mean * self._span(), sd * self._span()

    def predict(self, x) -> dict:
        """R, L and their standard deviations, each an array of shape (n,).

        ``x``: FRFData (or a list of them), arrays or a dataset (see `as_complex`).
        """
        self._check_fitted()
        a, std = self.as_complex(x)
        if self.kind in ("physics", "supervised"):
            mean, sd = self._net_predict(a, std)
            return {"R": mean[:, 0], "L": mean[:, 1], "R_std": sd[:, 0], "L_std": sd[:, 1]}
        if self.kind == "optimization":
            return self._optimise(a, std, start=None)
        mean, _ = self._net_predict(a, std)
        return self._optimise(a, std, start=mean)

    def _optimise(self, a, std, start):
        from ..identify import identify, identify_many
        from ..io import FRFData

        datas = [FRFData(self.freq_hz, {"a1": ai[0], "a2": ai[1]},
                         {} if std is None else {"a1": std[i][0], "a2": std[i][1]}) for i, ai in enumerate(a)]
        if start is None:
            fits = identify_many(datas, rig=self.rig, free=("R", "L"), global_search=True, seed=int(self.seed))
        else:
            fits = [identify(d, rig=self.rig, free=("R", "L"), start={"R": float(s[0]), "L": float(max(s[1], 1e-5))},
                             global_search=False, max_nfev=self.refine_nfev) for d, s in zip(datas, start)]
        out = {k: np.array([f.values[k] for f in fits]) for k in ("R", "L")}
        out.update({f"{k}_std": np.array([f.std.get(k, np.nan) for f in fits]) for k in ("R", "L")})
        return out

    def predict_one(self, x) -> dict:
        """`predict` for a single FRF, as plain floats."""
        p = self.predict(x)
        if p["R"].size != 1:
            raise DataError(f"predict_one takes one FRF, got {p['R'].size}")
        return {k: float(v[0]) for k, v in p.items()}

    def latent(self, x, member: int = 0) -> np.ndarray:
        """(n, 64) activations of the 64-wide layer of ensemble member ``member`` (default 0)."""
        torch = _torch()
        feats = torch.as_tensor(self.features(x))
        with torch.no_grad():
            return self.networks_[member].latent(feats).numpy()

    def reconstruction_error(self, x, prediction: dict | None = None) -> np.ndarray:
        """Relative FRF error of the prediction: ||A(R̂, L̂) - A|| / ||A|| per FRF (both channels)."""
        from .dataset import simulate_pairs

        a, _ = self.as_complex(x)
        p = self.predict(x) if prediction is None else prediction
        a1, a2 = simulate_pairs(p["R"], np.maximum(p["L"], 1e-9), self.freq_hz, self.rig)
        rec = np.stack([a1, a2], axis=1)
        return np.linalg.norm((rec - a).reshape(len(a), -1), axis=1) / np.linalg.norm(a.reshape(len(a), -1), axis=1)

    # ------------------------------------------------------------ save / load
    def save(self, path) -> Path:
        """Write ``path/model.json`` (metadata) and ``path/weights.pt`` (state_dict); no pickle."""
        from .persistence import save_model

        self._check_fitted()
        return save_model(self, path)

    @classmethod
    def load(cls, path) -> "InverseModel":
        """A model written by `save` (weights read with ``torch.load(weights_only=True)``)."""
        from .persistence import load_model

        return load_model(path)

    def get_params(self) -> dict:
        names = ("kind", "preset", "noise", "epochs", "warm_start_epochs", "batch_size", "lr", "physics_lr", "lr_final",
                 "precondition", "n_members", "samples_per_pair", "n_samples", "val_fraction", "refit", "mc_samples",
                 "refine_nfev", "seed", "device", "threads", "verbose")
        return {n: getattr(self, n) for n in names}

    def __repr__(self):
        state = "fitted" if self.is_fitted else "not fitted"
        return f"InverseModel(kind={self.kind!r}, preset={self.preset!r}, noise={self.noise:g}, {state})"


def normalised_outputs(model: InverseModel, X, raw: bool = False):
    """Ensemble-mean normalised outputs (n, 2), differentiable with respect to ``X``.

    ``X``: torch tensor (n, 240) of scaled features (``model.features(...)``),
    or of raw features [Re A1, Re A2, Im A1, Im A2] with ``raw=True`` (the
    standardisation is then applied inside, so gradients are with respect to
    the raw spectral features of eq. 17).
    """
    torch = _torch()
    model._check_net()
    if raw:
        mean = torch.as_tensor(model.scaler_.mean, dtype=X.dtype, device=X.device)
        scale = torch.as_tensor(model.scaler_.scale, dtype=X.dtype, device=X.device)
        X = (X - mean) / scale
    return model.ensemble_(X.float()).mean(dim=0)

"""`InverseModel`: acceleration FRFs -> shunt R, L with standard deviations (use case II).

A scikit-learn style estimator: ``__init__`` stores its arguments and nothing
else, `fit` validates them against one table (``_parameter_constraints``),
learned attributes end in ``_``, `get_params` / `set_params` come from the
signature (so ``sklearn.base.clone`` works), and the signature holds every
default (the preset's training-set size aside: `satmd.inverse.params.PRESET_SIZES`).
The kinds are strategy objects (`satmd.inverse.strategies`):

``physics``
    Deep ensemble trained with the physics-consistent loss of eq. 22 through
    the torch twin, after a supervised warm start, with a per-sample
    Gauss-Newton preconditioner (`satmd.inverse.training`).
``supervised``
    The same ensemble trained by MSE on normalised labels (the paper's baseline).
``optimization``
    Repeated global least squares per FRF; nothing to train.
``hybrid``
    The physics net's prediction refined by a few least-squares steps.

Every prediction is checked through the forward model (`satmd.inverse.inputs.forward_check`):
data that the predicted R, L do not explain raise a `satmd.io.DataWarning`
and are marked in the result. FRFs on another grid are brought onto the net's.

Contract for the explainability package (`satmd.explain.contract.ExplainableModel`)
-----------------------------------------------------------------------------------
- ``networks_``: torch modules mapping scaled float32 features (n, 240) --
  ``features(x)`` -- to normalised outputs (n, 2) in [0, 1] (eq. 19-20).
- ``features(x)``: raw features [Re A1, Re A2, Im A1, Im A2] standardised with ``scaler_``.
- ``latent(x, member=0)``: (n, 64) activations of one member.
- `normalised_outputs(model, X)`: differentiable ensemble-mean normalised outputs.
"""
from __future__ import annotations

import inspect
import time
from numbers import Integral, Real
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import DataError, SatmdError
from ..physics import PAPER_GRID_HZ, Rig
from .dataset import BOUNDS, PRESETS, InverseDataset, complex_to_features, make_dataset
from .params import PRESET_SIZES, Grid, Interval, Options, validate
from .strategies import CALIBRATIONS, KINDS, NET_KINDS, STRATEGIES  # noqa: F401 - NET_KINDS re-exported

if TYPE_CHECKING:
    from .training import Scaler

_LEARNED = ("ensemble_", "networks_", "scaler_", "std_scale_", "history_", "fit_info_")


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
    noise : relative input noise (eq. 23) used in training, in [0, 1)
    epochs : training epochs in all (physics: the first ``warm_start_epochs`` supervised)
    warm_start_epochs : supervised epochs before the physics loss (physics kind)
    batch_size : samples per step
    lr, physics_lr : peak learning rates (warm start / supervised, physics phase),
        quoted at a batch of 64 and scaled by sqrt(batch_size / 64)
    lr_final : learning rate at the end of each phase (cosine schedule)
    n_members : ensemble members
    precondition : Gauss-Newton preconditioning of the eq. 22 gradient
    jacobian : how training gets the residuals of eq. 22 and d residual / d(R, L): "mobius" (each
        acceleration a Möbius map of Zs = R + iωL, fitted once from the twin: exact derivatives, no twin
        call per step, gradients back-propagated by hand; `satmd.inverse.objective.ShuntMobius`), "shunt"
        (the twin, one difference in R; dA/dL = iω dA/dR) or "fd" (the twin, both by differences: the
        method before issue 29)
    twin_dtype : precision of the torch twin in training, "complex64" or "complex128"
    threads : torch CPU threads during training (None leaves torch's setting)
    samples_per_pair : paper preset: samples around each pair (None: ``PRESET_SIZES``)
    n_samples : box preset: number of samples (None: ``PRESET_SIZES``)
    calibration : std calibration (`satmd.inverse.strategies`): "crossfit" (one training; each validation
        pair held out from one member, whose out-of-fold predictions calibrate) or "holdout" (train without
        the validation pairs, calibrate on them, retrain on all with ``refit``: the method before issue 29)
    val_fraction : share of pairs (paper) or samples (box) held out (from one member: crossfit) to calibrate
    refit : holdout: after the calibration, train the nets again, from scratch, on every pair
    mc_samples : Monte Carlo draws for the noise part of the std
    refine_nfev : least-squares evaluations of the hybrid refinement
    seed : every random number derives from it
    device : "cpu", "cuda", "cuda:N" or None (CUDA when present)
    verbose : progress on stderr
    rig : fixed mechanical parameters (None: the paper's rig)
    freq_hz : the net's frequency grid (default: the paper's 60 points, 40-130 Hz)
    """

    _parameter_constraints = {
        "kind": [Options(KINDS)], "preset": [Options(PRESETS)], "noise": [Interval(Real, 0, 1, "hi")],
        "epochs": [Interval(Integral, 1)], "warm_start_epochs": [Interval(Integral, 0)],
        "batch_size": [Interval(Integral, 1)], "lr": [Interval(Real, 0, 1, "lo")],
        "physics_lr": [Interval(Real, 0, 1, "lo")], "lr_final": [Interval(Real, 0, 1)],
        "n_members": [Interval(Integral, 1, 256)], "precondition": [bool],
        "jacobian": [Options(("mobius", "shunt", "fd"))],
        "twin_dtype": [Options(("complex64", "complex128"))], "threads": [None, Interval(Integral, 1)],
        "samples_per_pair": [None, Interval(Integral, 1)], "n_samples": [None, Interval(Integral, 2)],
        "val_fraction": [Interval(Real, 0, 1, "hi")], "refit": [bool],
        "calibration": [Options(CALIBRATIONS)], "mc_samples": [Interval(Integral, 0)],
        "refine_nfev": [None, Interval(Integral, 1)], "seed": [Interval(Integral, 0)], "device": [None, str],
        "verbose": [bool], "rig": [None, Rig], "freq_hz": [Grid()],
    }
    bounds = BOUNDS  # output normalisation of eq. 20 (SPEC §5), not a hyperparameter
    scaler_: Scaler  # learned (set by fit or load; an annotation only: no attribute before then)

    def __init__(self, kind="physics", preset="paper", noise=0.0, *, epochs=90, warm_start_epochs=50,
                 batch_size=64, lr=1e-3, physics_lr=3e-4, lr_final=1e-5, n_members=5, precondition=True,
                 jacobian="mobius", twin_dtype="complex64", threads=1, samples_per_pair=None, n_samples=None,
                 val_fraction=0.2, refit=True, calibration="crossfit", mc_samples=64, refine_nfev=20, seed=0,
                 device=None, verbose=True, rig=None, freq_hz=PAPER_GRID_HZ):
        self.kind = kind
        self.preset = preset
        self.noise = noise
        self.epochs = epochs
        self.warm_start_epochs = warm_start_epochs
        self.batch_size = batch_size
        self.lr = lr
        self.physics_lr = physics_lr
        self.lr_final = lr_final
        self.n_members = n_members
        self.precondition = precondition
        self.jacobian = jacobian
        self.twin_dtype = twin_dtype
        self.threads = threads
        self.samples_per_pair = samples_per_pair
        self.n_samples = n_samples
        self.val_fraction = val_fraction
        self.refit = refit
        self.calibration = calibration
        self.mc_samples = mc_samples
        self.refine_nfev = refine_nfev
        self.seed = seed
        self.device = device
        self.verbose = verbose
        self.rig = rig
        self.freq_hz = freq_hz

    # ------------------------------------------------------------- parameters
    @classmethod
    def _param_names(cls) -> list[str]:
        return [p for p in inspect.signature(cls.__init__).parameters if p != "self"]

    def get_params(self, deep: bool = True) -> dict:
        """Hyperparameters by name (those of ``__init__``); ``deep`` is accepted for scikit-learn."""
        return {name: getattr(self, name) for name in self._param_names()}

    def set_params(self, **params) -> "InverseModel":
        """Set hyperparameters by name; returns self (validated at the next `fit`)."""
        names = self._param_names()
        for name, value in params.items():
            if name not in names:
                raise SatmdError(f"InverseModel has no parameter {name!r}; parameters: {', '.join(names)}")
            setattr(self, name, value)
        return self

    def validate_params(self):
        """Check the hyperparameters against the one constraint table (`satmd.inverse.params`)."""
        validate(self.get_params(), self._parameter_constraints)

    def _strategy(self):
        if self.kind not in STRATEGIES:
            raise SatmdError(f"unknown kind {self.kind!r}; choose from {', '.join(KINDS)}")
        return STRATEGIES[self.kind]

    @property
    def rig_or_default(self) -> Rig:
        """The rig the model works with: ``rig``, or the paper's when None."""
        return Rig() if self.rig is None else self.rig

    def train_config(self, objective: str | None = None):
        """The resolved `satmd.inverse.training.TrainConfig` of these hyperparameters."""
        from .training import TrainConfig

        objective = objective or self._strategy().objective or "physics"
        return TrainConfig(objective=objective, epochs=int(self.epochs), warm_start_epochs=int(self.warm_start_epochs),
                           batch_size=int(self.batch_size), lr=float(self.lr), physics_lr=float(self.physics_lr),
                           lr_final=float(self.lr_final), n_members=int(self.n_members), noise=float(self.noise),
                           seed=int(self.seed), device=self.device, precondition=bool(self.precondition),
                           threads=self.threads, twin_dtype=self.twin_dtype, jacobian=self.jacobian)

    # -------------------------------------------------------------------- fit
    def make_data(self) -> InverseDataset:
        """The training data of this model's preset (train and validation partitions)."""
        sizes = {**PRESET_SIZES[self.preset], **{k: v for k, v in (("samples_per_pair", self.samples_per_pair),
                                                                   ("n_samples", self.n_samples)) if v is not None}}
        return make_dataset(self.preset, val_fraction=self.val_fraction, seed=self.seed, freq_hz=self.freq_hz,
                            rig=self.rig, **sizes)

    def fit(self, data: InverseDataset | None = None) -> "InverseModel":
        """Train (net kinds) or set up (optimization). Returns self.

        Parameters
        ----------
        data : an `InverseDataset` on the model's grid (default: built from the preset)

        Returns
        -------
        InverseModel
        """
        self.validate_params()
        strategy = self._strategy()
        for name in _LEARNED:
            self.__dict__.pop(name, None)
        t0, c0 = time.perf_counter(), time.process_time()
        info = {"kind": self.kind, "preset": self.preset, "noise": float(self.noise), "seed": int(self.seed)}
        if strategy.has_net:
            from .training import check_device

            check_device(self.device)  # before any work
            data = self.make_data() if data is None else data
            grid = np.asarray(self.freq_hz, float)
            if data.freq_hz.shape != grid.shape or not np.allclose(data.freq_hz, grid):
                raise DataError("training data and model use different frequency grids")
            _torch().manual_seed(int(self.seed))
        info.update(strategy.fit(self, data))
        self.fit_info_ = {**info, "train_s": time.perf_counter() - t0, "train_cpu_s": time.process_time() - c0}
        return self

    def set_ensemble(self, ensemble):
        """Install a trained ensemble (the strategies and `load` call this), frozen for inference."""
        self.ensemble_ = ensemble.eval().requires_grad_(False)
        self.networks_ = [net.requires_grad_(False) for net in ensemble.members()]

    @property
    def is_fitted(self) -> bool:
        return hasattr(self, "fit_info_")

    def _check_fitted(self):
        if not self.is_fitted:
            raise SatmdError("this InverseModel is not fitted yet: call fit() or InverseModel.load()")

    def _check_net(self):
        self._check_fitted()
        if not self._strategy().has_net:
            raise SatmdError(f"kind {self.kind!r} has no network")

    # ---------------------------------------------------------------- inputs
    def _prepare(self, x):
        import warnings

        from ..io import DataWarning
        from .inputs import prepare

        inputs = prepare(x, self.freq_hz, self.rig_or_default)
        for note in inputs.notes:
            warnings.warn(note, DataWarning, stacklevel=3)
        return inputs

    def as_complex(self, x):
        """Inputs as (n, 2, F) complex [A1, A2] on the model's grid, and their noise std (n, 2, F) or None.

        Parameters
        ----------
        x : FRFData with channels a1, a2 (any grid: brought onto the model's,
            with a `satmd.io.DataWarning` where the data do not cover it), a
            sequence of FRFData, an `InverseDataset`, a `satmd.physics.Response`,
            a dict with "a1", "a2", a complex array (2, F) or (n, 2, F), or raw
            real features (4F,) or (n, 4F)

        Returns
        -------
        (ndarray, ndarray or None)
        """
        inputs = self._prepare(x)
        return inputs.a, inputs.std

    def features(self, x) -> np.ndarray:
        """Scaled network inputs (n, 240) float32: what ``networks_`` take."""
        self._check_net()
        a, _ = self.as_complex(x)
        return self.scaler_.transform(complex_to_features(a))

    # --------------------------------------------------------------- predict
    def predict(self, x, check: bool = True) -> dict:
        """R, L and their standard deviations, each an array (n,), with the forward check.

        Parameters
        ----------
        x : inputs (see `as_complex`)
        check : run the forward check (``residual``, ``residual_expected``,
            ``residual_ratio``, ``explained`` in the result; a
            `satmd.io.DataWarning` when data are not explained)

        Returns
        -------
        dict of arrays (std NaN where it would mean nothing, one member: a `DataWarning` says why)
        """
        import warnings

        from ..io import DataWarning
        from .inputs import DEFAULT_RESIDUAL_REF, check_message, forward_check, trust_check

        self._check_fitted()
        inputs = self._prepare(x)
        out = self._strategy().predict(self, inputs)
        if check:
            ref = float(self.fit_info_.get("residual_ref", DEFAULT_RESIDUAL_REF))
            out.update(forward_check(inputs, out["R"], out["L"], self.rig_or_default, ref, float(self.noise)))
            message = check_message(out, out["R"], out["L"], self.rig_or_default)
            if message:
                warnings.warn(message, DataWarning, stacklevel=2)
        # std finite, >= 0 and saying something, or none (NaN) with the reason (a one-member ensemble)
        message = trust_check(out, self.bounds, self._strategy().no_std(self))
        if message:
            warnings.warn(message, DataWarning, stacklevel=2)
        return out

    def predict_one(self, x) -> dict:
        """`predict` for a single FRF, as plain Python values."""
        p = self.predict(x)
        if p["R"].size != 1:
            raise DataError(f"predict_one takes one FRF, got {p['R'].size}")
        return {k: v[0].item() for k, v in p.items()}

    def latent(self, x, member: int = 0) -> np.ndarray:
        """(n, 64) activations of the 64-wide layer of ensemble member ``member`` (default 0)."""
        torch = _torch()
        feats = torch.as_tensor(self.features(x))
        with torch.no_grad():
            return self.networks_[member].latent(feats).numpy()

    def reconstruction_error(self, x, prediction: dict | None = None) -> np.ndarray:
        """Relative FRF error of the prediction: ||A(R̂, L̂) - A|| / ||A|| per FRF (both channels)."""
        from .inputs import forward_check

        inputs = self._prepare(x)
        p = self.predict(x, check=False) if prediction is None else prediction
        return forward_check(inputs, p["R"], p["L"], self.rig_or_default, 1.0, 0.0)["residual"]

    # ------------------------------------------------------------ save / load
    def to_dict(self) -> dict:
        """JSON-ready description of the fitted model (everything but the weights)."""
        from .persistence import model_meta

        self._check_fitted()
        return model_meta(self)

    @classmethod
    def from_dict(cls, meta: dict, state: dict | None = None) -> "InverseModel":
        """The model described by `to_dict`, with the ensemble's weights ``state`` (net kinds)."""
        from .persistence import model_from_meta

        return model_from_meta(cls, meta, state)

    def save(self, path) -> Path:
        """Write ``path/model.json`` (metadata) and ``path/weights.pt`` (state_dict), together; no pickle."""
        from .persistence import ensemble_state, write_folder

        return write_folder(path, self.to_dict(), ensemble_state(self))

    @classmethod
    def load(cls, path) -> "InverseModel":
        """A model written by `save` (weights read with ``torch.load(weights_only=True)``).

        A damaged, truncated or edited folder is refused with one `DataError` line naming the file.
        """
        from .persistence import read_folder

        return read_folder(cls, path)

    def __repr__(self):
        state = "fitted" if self.is_fitted else "not fitted"
        return f"InverseModel(kind={self.kind!r}, preset={self.preset!r}, noise={self.noise!r}, {state})"


def normalised_outputs(model: InverseModel, X, raw: bool = False):
    """Ensemble-mean normalised outputs (n, 2), differentiable with respect to ``X``.

    Parameters
    ----------
    model : a fitted net-kind InverseModel
    X : torch tensor (n, 240) of scaled features (``model.features(...)``), or of
        raw features [Re A1, Re A2, Im A1, Im A2] with ``raw=True`` (standardised
        inside, so gradients are with respect to the raw spectral features of eq. 17)
    raw : see ``X``

    Returns
    -------
    torch.Tensor
    """
    torch = _torch()
    model._check_net()
    if raw:
        mean = torch.as_tensor(model.scaler_.mean, dtype=X.dtype, device=X.device)
        scale = torch.as_tensor(model.scaler_.scale, dtype=X.dtype, device=X.device)
        X = (X - mean) / scale
    return model.ensemble_(X.float()).mean(dim=0)

"""The four kinds of `InverseModel` as strategy objects (``STRATEGIES[kind]``).

A strategy knows how to fit a model of its kind (setting the model's learned
attributes) and how to turn prepared inputs into R, L and standard
deviations. `InverseModel` holds the hyperparameters and delegates; adding a
kind is one class here and one entry in ``STRATEGIES``.

Uncertainty of the net kinds
----------------------------
``std² = c² (σ_ens² + σ_noise²)`` per output: σ_ens is the spread of the
ensemble members, σ_noise the spread of the ensemble mean when the input is
perturbed again by its measurement noise (``mc_samples`` Monte Carlo draws;
the data's std columns when given, else the training noise level), and ``c``
is fitted on held-out pairs so that ``|error| <= 2 std`` holds for 95 % of
them (``std_scale_``). Where the held-out pairs come from is the model's
``calibration``:

``crossfit`` (default)
    One training. The validation pairs (``val_fraction`` of them) are dealt
    among the members (`satmd.inverse.dataset.crossfit_folds`): each is held
    out from one member only, which trains on every other pair, while the
    other members train on it. That member's out-of-fold prediction there
    (a single member errs at least as much as the ensemble mean, so the fitted
    ``c`` leans to the safe side), against the std the ensemble reports
    there, calibrates ``c``. Every pair shapes the ensemble, and every
    member trains on nearly every pair. (Dealing *all* pairs into one fold
    per member, the textbook cross-fit, left each member a fifth of the
    pairs short and cost 2-5x on Table 2's MAE. Leaving a member out of the
    mean where it held out the pair was measured too: no better, worse on one
    seed of three, so every member counts everywhere.)
``holdout`` (the method before issue 29)
    A training on the pairs outside ``val_fraction``, the calibration on
    those held out, then (``refit``) a second training, from scratch, on
    every pair.

The least-squares kinds report the Jacobian standard errors of their fit.
"""
from __future__ import annotations

import numpy as np

from ..conventions import ACCEL_CHANNELS
from .dataset import InverseDataset, complex_to_features


CALIBRATIONS = ("crossfit", "holdout")  # the std calibration schemes (module docstring)
CALIBRATION_SAMPLES = 1000  # at most this many out-of-fold samples calibrate a cross-fitted ensemble


def _span_lo(model):
    b = model.bounds
    return (np.array([b["R"][1] - b["R"][0], b["L"][1] - b["L"][0]]), np.array([b["R"][0], b["L"][0]]))


def net_predict(model, a, std, normalised: bool = False):
    """Ensemble mean and calibrated std (n, 2) of complex inputs ``a`` (n, 2, F); physical units by default."""
    import torch

    x = torch.as_tensor(model.scaler_.transform(complex_to_features(a)))
    with torch.no_grad():
        out = model.ensemble_(x).double()  # (E, n, 2)
        mean = out.mean(dim=0)
        var = out.var(dim=0, unbiased=False) if out.shape[0] > 1 else torch.zeros_like(mean)
        if std is None and model.noise:
            std = model.noise * np.abs(a)
        if std is not None and model.mc_samples:
            unit = torch.as_tensor(complex_to_features(std + 1j * std) / model.scaler_.scale, dtype=torch.float32)
            gen = torch.Generator().manual_seed(int(model.seed) + 11)
            draws = [model.ensemble_(x + unit * torch.randn(x.shape, generator=gen)).double().mean(dim=0)
                     for _ in range(int(model.mc_samples))]
            var = var + torch.stack(draws).var(dim=0)
    sd = var.sqrt().numpy() * model.std_scale_
    mean = mean.numpy()
    if normalised:
        return mean, sd
    span, lo = _span_lo(model)
    return lo + mean * span, sd * span


class NetStrategy:
    """A deep ensemble of the SPEC §5 net trained with ``objective`` ("physics": eq. 22; "supervised": MSE)."""

    has_net = True

    def __init__(self, objective: str):
        self.objective = objective

    def fit(self, model, data: InverseDataset) -> dict:
        """Train and calibrate the std by the model's ``calibration`` scheme (see the module docstring)."""
        if len(data.train) == 0:
            from ..errors import DataError

            raise DataError("no training samples")
        if model.calibration == "crossfit" and int(model.n_members) >= 2 and len(data.val):
            return self.fit_crossfit(model, data)
        info = self.fit_holdout(model, data)
        if model.calibration == "crossfit" and len(data.val):
            info["calibration_note"] = "one member: no cross-fitting, hold-out calibration instead"
        return info

    def fit_crossfit(self, model, data: InverseDataset) -> dict:
        """One training of members on different folds; the std calibrated on their out-of-fold predictions."""
        from .dataset import crossfit_folds
        from .training import Scaler, train_ensemble

        config = model.train_config(self.objective)
        n_members = int(model.n_members)
        folds = crossfit_folds(data, n_members, seed=int(model.seed))
        members = np.stack([folds != k for k in range(n_members)])
        model.scaler_ = Scaler.fit(data.features())
        model.std_scale_ = np.ones(2)
        ensemble, history = train_ensemble(data, None, config, model.scaler_, model.rig_or_default, model.bounds,
                                           verbose=model.verbose, members=members)
        model.set_ensemble(ensemble)
        model.history_ = history
        oof = np.flatnonzero(folds >= 0)
        held = []  # per held-out pair (of several samples): its member and the box its samples span (a record)
        for g in np.unique(data.group[oof]):
            at = data.group == g
            if at.sum() > 1:
                held.append([int(folds[at][0]), *(float(f(v[at])) for v in (data.R, data.L) for f in (np.min, np.max))])
        info = {"objective": self.objective, "config": config.to_dict(), "dataset": data.info,
                "calibration": "crossfit", "n_folds": n_members, "held_out": held, "n_train": len(data), "n_val": int(oof.size),
                "device": history["device"], "warm_start_epochs": history["warm_start_epochs"], "refit": False}
        if CALIBRATION_SAMPLES < oof.size:  # a random share: the noise draws cost a net pass each
            oof = np.sort(np.random.default_rng([int(model.seed), 31]).choice(oof, CALIBRATION_SAMPLES, replace=False))
        check = data.subset(np.isin(np.arange(len(data)), oof))
        info.update(self.calibrate(model, check, member=folds[oof]))
        info["residual_ref"] = residual_ref(model, check, member=folds[oof])
        return info

    def fit_holdout(self, model, data: InverseDataset) -> dict:
        """Train, calibrate the std on the validation pairs, then (``refit``) train again on every pair."""
        from .training import Scaler, train_ensemble

        train, val = data.train, data.val
        config = model.train_config(self.objective)
        rig = model.rig_or_default
        model.scaler_ = Scaler.fit(train.features())
        model.std_scale_ = np.ones(2)
        ensemble, history = train_ensemble(train, val if len(val) else None, config, model.scaler_, rig,
                                           model.bounds, verbose=model.verbose)
        model.set_ensemble(ensemble)
        model.history_ = history
        info = {"objective": self.objective, "config": config.to_dict(), "dataset": data.info,
                "calibration": "holdout", "n_train": len(train), "n_val": len(val), "device": history["device"],
                "warm_start_epochs": history["warm_start_epochs"], "refit": False}
        check_set = val if len(val) else train.subset(np.arange(len(train)) < 500)
        if len(val):
            info.update(self.calibrate(model, val))
        info["residual_ref"] = residual_ref(model, check_set)
        if len(val) and model.refit:
            # the calibration stays; the nets are trained again, from scratch, on every pair
            model.scaler_ = Scaler.fit(data.features())
            ensemble, again = train_ensemble(data, None, config, model.scaler_, rig, model.bounds,
                                             verbose=model.verbose)
            model.set_ensemble(ensemble)
            model.history_["refit_loss"] = again["loss"]
            model.history_["train_s"] += again["train_s"]
            info.update(refit=True, n_final=len(data))
        return info

    @staticmethod
    def calibrate(model, val: InverseDataset, member=None) -> dict:
        """Fit ``std_scale_`` so that 95 % of validation errors lie within 2 std.

        ``member`` (n,): for cross-fitting, the member each sample is out-of-fold for; its prediction
        stands in for the ensemble mean (the std is the ensemble's, as reported for new data).
        """
        rng = np.random.default_rng(int(model.seed) + 7)
        a = np.stack([val.a1, val.a2], axis=1)
        std = None
        if model.noise:
            std = model.noise * np.abs(a)
            a = a + std * (rng.standard_normal(a.shape) + 1j * rng.standard_normal(a.shape))
        model.std_scale_ = np.ones(2)
        mean, sd = net_predict(model, a, std, normalised=True)
        if member is not None:
            mean = member_outputs(model, a, member)
        err = np.abs(mean - val.labels_normalised(model.bounds))
        z = err / np.maximum(sd, 1e-12)
        model.std_scale_ = np.maximum(np.quantile(z, 0.95, axis=0) / 2.0, 1e-6)
        return {"std_scale": model.std_scale_.tolist(), "val_mae": (err.mean(axis=0) * _span_lo(model)[0]).tolist(),
                "val_coverage_2sd": float(np.mean(err <= 2 * sd * model.std_scale_))}

    def predict(self, model, inputs) -> dict:
        mean, sd = net_predict(model, inputs.a, inputs.std)
        return {"R": mean[:, 0], "L": mean[:, 1], "R_std": sd[:, 0], "L_std": sd[:, 1]}

    def no_std(self, model) -> str | None:
        """Why this model's predictions come without a std (None: they have one).

        The std is the calibrated spread of the members: one member has no
        spread, and a calibration factor beyond `satmd.inverse.inputs.MAX_STD_SCALE`
        scales up a spread the ensemble does not have (0 or 1e10, both meaningless).
        """
        from .inputs import MAX_STD_SCALE

        if len(model.networks_) < 2:
            return ("a one-member ensemble has no spread between members to measure the uncertainty by "
                    "(train two or more members)")
        scale = float(np.max(np.asarray(model.std_scale_, dtype=float)))
        if scale > MAX_STD_SCALE:
            return (f"the model's std calibration factor is {scale:.3g}: its ensemble has no spread of its own "
                    "(too few members or epochs); retrain it")
        return None


def member_outputs(model, a, member) -> np.ndarray:
    """Normalised outputs (n, 2) of complex inputs ``a`` (n, 2, F), sample ``i`` from ensemble member ``member[i]``."""
    import torch

    x = torch.as_tensor(model.scaler_.transform(complex_to_features(a)))
    with torch.no_grad():
        out = model.ensemble_(x).double().numpy()  # (E, n, 2)
    return out[np.asarray(member, int), np.arange(len(a))]


def residual_ref(model, ds: InverseDataset, member=None) -> float:
    """99th percentile of the net's relative FRF error on noise-free, in-distribution data (the check's floor).

    ``member`` (n,): take sample ``i``'s prediction from that member (its out-of-fold one) instead of the mean.
    """
    from ..physics import frf

    a = np.stack([ds.a1, ds.a2], axis=1)
    if member is None:
        mean, _ = net_predict(model, a, None)
    else:
        span, lo = _span_lo(model)
        mean = lo + member_outputs(model, a, member) * span
    rec = frf(ds.freq_hz, model.rig_or_default.replace(R=mean[:, 0], L=np.maximum(mean[:, 1], 1e-9)), outputs=ACCEL_CHANNELS)
    assert rec.a1 is not None and rec.a2 is not None  # both were asked for
    err = np.linalg.norm((np.stack([rec.a1, rec.a2], axis=1) - a).reshape(len(a), -1), axis=1)
    return float(max(np.quantile(err / np.linalg.norm(a.reshape(len(a), -1), axis=1), 0.99), 1e-4))


def least_squares(model, a, std, start):
    """R, L per FRF by least squares on the model grid: global search (``start`` None) or refined from ``start``."""
    from ..identification import identify, identify_many
    from ..io import FRFData

    datas = [FRFData(model.freq_hz, {"a1": ai[0], "a2": ai[1]},
                     {} if std is None else {"a1": std[i][0], "a2": std[i][1]}) for i, ai in enumerate(a)]
    if start is None:
        fits = identify_many(datas, rig=model.rig_or_default, free=("R", "L"), global_search=True, seed=int(model.seed))
    else:
        fits = [identify(d, rig=model.rig_or_default, free=("R", "L"), start={"R": float(s[0]), "L": float(max(s[1], 1e-5))},
                         global_search=False, max_nfev=model.refine_nfev, warn=False) for d, s in zip(datas, start)]
    out = {k: np.array([f.values[k] for f in fits]) for k in ("R", "L")}
    out.update({f"{k}_std": np.array([f.std.get(k, np.nan) for f in fits]) for k in ("R", "L")})
    return out


class OptimizationStrategy:
    """Repeated global least squares per FRF (`satmd.identification.identify_many`, free R and L); nothing to train."""

    has_net = False
    objective = None

    def fit(self, model, data) -> dict:
        return {"residual_ref": 1e-3}  # least squares fit the data as well as the model can

    def predict(self, model, inputs) -> dict:
        return least_squares(model, inputs.a, inputs.std, None)

    def no_std(self, model) -> str | None:
        """None: the least-squares standard errors are the std."""
        return None


class HybridStrategy(NetStrategy):
    """The physics net's prediction refined by a few least-squares steps (no global search)."""

    def __init__(self):
        super().__init__("physics")

    def fit(self, model, data) -> dict:
        info = super().fit(model, data)
        info["residual_ref"] = 1e-3  # the refinement fits the data
        return info

    def predict(self, model, inputs) -> dict:
        mean, _ = net_predict(model, inputs.a, inputs.std)
        return least_squares(model, inputs.a, inputs.std, mean)

    def no_std(self, model) -> str | None:
        """None: the refinement's least-squares standard errors are the std, whatever the ensemble."""
        return None


STRATEGIES: dict[str, NetStrategy | OptimizationStrategy] = {
    "physics": NetStrategy("physics"), "supervised": NetStrategy("supervised"),
    "optimization": OptimizationStrategy(), "hybrid": HybridStrategy()}
KINDS = tuple(STRATEGIES)
NET_KINDS = tuple(k for k, s in STRATEGIES.items() if s.has_net)

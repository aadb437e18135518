"""Saving and loading an `InverseModel` without pickle.

A saved model is a folder:

- ``model.json``: schema ``satmd-inverse/1``, hyperparameters, kind, preset,
  bounds, frequency grid, rig, input scaling, std calibration, seeds,
  training summary and the versions of satmd / torch / numpy;
- ``weights.pt``: the ensemble's ``state_dict`` (tensors only, written with
  ``torch.save`` and read back with ``torch.load(weights_only=True)``);
  absent for the ``optimization`` kind.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import DataError, SatmdError

SCHEMA = "satmd-inverse/1"
META = "model.json"
WEIGHTS = "weights.pt"


def _jsonable(x):
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    return x


def save_model(model, path) -> Path:
    from .. import __version__

    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    versions = {"satmd": __version__, "numpy": np.__version__}
    history = {k: v for k, v in model.history_.items() if k in ("loss", "val_mae", "phase", "train_s", "device")}
    meta = {
        "schema": SCHEMA,
        "params": model.get_params(),
        "kind": model.kind,
        "preset": model.preset,
        "bounds": {k: list(v) for k, v in model.bounds.items()},
        "freq_hz": model.freq_hz.tolist(),
        "rig": {k: float(v) for k, v in model.rig.as_dict().items()},
        "feature_order": "[Re A1, Re A2, Im A1, Im A2] over freq_hz (satmd.physics.torch.features)",
        "scaler": model.scaler_.to_dict() if model.scaler_ is not None else None,
        "std_scale": list(map(float, model.std_scale_)),
        "fit_info": model.fit_info_,
        "history": history,
        "versions": versions,
    }
    if model.ensemble_ is not None:
        import torch

        versions["torch"] = torch.__version__
        meta["network"] = {"class": "EnsembleNet", "n_members": model.ensemble_.n_members,
                           "sizes": list(model.ensemble_.sizes)}
        state = {k: v.detach().cpu().contiguous() for k, v in model.ensemble_.state_dict().items()}
        torch.save(state, path / WEIGHTS)
    (path / META).write_text(json.dumps(_jsonable(meta), indent=1), encoding="utf-8")
    return path


def load_model(path):
    from ..physics import Rig
    from .model import InverseModel

    path = Path(path)
    meta_file = path / META
    if not meta_file.is_file():
        raise SatmdError(f"{path}: not a saved inverse model (no {META})")
    try:
        meta = json.loads(meta_file.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise DataError(f"{meta_file}: invalid JSON ({exc.msg}, line {exc.lineno})") from None
    if meta.get("schema") != SCHEMA:
        raise DataError(f"{meta_file}: schema {meta.get('schema')!r}, expected {SCHEMA!r}")
    import inspect

    known = set(inspect.signature(InverseModel.__init__).parameters) - {"self", "rig", "freq_hz"}
    params = {k: v for k, v in dict(meta["params"]).items() if k in known}
    params["verbose"] = False
    model = InverseModel(**params, rig=Rig(**meta["rig"]), freq_hz=np.array(meta["freq_hz"]))
    model.bounds = {k: tuple(v) for k, v in meta["bounds"].items()}
    model.std_scale_ = np.array(meta["std_scale"], float)
    model.fit_info_ = meta.get("fit_info") or {"loaded": True}
    model.history_ = meta.get("history", {})
    if meta.get("scaler"):
        from .training import Scaler

        model.scaler_ = Scaler.from_dict(meta["scaler"])
    if "network" in meta:
        import torch

        from .nets import EnsembleNet

        weights = path / WEIGHTS
        if not weights.is_file():
            raise SatmdError(f"{path}: {WEIGHTS} is missing")
        net = EnsembleNet(meta["network"]["n_members"], meta["network"]["sizes"])
        state = torch.load(weights, map_location="cpu", weights_only=True)
        net.load_state_dict(state)
        model._set_ensemble(net)
    return model

"""`InverseModel.to_dict` / `from_dict` / `save` / `load` without pickle.

A saved model is a folder:

- ``model.json``: schema ``satmd-inverse/2`` (format 1, before issue 29, still
  loads: see ``FORMATS``), hyperparameters, kind, preset,
  bounds, frequency grid, rig, input scaling, std calibration, training
  summary, the versions of satmd / torch / numpy, and a sha256 of all that
  (a hand-edited file is noticed);
- ``weights.pt``: the ensemble's ``state_dict`` (tensors only, written with
  ``torch.save`` and read back with ``torch.load(weights_only=True)``);
  absent for the ``optimization`` kind.

Both files are written together or not at all. This module takes the model
class as an argument and never imports `satmd.inverse.model`.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np

from ..errors import DataError, SatmdError
from ..jsonsafe import jsonable
from .dataset import BOUNDS
from .strategies import KINDS, STRATEGIES

SCHEMA = "satmd-inverse/2"
#: The formats this version reads, each with the hyperparameters its files lack: format 1 models were
#: trained with the hold-out calibration and the finite-difference Jacobian (issue 29 added both settings).
FORMATS = {"satmd-inverse/1": {"calibration": "holdout", "jacobian": "fd"}, SCHEMA: {}}
META = "model.json"
WEIGHTS = "weights.pt"
CHECKSUM = "sha256"
_NOT_PARAMS = ("rig", "freq_hz")  # stored resolved, at the top level


def _checksum(meta: dict) -> str:
    body = {k: v for k, v in meta.items() if k != CHECKSUM}
    return hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()


def model_meta(model) -> dict:
    """The JSON-ready description of a fitted model (`InverseModel.to_dict`)."""
    from ..version import __version__

    versions = {"satmd": __version__, "numpy": np.__version__}
    history = {k: v for k, v in getattr(model, "history_", {}).items()
               if k in ("loss", "val_mae", "val_epoch", "phase", "train_s", "device")}
    meta = {
        "schema": SCHEMA,
        "params": {k: v for k, v in model.get_params().items() if k not in _NOT_PARAMS},
        "kind": model.kind,
        "preset": model.preset,
        "bounds": {k: list(v) for k, v in model.bounds.items()},
        "freq_hz": np.asarray(model.freq_hz, float).tolist(),
        "rig": {k: float(v) for k, v in model.rig_or_default.as_dict().items()},
        "feature_order": "[Re A1, Re A2, Im A1, Im A2] over freq_hz (satmd.physics.torch.features)",
        "scaler": model.scaler_.to_dict() if getattr(model, "scaler_", None) is not None else None,
        "std_scale": list(map(float, getattr(model, "std_scale_", np.ones(2)))),
        "fit_info": model.fit_info_,
        "history": history,
        "versions": versions,
    }
    if getattr(model, "ensemble_", None) is not None:
        import torch

        versions["torch"] = torch.__version__
        meta["network"] = {"class": "EnsembleNet", "n_members": model.ensemble_.n_members,
                           "sizes": list(model.ensemble_.sizes)}
    meta = jsonable(meta)
    meta[CHECKSUM] = _checksum(meta)
    return meta


def model_from_meta(cls, meta: dict, state: dict | None = None):
    """The model `model_meta` described, with weights ``state`` (net kinds); `SatmdError` for anything else."""
    from ..physics import Rig

    if _depth(meta) > MAX_DEPTH:
        raise DataError(f"nests deeper than {MAX_DEPTH} levels (not a file satmd wrote)")
    if not isinstance(meta, dict) or meta.get("schema") not in FORMATS:
        raise DataError(_schema_refusal(meta))
    if CHECKSUM in meta and meta[CHECKSUM] != _checksum(meta):  # models saved before the checksum have none
        raise DataError("contents differ from what was saved (checksum mismatch); edited by hand?")
    for key, typ in (("params", dict), ("rig", dict), ("bounds", dict), ("freq_hz", list), ("std_scale", list)):
        if not isinstance(meta.get(key), typ):
            raise DataError(f"{key!r} missing or not a {typ.__name__}")
    kind = meta.get("kind")
    if kind not in KINDS:
        raise DataError(f"unknown kind {kind!r} (known: {', '.join(KINDS)})")
    strategy = STRATEGIES[kind]
    info = meta.get("fit_info") or {}
    objective = info.get("objective") if isinstance(info, dict) else None
    if meta["params"].get("kind") != kind or not isinstance(info, dict) or info.get("kind", kind) != kind or (
            objective is not None and objective != strategy.objective):
        raise DataError(f"kind {kind!r} differs from the kind it was trained as")
    if strategy.has_net != ("network" in meta) or (strategy.has_net and not isinstance(meta.get("scaler"), dict)):
        raise DataError(f"kind {kind!r} " + ("needs a network and its input scaler" if strategy.has_net
                                             else "has no network"))
    names = set(cls._param_names()) - set(_NOT_PARAMS)
    # a None where None is not allowed stands for "the default" in models saved by earlier versions
    params = {**FORMATS[meta["schema"]], **{k: v for k, v in meta["params"].items()
              if k in names and (v is not None or None in cls._parameter_constraints.get(k, ()))}}
    params["verbose"] = False
    try:
        if {k: tuple(map(float, v)) for k, v in meta["bounds"].items()} != {k: tuple(v) for k, v in BOUNDS.items()}:
            raise DataError(f"bounds {meta['bounds']} differ from eq. 20's {dict(BOUNDS)}")
        model = cls(**params, rig=Rig(**meta["rig"]).validate(), freq_hz=np.array(meta["freq_hz"], float))
        model.validate_params()
        _check_numbers(meta["params"], model.freq_hz, meta["rig"])
        model.std_scale_ = np.array(meta["std_scale"], float).reshape(2)
        if not (np.all(np.isfinite(model.std_scale_)) and np.all(model.std_scale_ > 0)):
            raise DataError(f"std_scale {meta['std_scale']} must be two finite numbers > 0 (a std is never negative)")
        if strategy.has_net:
            from .training import Scaler

            model.scaler_ = Scaler.from_dict(meta["scaler"])
            n_features = (4 * model.freq_hz.size,)
            if model.scaler_.mean.shape != n_features or model.scaler_.scale.shape != n_features:
                raise DataError("input scaler does not fit the frequency grid")
            if not (np.all(np.isfinite(model.scaler_.mean)) and np.all(np.isfinite(model.scaler_.scale))
                    and np.all(model.scaler_.scale > 0)):
                raise DataError("input scaler holds NaN, infinite or non-positive values")
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, SatmdError):
            raise
        raise DataError(f"damaged model description ({' '.join(str(exc).split())})") from None
    model.fit_info_ = info or {"loaded": True}
    model.history_ = meta.get("history") or {}
    if strategy.has_net:
        if state is None:
            raise DataError("a network model needs its weights")
        model.set_ensemble(_ensemble(meta["network"], state, model.freq_hz.size))
    return model


MAX_DEPTH = 16  # nesting of model.json (satmd writes 4)
MAX_MC_SAMPLES = 1024  # Monte Carlo draws per prediction a saved model may ask for
MAX_REFINE_NFEV = 10_000
MAX_GRID = 100_000  # frequencies of a saved model's grid


def _depth(value, level=0) -> int:
    """Nesting depth of JSON data, without recursing past `MAX_DEPTH`."""
    if level > MAX_DEPTH or not isinstance(value, (dict, list)):
        return level
    items = value.values() if isinstance(value, dict) else value
    return max([_depth(v, level + 1) for v in items] or [level])


def _check_numbers(params: dict, freq_hz, rig: dict):
    """Settings a file could set to make a prediction hang, allocate without bound or overflow."""
    from ..physics import Rig

    for key, ref in Rig().as_dict().items():
        x = rig.get(key, ref)
        if not isinstance(x, (int, float)) or (ref and x and not abs(ref) / 1e6 <= abs(x) <= abs(ref) * 1e6):
            raise DataError(f"rig.{key} = {x!r} is more than a factor 1e6 from the paper's {ref:g}")
    for key, top in (("mc_samples", MAX_MC_SAMPLES), ("refine_nfev", MAX_REFINE_NFEV)):
        value = params.get(key)
        if value is not None and not (isinstance(value, (int, float)) and 0 <= value <= top):
            raise DataError(f"params.{key} = {value!r} is outside 0..{top}")
    if not (1 <= freq_hz.size <= MAX_GRID and np.all(np.isfinite(freq_hz)) and np.all(freq_hz > 0)
            and np.all(np.diff(freq_hz) > 0)):
        raise DataError(f"freq_hz must be 1..{MAX_GRID} finite, positive, increasing frequencies")


def _schema_refusal(meta) -> str:
    """Why a file's schema is refused, in one line (a newer format says to upgrade)."""
    got = meta.get("schema") if isinstance(meta, dict) else type(meta).__name__
    prefix, _, version = str(got).rpartition("/")
    if prefix == "satmd-inverse" and version.isdigit() and int(version) > len(FORMATS):
        return (f"schema {got!r}: saved by a newer satmd (format {version}); this version reads formats "
                f"1-{len(FORMATS)}: upgrade satmd to load it")
    return f"schema {got!r}, expected one of {', '.join(map(repr, FORMATS))}"


def _ensemble(net: dict, state: dict, n_freq: int):
    import torch

    from .nets import EnsembleNet

    try:
        members, sizes = int(net["n_members"]), [int(s) for s in net["sizes"]]
    except (KeyError, TypeError, ValueError):
        raise DataError("damaged network description") from None
    # bounds on what a file may ask us to allocate (the SPEC net is 240-256-128-64-2)
    if not (1 <= members <= 256 and len(sizes) >= 2 and sizes[0] == 4 * n_freq and sizes[-1] == 2
            and all(1 <= s <= 8192 for s in sizes)):
        raise DataError(f"network {members} x {sizes} does not fit a {n_freq}-point grid")
    ensemble = EnsembleNet(members, sizes)
    try:
        ensemble.load_state_dict(state)
    except (RuntimeError, TypeError, AttributeError, KeyError):
        raise DataError(f"the weights do not match the network {members} x {sizes}") from None
    if not all(bool(torch.isfinite(v).all()) for v in state.values()):
        raise DataError("weights contain NaN or infinite values (a damaged file)")
    return ensemble


def ensemble_state(model) -> dict | None:
    """The ensemble's weights as CPU tensors (the ``state_dict`` `write_folder` saves), or None (no nets)."""
    ensemble = getattr(model, "ensemble_", None)
    if ensemble is None:
        return None
    return {k: v.detach().cpu().contiguous() for k, v in ensemble.state_dict().items()}


def write_folder(path, meta: dict, state: dict | None) -> Path:
    """Write ``model.json`` and ``weights.pt`` (when ``state``) into ``path``, both or neither."""
    from ..io.atomic import all_or_none, atomic_write

    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    with all_or_none():
        if state is not None:
            import torch

            with atomic_write(path / WEIGHTS) as fh:
                torch.save(state, fh)
        with atomic_write(path / META, "w") as fh:
            fh.write(json.dumps(meta, indent=1))
    return path


def read_folder(cls, path):
    """The model saved in folder ``path``; a damaged or edited folder is refused with a one-line DataError."""
    path = Path(path)
    meta_file = path / META
    if not meta_file.is_file():
        raise SatmdError(f"{path}: not a saved inverse model (no {META})")
    from ..io.limits import check_file

    check_file(meta_file, 64 * 2 ** 20)  # satmd writes under 1 MB; a FIFO or a device is refused unopened
    try:
        meta = json.loads(meta_file.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise DataError(f"{meta_file}: invalid JSON ({exc.msg}, line {exc.lineno})") from None
    except RecursionError:
        raise DataError(f"{meta_file}: JSON nested too deeply (not a file satmd wrote)") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"{meta_file}: cannot read ({getattr(exc, 'strerror', None) or exc})") from None
    state = None
    if isinstance(meta, dict) and STRATEGIES.get(meta.get("kind")) is not None and "network" in meta:
        state = _read_weights(path / WEIGHTS)
    try:
        return model_from_meta(cls, meta, state)
    except SatmdError as exc:
        where = path / WEIGHTS if str(exc).startswith(("the weights", "weights")) else meta_file
        raise DataError(f"{where}: {exc}") from None


def _read_weights(file: Path) -> dict:
    import pickle
    import zipfile

    import torch

    if not file.is_file():
        raise DataError(f"{file}: missing (the model's weights)")
    from ..io.limits import check_file

    check_file(file, 2 * 2 ** 30)
    try:
        state = torch.load(file, map_location="cpu", weights_only=True)
    except (RuntimeError, EOFError, OSError, pickle.UnpicklingError, zipfile.BadZipFile, ValueError):
        raise DataError(f"{file}: damaged or truncated (not a readable torch weights file)") from None
    if not isinstance(state, dict) or not all(isinstance(v, torch.Tensor) for v in state.values()):
        raise DataError(f"{file}: not a state_dict of tensors")
    return state

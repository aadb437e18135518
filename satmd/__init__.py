"""satmd: semi-active shunted piezoelectric tuned mass dampers.

Forward model, grey-box identification, amortized inversion, explainability
and missing-physics discovery from measured or simulated FRFs.

The names below load on first use (PEP 562): ``import satmd`` itself imports
nothing heavy, so the ``satmd`` command can take charge of Ctrl-C before
numpy and scipy load, and ``satmd.identify`` costs what identification needs.
"""
from __future__ import annotations

import importlib

TYPE_CHECKING = False  # typing.TYPE_CHECKING without importing typing (type checkers take the name as true)
from .version import __version__  # noqa: F401  (re-exported: satmd.__version__)
from ._moved import install as _install_moved

_install_moved()  # module paths that moved answer one release more, with a warning (issue 48)

# public name -> the module that defines it (imported when the name is first used)
_EXPORTS = {
    **dict.fromkeys(("DataError", "DataTypeError", "DataWarning", "FormatError", "IdentifiabilityWarning", "PinnedParameterWarning",
                     "PoorFitWarning", "SatmdError"), ".errors"),
    **dict.fromkeys(("FRFData", "load_frf", "save_frf", "Recording", "load_recording", "save_recording",
                     ), ".io"),
    "estimate_frf": ".signal",
    **dict.fromkeys(("PAPER_GRID_HZ", "DielectricLoss", "Effect", "ExtraMode", "ParameterOffset", "Rig", "SensorGain",
                     "ShuntCapacitance", "StructuralDamping", "TimeDelay", "effect", "frf", "NonlinearElement",
                     "integrate", "nonlinear_element", "register_nonlinear"), ".physics"),
    "simulate": ".simulation",
    **dict.fromkeys(("FitResult", "identify", "identify_many", "fit_nonlinear", "NonlinearFit"), ".identification"),
    **dict.fromkeys(("fit_modes", "follow_modes"), ".modal"),
    **dict.fromkeys(("DiscoveryReport", "discover", "discover_many"), ".discovery"),
    **dict.fromkeys(("StructureModel", "fit_structure", "locate_joint"), ".structure"),
    **dict.fromkeys(("TuneResult", "retune", "tune"), ".tuning"),
    "tune_nonlinear": ".tuning.nonlinear",
    "InverseModel": ".inverse",  # torch is optional: it loads only when the model is used
}

if TYPE_CHECKING:  # what type checkers and editors see; at run time `__getattr__` imports on first use
    from .discovery import DiscoveryReport, discover, discover_many
    from .errors import (DataError, DataTypeError, DataWarning, FormatError, IdentifiabilityWarning,
                         PinnedParameterWarning, PoorFitWarning, SatmdError)
    from .identification import FitResult, NonlinearFit, fit_nonlinear, identify, identify_many
    from .inverse import InverseModel
    from .io import FRFData, Recording, load_frf, load_recording, save_frf, save_recording
    from .modal import fit_modes, follow_modes
    from .physics import (PAPER_GRID_HZ, DielectricLoss, Effect, ExtraMode, NonlinearElement, ParameterOffset, Rig,
                          SensorGain, ShuntCapacitance, StructuralDamping, TimeDelay, effect, frf, integrate,
                          nonlinear_element, register_nonlinear)
    from .signal import estimate_frf
    from .simulation import simulate
    from .structure import StructureModel, fit_structure, locate_joint
    from .tuning import TuneResult, retune, tune
    from .tuning.nonlinear import tune_nonlinear


def __getattr__(name):
    """A public name (or a subpackage, ``satmd.io``) imported on first use and kept."""
    source = _EXPORTS.get(name)
    if source is not None:
        value = getattr(importlib.import_module(source, __name__), name)
    elif not name.startswith("_"):
        try:
            value = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":  # the submodule exists; something it imports is missing
                raise
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "Rig", "frf", "effect", "Effect", "FRFData", "load_frf", "save_frf", "simulate", "PAPER_GRID_HZ",
    "SensorGain", "TimeDelay", "StructuralDamping", "DielectricLoss", "ShuntCapacitance", "ExtraMode",
    "ParameterOffset", "SatmdError", "DataError", "FormatError", "DataWarning", "PoorFitWarning",
    "PinnedParameterWarning", "IdentifiabilityWarning", "identify", "identify_many", "FitResult",
    "discover", "discover_many", "DiscoveryReport", "InverseModel", "tune", "TuneResult", "retune",
    "NonlinearElement", "nonlinear_element", "integrate", "register_nonlinear", "DataTypeError",
    "Recording", "load_recording", "save_recording", "estimate_frf", "fit_nonlinear", "NonlinearFit",
    "tune_nonlinear", "fit_modes", "follow_modes", "StructureModel", "fit_structure", "locate_joint",
]

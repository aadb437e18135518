"""satmd: semi-active shunted piezoelectric tuned mass dampers.

Forward model, grey-box identification, amortized inversion, explainability
and missing-physics discovery from measured or simulated FRFs.
"""
from .errors import (DataError, DataWarning, FormatError, IdentifiabilityWarning, PinnedParameterWarning, PoorFitWarning,
                     SatmdError)
from .io import FRFData, load_frf, save_frf
from .physics import (
    PAPER_GRID_HZ,
    DielectricLoss,
    Effect,
    ExtraMode,
    ParameterOffset,
    Rig,
    SensorGain,
    ShuntCapacitance,
    StructuralDamping,
    TimeDelay,
    effect,
    frf,
    NonlinearElement,
    integrate,
    nonlinear_element,
)
from .simulation import simulate
from .identification import FitResult, identify, identify_many  # noqa: E402  (binds the functions over the subpackages)
from .discovery import DiscoveryReport, discover, discover_many  # noqa: E402
from .tuning import TuneResult, retune, tune  # noqa: E402  (light: scipy.optimize loads on first use)

from .version import __version__  # noqa: E402, F401  (re-exported: satmd.__version__)


def __getattr__(name):
    # torch is optional: the inverse model loads on first use, so `import satmd` works without it
    if name == "InverseModel":
        from .inverse import InverseModel

        return InverseModel
    raise AttributeError(f"module 'satmd' has no attribute {name!r}")

__all__ = [
    "Rig", "frf", "effect", "Effect", "FRFData", "load_frf", "save_frf", "simulate", "PAPER_GRID_HZ",
    "SensorGain", "TimeDelay", "StructuralDamping", "DielectricLoss", "ShuntCapacitance", "ExtraMode",
    "ParameterOffset", "SatmdError", "DataError", "FormatError", "DataWarning", "PoorFitWarning",
    "PinnedParameterWarning", "IdentifiabilityWarning", "identify", "identify_many", "FitResult",
    "discover", "discover_many", "DiscoveryReport", "InverseModel", "tune", "TuneResult", "retune",
    "NonlinearElement", "nonlinear_element", "integrate",
]

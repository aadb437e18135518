"""Module paths that moved (issue 48), kept one release as warned aliases.

``import satmd.io.lpm`` still works and warns (DeprecationWarning) that the module is now
``satmd.signal.lpm``; the old name and the new one are the same module object. Names that a
package re-exported from a module that moved (``from satmd.io import estimate_frf``) are answered
by that package's ``__getattr__`` through `moved_name`. Nothing here imports the new modules until
an old path is asked for, so the layering of the packages is not bent by the aliases.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: old module path -> new module path
MODULES = {
    **{f"satmd.io.{m}": f"satmd.signal.{m}" for m in
       ("excitation", "hits", "sweep", "lpm", "welch", "periodic", "impact", "sweepfrf", "transmissibility", "chain",
        "forcefloor", "estimate", "memo")},
    "satmd.io.timesim": "satmd.simulation.timesim",
    "satmd.io.acquisition": "satmd.simulation.acquisition",
    "satmd.io.conditions": "satmd.simulation.conditions",
    "satmd.simulation_nonlinear": "satmd.simulation.nonlinear",
    "satmd.discovery.nonlinear_discover": "satmd.discovery.nonlinear.levels",
    "satmd.discovery.nonlinear_findings": "satmd.discovery.nonlinear.findings",
    "satmd.discovery.nonlinear_modes": "satmd.discovery.nonlinear.modes",
    "satmd.discovery.nonlinear_name": "satmd.discovery.nonlinear.naming",
    "satmd.discovery.nonlinear_periodic": "satmd.discovery.nonlinear.periodic",
    "satmd.discovery.nonlinear_silverbox": "satmd.discovery.nonlinear.silverbox",
    "satmd.discovery.nonlinear_stats": "satmd.discovery.nonlinear.stats",
    "satmd.identification.nonlinear_compare": "satmd.identification.nonlinear.compare",
    "satmd.identification.nonlinear_result": "satmd.identification.nonlinear.result",
    "satmd.identification.nonlinear_signal": "satmd.identification.nonlinear.drive",
    "satmd.identification.nonlinear_stats": "satmd.identification.nonlinear.stats",
    **{f"satmd.report.sec_{m}": f"satmd.report.parts.{m}" for m in
       ("discover", "explain", "f16", "forward", "identify", "inverse", "nonlinear", "recording", "tune")},
}

#: package -> {name it re-exported: the module that has it now}
NAMES = {
    "satmd.io": {
        **dict.fromkeys(("estimate_frf", "default_nperseg", "transmissibility", "Transmissibility",
                         "model_transmissibility", "save_transmissibility"), "satmd.signal.estimate"),
        **dict.fromkeys(("Excitation", "detect_excitation"), "satmd.signal.excitation"),
        "simulate_recording": "satmd.simulation.timesim",
    },
}


def _warn(old: str, new: str, stacklevel: int = 4) -> None:
    warnings.warn(f"{old} is now {new} (the same object; the old path goes in the next release)",
                  DeprecationWarning, stacklevel=stacklevel)


def moved_name(package: str, name: str):
    """The object a package re-exported before a move (warns), or AttributeError."""
    source = NAMES.get(package, {}).get(name)
    if source is None:
        raise AttributeError(f"module {package!r} has no attribute {name!r}")
    _warn(f"{package}.{name}", f"{source.rpartition('.')[0]}.{name}")
    value = getattr(importlib.import_module(source), name)
    setattr(sys.modules[package], name, value)  # warned once; ``from package import name`` asks twice
    return value


class _Alias(importlib.abc.Loader):
    def __init__(self, new: str):
        self.new = new

    def create_module(self, spec):
        _warn(spec.name, self.new)
        module = importlib.import_module(self.new)
        self.spec = module.__spec__
        return module

    def exec_module(self, module):
        # the new module has run already; the import system stamped the old name's spec on it: undo that
        module.__spec__, module.__loader__ = self.spec, self.spec.loader


class _MovedFinder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        new = MODULES.get(fullname)
        if new is None:
            return None
        return importlib.util.spec_from_loader(fullname, _Alias(new))


def install() -> None:
    """Answer the old module paths (once per process)."""
    if not any(isinstance(f, _MovedFinder) for f in sys.meta_path):
        sys.meta_path.append(_MovedFinder())

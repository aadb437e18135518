"""Intersphinx inventories written offline, from the installed packages (no network at build time).

The docs link to numpy, scipy, torch, matplotlib, scikit-learn and the Python standard library
through intersphinx. Intersphinx normally downloads each project's ``objects.inv``; the machines
that build satmd's docs reach no website, so this module writes a stand-in for each one before the
build: the public names of the installed package (the modules listed below, walked one level
deep), each with the URL its project's documentation gives it (the projects' own URL schemes,
e.g. ``reference/generated/numpy.linspace.html``). A name this walk misses is left as plain code
text, never a warning (the build is not nitpicky). The files are cached per package version under
``build/intersphinx/``.
"""
from __future__ import annotations

import builtins
import importlib
import inspect
import re
import zlib
from pathlib import Path

# project: (base URL, modules walked, URL of a walked name {mod}.{name}, URL of a module page)
NUMPY = ("https://numpy.org/doc/stable/",
         ("numpy", "numpy.linalg", "numpy.random", "numpy.fft", "numpy.polynomial"),
         "reference/generated/{mod}.{name}.html", {"numpy": "reference/index.html",
                                                    "numpy.linalg": "reference/routines.linalg.html",
                                                    "numpy.random": "reference/random/index.html",
                                                    "numpy.fft": "reference/routines.fft.html",
                                                    "numpy.polynomial": "reference/routines.polynomials.html"})
SCIPY_SUBS = ("optimize", "signal", "stats", "interpolate", "linalg", "integrate", "io", "special", "fft",
              "spatial", "sparse", "ndimage")
SCIPY = ("https://docs.scipy.org/doc/scipy/", tuple(f"scipy.{s}" for s in SCIPY_SUBS),
         "reference/generated/{mod}.{name}.html", {f"scipy.{s}": f"reference/{s}.html" for s in SCIPY_SUBS})
TORCH_SUBS = ("torch", "torch.nn", "torch.nn.functional", "torch.optim", "torch.func", "torch.linalg", "torch.fft")
TORCH = ("https://docs.pytorch.org/docs/stable/", TORCH_SUBS, "generated/{mod}.{name}.html",
         {"torch": "torch.html", "torch.nn": "nn.html", "torch.nn.functional": "nn.functional.html",
          "torch.optim": "optim.html", "torch.func": "func.html", "torch.linalg": "linalg.html",
          "torch.fft": "fft.html"})
MATPLOTLIB = ("https://matplotlib.org/stable/", ("matplotlib.pyplot",), "api/_as_gen/{mod}.{name}.html",
              {"matplotlib.pyplot": "api/pyplot_summary.html"})
SKLEARN = ("https://scikit-learn.org/stable/", ("sklearn.base", "sklearn.decomposition", "sklearn.linear_model",
                                                "sklearn.model_selection", "sklearn.metrics"),
           "modules/generated/{mod}.{name}.html", {})
STDLIB = ("pathlib", "concurrent.futures", "os", "typing", "collections.abc", "dataclasses", "json", "warnings",
          "argparse", "io", "enum", "re", "time", "functools", "itertools", "math", "datetime", "tempfile",
          "subprocess", "signal", "multiprocessing")
PYTHON_URL = "https://docs.python.org/3/"
_STDTYPES = {"str", "list", "dict", "tuple", "set", "frozenset", "bytes", "bytearray", "range", "memoryview"}


def _role(obj) -> str:
    if inspect.isclass(obj):
        return "py:exception" if issubclass(obj, BaseException) else "py:class"
    if inspect.ismodule(obj):
        return "py:module"
    if callable(obj):
        return "py:function"
    return "py:data"


def _public(mod):
    names = getattr(mod, "__all__", None)
    if names is None:
        names = [n for n in dir(mod) if not n.startswith("_")]
    for name in names:
        if not isinstance(name, str) or name.startswith("_"):
            continue
        try:
            yield name, getattr(mod, name)
        except Exception:  # noqa: BLE001 (a lazy attribute that fails to load: not documented here)
            continue


def _walk(modules, pattern, module_pages):
    """(name, role, uri) for the walked modules' public names, plus class methods one level down."""
    out = {}
    for modname in modules:
        try:
            mod = importlib.import_module(modname)
        except Exception:  # noqa: BLE001 (an optional package that is not installed, or fails to import)
            continue
        if modname in module_pages:
            out[modname] = ("py:module", module_pages[modname])
        for name, obj in _public(mod):
            full = f"{modname}.{name}"
            if inspect.ismodule(obj):
                if obj.__name__ in module_pages:
                    out.setdefault(obj.__name__, ("py:module", module_pages[obj.__name__]))
                continue
            out.setdefault(full, (_role(obj), pattern.format(mod=modname, name=name)))
            if inspect.isclass(obj):
                for meth, value in vars(obj).items():
                    if not meth.startswith("_") and callable(value):
                        out.setdefault(f"{full}.{meth}", ("py:method",
                                                          pattern.format(mod=modname, name=f"{name}.{meth}")))
    return out


def _python():
    out = {}
    for name in dir(builtins):
        if name.startswith("_"):
            continue
        obj = getattr(builtins, name)
        if inspect.isclass(obj) and issubclass(obj, BaseException):
            out[name] = ("py:exception", f"library/exceptions.html#{name}")
        elif name in _STDTYPES:
            out[name] = ("py:class", f"library/stdtypes.html#{name}")
        elif name in ("None", "True", "False", "NotImplemented", "Ellipsis"):
            out[name] = ("py:data", f"library/constants.html#{name}")
        elif inspect.isclass(obj):
            out[name] = ("py:class", f"library/functions.html#{name}")
        elif callable(obj):
            out[name] = ("py:function", f"library/functions.html#{name}")
    for modname in STDLIB:
        mod = importlib.import_module(modname)
        page = f"library/{modname}.html"
        out[modname] = ("py:module", f"{page}#module-{modname}")
        for name, obj in _public(mod):
            if not inspect.ismodule(obj):
                out.setdefault(f"{modname}.{name}", (_role(obj), f"{page}#{modname}.{name}"))
    return out


def _extra(project):
    if project == "numpy":
        return {"numpy.typing.ArrayLike": ("py:data", "reference/typing.html#numpy.typing.ArrayLike"),
                "numpy.typing.NDArray": ("py:data", "reference/typing.html#numpy.typing.NDArray"),
                "array_like": ("std:term", "glossary.html#term-array_like"),
                "array-like": ("std:term", "glossary.html#term-array-like")}
    if project == "torch":
        return {"torch.Tensor": ("py:class", "tensors.html#torch.Tensor"),
                "torch.dtype": ("py:class", "tensor_attributes.html#torch.dtype"),
                "torch.device": ("py:class", "tensor_attributes.html#torch.device")}
    if project == "matplotlib":
        return {"matplotlib.figure.Figure": ("py:class", "api/_as_gen/matplotlib.figure.Figure.html"),
                "matplotlib.axes.Axes": ("py:class", "api/_as_gen/matplotlib.axes.Axes.html")}
    return {}


def _dump(path: Path, project: str, version: str, entries: dict) -> None:
    lines = []
    for name, (role, uri) in sorted(entries.items()):
        if re.search(r"\s", name):
            continue
        if uri.endswith(name) and "#" in uri:
            uri = uri[: -len(name)] + "$"
        lines.append(f"{name} {role} 1 {uri} -")
    head = (f"# Sphinx inventory version 2\n# Project: {project}\n# Version: {version}\n"
            "# The remainder of this file is compressed using zlib.\n").encode()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_bytes(head + zlib.compress("\n".join(lines).encode() + b"\n"))
    tmp.replace(path)


def _version(dist: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(dist)
    except PackageNotFoundError:
        return ""


PROJECTS = {  # intersphinx name: (distribution, spec or None for the standard library)
    "python": ("", None),
    "numpy": ("numpy", NUMPY),
    "scipy": ("scipy", SCIPY),
    "torch": ("torch", TORCH),
    "matplotlib": ("matplotlib", MATPLOTLIB),
    "sklearn": ("scikit-learn", SKLEARN),
}


def intersphinx_mapping(cache: Path) -> dict:
    """``intersphinx_mapping`` for conf.py: {name: (base URL, local inventory)}; writes what is missing."""
    import sys

    out = {}
    for project, (dist, spec) in PROJECTS.items():
        version = f"{sys.version_info[0]}.{sys.version_info[1]}" if spec is None else _version(dist)
        if spec is not None and not version:
            continue  # not installed: no links to it
        path = cache / f"{project}-{version}.inv"
        if not path.is_file():
            if spec is None:
                entries = _python()
            else:
                base, modules, pattern, pages = spec
                entries = _walk(modules, pattern, pages) | _extra(project)
            _dump(path, project, version, entries)
        out[project] = (PYTHON_URL if spec is None else spec[0], str(path))
    return out

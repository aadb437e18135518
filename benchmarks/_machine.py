"""The machine a benchmark figure was measured on, recorded with every figure.

    from _machine import machine, describe
    result["machine"] = machine(device="cpu", threads=1)   # at the start of the run
    ...
    result["machine"].update(load_after(result["machine"]))  # at the end
    print(line + " | " + describe(result["machine"]))

``device`` is what ran the timed code ("cpu", "cuda", "cuda:1"); ``threads`` the
worker threads (or processes) the figure used. torch is asked for its version
and its own thread count only when it is installed; asking does not start CUDA
unless the device is a GPU.
"""
from __future__ import annotations

import importlib.util
import os
import platform
import sys


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _load():
    return [round(x, 2) for x in os.getloadavg()] if hasattr(os, "getloadavg") else None


def provenance() -> dict:
    """The commit the figures were measured at (and whether the tree had changes), and when."""
    import subprocess
    import time

    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = {"date": time.strftime("%Y-%m-%d %H:%M:%S")}
    try:
        out["commit"] = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True,
                                       text=True, timeout=10).stdout.strip() or None
        # the results an earlier benchmark of the same run wrote are not a change of what is measured
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", ".",
                                ":(exclude)benchmarks/results"], cwd=root, capture_output=True, text=True,
                               timeout=10).stdout.strip()
        out["tree_changed"] = bool(dirty)
    except (OSError, subprocess.SubprocessError):
        out["commit"] = None
    return out


def machine(device: str = "cpu", threads: int | None = None) -> dict:
    """Device, library versions, thread counts, load average, and the commit and date of the run, JSON-ready."""
    import numpy as np

    cpus = os.cpu_count()
    info = {
        "device": device,
        "device_name": _cpu_model(),
        "threads": threads,
        "cpu_count": cpus,
        "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else cpus,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "torch": None,
        "torch_threads": None,
        "platform": platform.platform(),
        "load_average_1_5_15_before": _load(),
        "note": ("a load average above cpu_count means other processes shared the cores; "
                 "ratios are measured in the same run, interleaved"),
        **provenance(),
    }
    if importlib.util.find_spec("torch") is not None:
        import torch

        info["torch"] = torch.__version__
        info["torch_threads"] = torch.get_num_threads()
        if device.startswith("cuda") and torch.cuda.is_available():
            info["device_name"] = torch.cuda.get_device_name(torch.device(device))
            info["cuda"] = torch.version.cuda
    if "distributed" in sys.modules or importlib.util.find_spec("distributed") is not None:
        try:
            from importlib.metadata import version

            info["dask_distributed"] = version("distributed")
        except Exception:  # noqa: BLE001 - a version string is optional
            pass
    return info


def load_after() -> dict:
    """The load average at the end of the run (merge into the dict from `machine`)."""
    return {"load_average_1_5_15_after": _load()}


def describe(info: dict) -> str:
    """One short bracket for a benchmark's printed line."""
    load = info.get("load_average_1_5_15_before")
    parts = [f"{info['device']} ({info['device_name']}, {info['cpu_count']} cores)"]
    if info.get("threads") is not None:
        parts.append(f"threads={info['threads']}")
    parts.append(f"torch {info['torch']}" if info.get("torch") else "no torch")
    if load:
        parts.append(f"load {load[0]:.1f}")
    return "[" + ", ".join(parts) + "]"

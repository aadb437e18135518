"""The schema of ``FRFData.estimator``: how FRFs estimated from a recording were made.

The dictionary travels with the FRFs (a ``# satmd estimator: {...}`` comment
in a satmd-frf CSV) and the fitting code reads numbers from it (the Welch
kernel width, the noise degrees of freedom), so every key satmd knows is
checked for its type and range here, once, whoever built the dictionary.
"""
from __future__ import annotations

import math

from ..errors import DataError

MAX_DEPTH = 8  # nesting of lists / objects in the metadata


def _number(lo=None, hi=None, *, lo_open=False, integer=False):
    def check(value):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return "must be a number"
        if integer and float(value) != int(value):
            return "must be an integer"
        x = float(value)
        if not math.isfinite(x):
            return "must be finite"
        if lo is not None and (x < lo or (lo_open and x == lo)):
            return f"must be {'>' if lo_open else '>='} {lo:g}"
        if hi is not None and x > hi:
            return f"must be <= {hi:g}"
        return None
    return check


def _text(value):
    return None if isinstance(value, str) and len(value) <= 10_000 else "must be a string (at most 10000 characters)"


def _flag(value):
    return None if isinstance(value, bool) else "must be true or false"


def _band(value):
    if not (isinstance(value, list) and len(value) == 2):
        return "must be [LO, HI] in Hz"
    problems = [_number(0, 1e9)(v) for v in value]
    if any(problems):
        return f"must be [LO, HI] in Hz: each {next(p for p in problems if p)}"
    return None if value[0] < value[1] else "must be [LO, HI] with LO < HI"


def _findings(value):
    if not isinstance(value, list) or len(value) > 1000:
        return "must be a list of findings"
    for k, item in enumerate(value):
        if not isinstance(item, dict):
            return f"item {k + 1} must be an object"
        for key in ("name", "explanation", "remedy"):
            if _text(item.get(key)):
                return f"item {k + 1}: {key!r} {_text(item.get(key))}"
        if "corrected" in item and _flag(item["corrected"]):
            return f"item {k + 1}: 'corrected' {_flag(item['corrected'])}"
    return None


MAX_HZ = 1e9
METHODS = ("lpm", "welch-H1", "welch-H2", "periodic", "impact", "sweep", "realisations")
EXCITATIONS = ("random", "periodic", "impact", "sweep")
SCHEMA = {
    "method": lambda v: None if v in METHODS else f"must be one of {', '.join(METHODS)}",
    "excitation": lambda v: None if isinstance(v, dict) and v.get("kind") in EXCITATIONS else (
        f"must be an object whose 'kind' is one of {', '.join(EXCITATIONS)}"),
    "reference": _text,
    "record_s": _number(0, lo_open=True),
    "band_hz": _band,
    "window_hz": _number(0, MAX_HZ, lo_open=True),
    "bins_per_window": _number(1, 1e9, integer=True),
    "degree": _number(0, 20, integer=True),
    "points": _number(1, 1e9, integer=True),
    "noise_dof": _number(0, 1e12, lo_open=True),
    "force_noise_floor_detected": _flag,
    "max_force_noise_bias": _number(0),
    "measurement": _findings,
    "window": _text,
    "nperseg": _number(1, 1e12, integer=True),
    "kernel_rms_hz": lambda v: None if v is None else _number(0, MAX_HZ)(v),  # None: an untapered window
    "overlap": _number(0, 1),
    "segments": _number(1, 1e12, integer=True),
    "resolution_hz": _number(0, MAX_HZ, lo_open=True),
    "window_decay_s": _number(0, 1e12, lo_open=True),  # an exponential window's τ: the data are H(iω + 1/τ)
}


def _depth(value, level=0) -> int:
    if level > MAX_DEPTH:
        return level
    if isinstance(value, dict):
        return max([_depth(v, level + 1) for v in value.values()] or [level])
    if isinstance(value, list):
        return max([_depth(v, level + 1) for v in value] or [level])
    return level


def validate_estimator(estimator, freq_max_hz: float | None = None) -> dict:
    """The estimator dictionary, checked key by key; a bad key is a `DataError` naming it and what is wrong.

    Parameters
    ----------
    estimator : dict or None
        ``FRFData.estimator`` (None or empty: FRFs not estimated by satmd).
    freq_max_hz : float, optional
        The data's highest frequency: a kernel width beyond it cannot be right.

    Returns
    -------
    dict
        A copy of ``estimator``. Keys satmd does not know are kept as they are
        (they are never read), provided they nest no deeper than `MAX_DEPTH`.
    """
    if estimator is None:
        return {}
    if not isinstance(estimator, dict):
        raise DataError(f"estimator metadata must be a JSON object, got {type(estimator).__name__}")
    if _depth(estimator) > MAX_DEPTH:
        raise DataError(f"estimator metadata nests deeper than {MAX_DEPTH} levels")
    for key, value in estimator.items():
        check = SCHEMA.get(key)
        problem = check(value) if check else None
        if problem:
            shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
            raise DataError(f"estimator metadata: {key!r} = {shown} {problem}")
    k = estimator.get("kernel_rms_hz")
    if freq_max_hz is not None and isinstance(k, (int, float)) and k > freq_max_hz:
        raise DataError(f"estimator metadata: 'kernel_rms_hz' = {k:g} Hz is wider than the data's whole band "
                        f"(up to {freq_max_hz:g} Hz)")
    return dict(estimator)


__all__ = ["MAX_DEPTH", "SCHEMA", "validate_estimator"]

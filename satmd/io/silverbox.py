"""The Silverbox benchmark (a measured Duffing-like circuit) as recordings: input ``force``, output ``y``.

Two kinds of files (Wigren & Schoukens 2013; the data set's README):

- ``SNJP_um_full_FNSI_<L>.mat`` / ``SNJP_ym_full_FNSI_<L>.mat``: one drive level L
  each, input ``um`` and output ``ym``, ``P`` periods of a periodic multisine on
  the DFT lines ``flines`` of one period, sample rate ``fs``.
- ``SNLS80mV.mat``: input ``V1`` and output ``V2`` at 610.35 Hz; a filtered
  Gaussian noise of growing amplitude (the "arrow", the first ~40,000
  samples), then realisations of an odd random-phase multisine separated by
  short silent gaps; the last period before each gap is steady state.

The channels are voltages (the circuit's "force" and "displacement"); they are
named ``force`` and ``y`` so that satmd's generic input→output tests take them.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import FormatError
from .recdata import Recording

SNLS_FS_HZ = 610.35
SNLS_PERIOD = 8192


def _loadmat(path: Path) -> dict:
    from scipy.io import loadmat

    if not path.exists():
        raise FormatError(path, "no such file")
    try:
        return loadmat(str(path))
    except Exception as exc:  # scipy raises several types for damaged files
        raise FormatError(path, f"not a readable .mat file ({exc})") from None


def silverbox_levels(directory) -> list:
    """The drive levels of ``SNJP_*_FNSI_<L>.mat`` in ``directory``, sorted (e.g. [5, 20, 50, 100, 150])."""
    found = {int(m.group(1)) for p in Path(directory).glob("SNJP_um_full_FNSI_*.mat")
             if (m := re.search(r"_(\d+)\.mat$", p.name))}
    return sorted(found)


def load_silverbox_level(directory, level: int) -> Recording:
    """One drive level as a Recording (channels ``force``, ``y``); meta holds periods and excited lines.

    Parameters
    ----------
    directory : folder with the ``SNJP_*`` files
    level : drive level L of the file names

    Returns
    -------
    Recording
        ``meta``: ``periods`` (P), ``period_samples``, ``lines`` (excited DFT
        lines of one period, comma-separated), ``level``, ``source``.
    """
    directory = Path(directory)
    pu, py = directory / f"SNJP_um_full_FNSI_{level}.mat", directory / f"SNJP_ym_full_FNSI_{level}.mat"
    mu, my = _loadmat(pu), _loadmat(py)
    for path, m, key in ((pu, mu, "um"), (py, my, "ym")):
        if key not in m:
            raise FormatError(path, f"has no variable {key!r}")
    u, y = np.ravel(mu["um"]).astype(float), np.ravel(my["ym"]).astype(float)
    if u.size != y.size:
        raise FormatError(py, f"ym has {y.size} samples, um {u.size}")
    fs = float(np.ravel(mu.get("fs", [[np.nan]]))[0])
    periods = int(np.ravel(mu.get("P", [[1]]))[0])
    if not np.isfinite(fs) or fs <= 0 or periods < 1 or u.size % periods:
        raise FormatError(pu, f"fs = {fs}, P = {periods} do not describe {u.size} samples")
    lines = np.ravel(mu.get("flines", np.arange(0))).astype(int)
    meta = {"source": str(pu), "level": str(level), "periods": str(periods), "period_samples": str(u.size // periods),
            "lines": ",".join(str(k) for k in lines), "kind": "silverbox multisine"}
    return Recording(fs, {"force": u, "y": y}, {"force": "V", "y": "V"}, meta)


def load_silverbox_snls(directory, period: int = SNLS_PERIOD):
    """``SNLS80mV.mat``: the arrow as a Recording and the multisine realisations as arrays.

    Parameters
    ----------
    directory : folder holding ``SNLS80mV.mat``
    period : samples per multisine period

    Returns
    -------
    arrow : Recording
        The filtered-noise part before the first multisine (channels ``force``, ``y``).
    multisine : dict
        ``u``, ``y``: (realisations, 1, period) steady-state periods (the last
        period before each gap); ``fs_hz``.
    """
    path = Path(directory) / "SNLS80mV.mat"
    m = _loadmat(path)
    for key in ("V1", "V2"):
        if key not in m:
            raise FormatError(path, f"has no variable {key!r}")
    u, y = np.ravel(m["V1"]).astype(float), np.ravel(m["V2"]).astype(float)
    env = np.sqrt(np.convolve((u - np.median(u)) ** 2, np.ones(20) / 20, mode="same"))
    quiet = env < 0.05 * np.std(u)  # the gaps are silent; the arrow's quiet start is not
    edges = np.flatnonzero(np.diff(quiet.astype(int)))
    loud = 0.2 * np.std(u)  # a gap follows a loud stretch; the arrow's quiet start does not
    gaps = [(a + 1, b + 1) for a, b in zip(edges[:-1], edges[1:])
            if quiet[a + 1] and b - a >= 30 and a >= 2000 and np.median(env[a - 2000:a]) > loud]
    if len(gaps) < 2:
        raise FormatError(path, "no silent gaps between multisine realisations found")
    arrow_end = gaps[0][0]
    starts = [b for _, b in gaps]
    ends = [a for a, _ in gaps[1:]] + [u.size]
    blocks = [(e - period, e) for s, e in zip(starts, ends) if e - s >= period]
    if not blocks:
        raise FormatError(path, f"no multisine block of {period} samples between the gaps")
    arrow = Recording(SNLS_FS_HZ, {"force": u[:arrow_end], "y": y[:arrow_end]}, {"force": "V", "y": "V"},
                      {"source": str(path), "kind": "silverbox arrow"})
    us = np.stack([u[a:b] for a, b in blocks])[:, None, :]
    ys = np.stack([y[a:b] for a, b in blocks])[:, None, :]
    return arrow, {"u": us, "y": ys, "fs_hz": SNLS_FS_HZ}

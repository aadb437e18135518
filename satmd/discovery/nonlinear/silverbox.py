"""Verdicts on the Silverbox benchmark (a measured Duffing-like circuit): generic input→output tests.

- The 5-level ladder (``SNJP_*_FNSI_<L>.mat``): per level, the FRF over the
  periods (noise from their spread) and the detection-line test; then the
  level dependence across levels and a one-mode fit per level
  (`findings.analyse_generic`).
- ``SNLS80mV.mat``: the "arrow" (filtered noise of growing amplitude) is cut into
  a quieter and a louder half, whose LPM FRFs are compared (level dependence,
  one-mode fits); each steady-state multisine period is tested for distortion
  with the regressors of `stats.linearity_test` (scores summed over
  the realisations).

Not a SATMD rig: the finding is ``nonlinear_unexplained`` with its character
(hardening / softening) and no SATMD element is named.
"""
from __future__ import annotations

import numpy as np

from ...numerics import force_level

from ...io.recdata import Recording
from ...io.silverbox import load_silverbox_level, load_silverbox_snls, silverbox_levels
from .findings import analyse_generic
from ...signal.periodic import multisine_bla, periodic_blocks
from .periodic import detection_lines_test
from .stats import NonlinearTest, band_scan, distortion_regressors, linearity_test


def ladder_report(directory, alpha: float = 1e-3):
    """The ``nonlinear`` report of the level ladder (see the module docstring).

    Parameters
    ----------
    directory : folder with the ``SNJP_*`` files
    alpha : level of each test

    Returns
    -------
    NonlinearReport
    """
    levels = silverbox_levels(directory)
    frfs, stds, tests, rms, freq = [], [], [], [], None
    for level in levels:
        rec = load_silverbox_level(directory, level)
        n = int(rec.meta["period_samples"])
        lines = np.array([int(k) for k in rec.meta["lines"].split(",")])
        u, y = periodic_blocks(rec["force"], n)[None], periodic_blocks(rec["y"], n)[None]
        bla = multisine_bla(u, y, lines, rec.fs_hz)
        freq = bla["freq_hz"]
        frfs.append({"y": bla["bla"]})
        stds.append({"y": bla["std"]})
        t = detection_lines_test(u, y, lines, rec.fs_hz, alpha=alpha / len(levels), name=f"distortion_lines@{level}")
        tests.append(t)
        rms.append(force_level(rec["force"]))
    return analyse_generic(frfs, stds, freq, rms, tests, alpha)


def snls_report(directory, alpha: float = 1e-3):
    """The ``nonlinear`` report of SNLS80mV: arrow halves and multisine distortion (see the module docstring).

    Parameters
    ----------
    directory : folder with ``SNLS80mV.mat``
    alpha : level of each test

    Returns
    -------
    NonlinearReport
    """
    from ...signal.lpm import lpm

    arrow, ms = load_silverbox_snls(directory)
    half = arrow.n_samples // 2
    parts = [Recording(arrow.fs_hz, {"force": arrow["force"][a:b], "acc1": arrow["y"][a:b]})
             for a, b in ((0, half), (half, 2 * half))]
    from ...signal.lpm import excited_band

    edges = [excited_band(p["force"], p.fs_hz)[:2] for p in parts]
    band = (max(20.0, *(e[0] for e in edges)), min(200.0, *(e[1] for e in edges)))  # one grid for both halves
    ests = [lpm(p, band_hz=band, width_hz=0.5) for p in parts]
    freq = np.intersect1d(np.round(ests[0].freq_hz, 9), np.round(ests[1].freq_hz, 9))
    idx = [np.searchsorted(np.round(e.freq_hz, 9), freq) for e in ests]
    frfs = [{"y": e.frf["a1"][i]} for e, i in zip(ests, idx)]
    stds = [{"y": e.std["a1"][i]} for e, i in zip(ests, idx)]
    levels = [force_level(p["force"]) for p in parts]
    test = _multisine_distortion(ms, band, alpha / 2)
    return analyse_generic(frfs, stds, freq, levels, [test], alpha / 2)


def _multisine_distortion(ms, band_hz, alpha) -> NonlinearTest:
    """Distortion regressors on every steady-state multisine period, scores summed over realisations."""
    fs = ms["fs_hz"]
    scores, freq, dof = None, None, 0
    for u, y in zip(ms["u"][:, 0], ms["y"][:, 0]):
        yc = y - y.mean()
        regs = distortion_regressors({"y": yc, "dy": np.gradient(yc) * fs},
                                     {"y": ("square", "cube"), "dy": ("cube", "absv")})
        t = linearity_test(u, {"y": y}, fs, regs, band_hz=band_hz, alpha=alpha)
        if "scores" not in t.details:
            continue
        scores = t.details["scores"] if scores is None else scores + t.details["scores"]
        freq, dof = t.details["freq_hz"], dof + t.details["dof"]
    if scores is None:
        return NonlinearTest("distortion_multisine", 1.0, [], alpha, {"reason": "no usable period"})
    p, bands, p_g, p_b = band_scan(freq, scores, dof, alpha)
    from .distortion import concentrated_bands

    t = NonlinearTest("distortion_multisine", p, bands, alpha, {"scores": scores, "freq_hz": freq, "dof": dof,
                                                                 "p_global": p_g, "p_band": p_b})
    return NonlinearTest(t.name, t.p_value, concentrated_bands(t), alpha, t.details)


def _resonance_in(bands, f_lo, f_hi) -> bool:
    return any(a <= f_hi and b >= f_lo for a, b in bands)


def silverbox_verdicts(directory, alpha: float = 1e-3) -> dict:
    """Both Silverbox verdicts as a JSON-ready dict (nonlinear? hardening? at the resonance? SATMD element?).

    Parameters
    ----------
    directory : the Silverbox folder
    alpha : level of the tests

    Returns
    -------
    dict
        ``ladder`` and ``snls``: the ``nonlinear`` blocks, plus ``verdict`` per
        record and a one-line ``summary``.
    """
    from ...physics.nonlinear import NONLINEAR

    out: dict[str, object] = {}
    words: list[str] = []
    for key, fn in (("ladder", ladder_report), ("snls", snls_report)):
        rep = fn(directory, alpha)
        f = rep.findings[0] if rep.findings else {}
        fn_hz = f.get("equivalent_linear", {}).get("f_n_hz", [])
        lt = next((t for t in rep.tests if t.name == "level_dependence"), None)
        lo = min(fn_hz) if fn_hz else 60.0
        hi = max(fn_hz) if fn_hz else 90.0
        verdict = {"nonlinear": bool(rep.detected), "character": f.get("character"),
                   "at_resonance": bool(lt is not None and _resonance_in(lt.bands_hz, 0.9 * lo, 1.1 * hi)),
                   "satmd_element_named": any(x.get("name") in NONLINEAR for x in rep.findings),
                   "f_n_hz": fn_hz}
        out[key] = {"nonlinear": rep.to_dict(), "verdict": verdict}
        words.append(f"{key}: {'nonlinear' if verdict['nonlinear'] else 'linear'}, {verdict['character']}, "
                     f"{'at' if verdict['at_resonance'] else 'not at'} the resonance "
                     f"(f_n {', '.join(f'{x:.1f}' for x in fn_hz)} Hz), "
                     f"{'a SATMD element named' if verdict['satmd_element_named'] else 'no SATMD element named'}")
    out["summary"] = "; ".join(words)
    return out

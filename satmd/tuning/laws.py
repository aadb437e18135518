"""Classical closed-form tuning laws, and their designs on a given rig.

Piezoelectric RL shunt on one structural mode (open/short-circuit natural
frequencies ω_oc, ω_sc; generalised coupling k_c² = (ω_oc² − ω_sc²)/ω_sc²):

- equal peaks (Yamada et al. 2010, Thomas et al. 2012):
  L = 1/(Cp ω_oc²), R = √(3/2)·k_c/(Cp ω_oc)
- Hagood & von Flotow (1991): the same L, R = √2·k_c/((1 + k_c²) Cp ω_sc)

Mechanical TMD of mass ratio μ = m2/m1 on an undamped host (ω1 = √(k1/m1)):

- Den Hartog: ω2/ω1 = 1/(1 + μ), ζ = √(3μ / (8 (1 + μ)³))
- Nishihara & Asami (2002), exact H∞:
  ω2/ω1 = 2/(1 + μ)·√(2 (16 + 23μ + 9μ² + 2 (2 + μ)√(4 + 3μ)) / (3 (64 + 80μ + 27μ²))),
  ζ = ¼·√((8 + 9μ − 4√(4 + 3μ)) / (1 + μ))
- Asami et al. (2002), H2 for a white-noise force:
  ω2/ω1 = √(1 + μ/2)/(1 + μ), ζ = √(μ (1 + 3μ/4) / (4 (1 + μ)(1 + μ/2)))

with kp = m2 ω2², cp = 2 ζ √(kp m2). On a user's rig the mode frequencies
come from the model itself (peaks of the undamped open- and short-circuit
responses), so the laws are checked exactly where the user will use them.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..physics.effects import Effect
from ..physics.rig import Rig
from .objective import band_grid, magnitude, refine_peaks

OPEN_CIRCUIT_R = 1e12  # Ω: R -> ∞ leaves the piezo open


def equal_peak_shunt(Cp: float, f_oc: float, f_sc: float) -> dict:
    """Equal-peak RL shunt for one mode.

    Parameters
    ----------
    Cp : piezo capacitance [F]
    f_oc, f_sc : open- and short-circuit natural frequencies of the mode [Hz]

    Returns
    -------
    {"R": Ω, "L": H}
    """
    w_oc, w_sc = 2 * math.pi * f_oc, 2 * math.pi * f_sc
    kc = math.sqrt(max(w_oc**2 - w_sc**2, 0.0)) / w_sc
    return {"R": math.sqrt(1.5) * kc / (Cp * w_oc), "L": 1.0 / (Cp * w_oc**2)}


def hagood_von_flotow_shunt(Cp: float, f_oc: float, f_sc: float) -> dict:
    """Hagood & von Flotow's RL shunt {R, L}."""
    w_oc, w_sc = 2 * math.pi * f_oc, 2 * math.pi * f_sc
    kc = math.sqrt(max(w_oc**2 - w_sc**2, 0.0)) / w_sc
    return {"R": math.sqrt(2.0) * kc / ((1 + kc**2) * Cp * w_sc), "L": 1.0 / (Cp * w_oc**2)}


def den_hartog(mu: float) -> tuple[float, float]:
    """(frequency ratio, damping ratio) of Den Hartog's fixed-point tuning."""
    return 1.0 / (1.0 + mu), math.sqrt(3 * mu / (8 * (1 + mu) ** 3))


def nishihara_asami(mu: float) -> tuple[float, float]:
    """(frequency ratio, damping ratio) of the exact H∞ optimum (Nishihara & Asami 2002)."""
    s = math.sqrt(4 + 3 * mu)
    ratio = 2 / (1 + mu) * math.sqrt(2 * (16 + 23 * mu + 9 * mu**2 + 2 * (2 + mu) * s)
                                     / (3 * (64 + 80 * mu + 27 * mu**2)))
    return ratio, 0.25 * math.sqrt((8 + 9 * mu - 4 * s) / (1 + mu))


def asami_h2(mu: float) -> tuple[float, float]:
    """(frequency ratio, damping ratio) of the H2 optimum for a white-noise force."""
    return math.sqrt(1 + mu / 2) / (1 + mu), math.sqrt(mu * (1 + 0.75 * mu) / (4 * (1 + mu) * (1 + mu / 2)))


def tmd_design(m1: float, k1: float, m2: float, ratio: float, zeta: float) -> dict:
    """{kp, cp} of a TMD of mass m2 at frequency ratio ``ratio`` and damping ratio ``zeta``."""
    kp = m2 * (ratio * math.sqrt(k1 / m1)) ** 2
    return {"kp": kp, "cp": 2 * zeta * math.sqrt(kp * m2)}


def effective_rig(rig: Rig, effects: Sequence[Effect]) -> Rig:
    """The rig after the effects that replace fixed parameters (parameter_offset)."""
    for eff in effects:
        rig = eff.rig(rig)
    return rig


def shunt_modes(rig: Rig, effects: Sequence[Effect], band_hz) -> list[tuple[float, float]]:
    """(f_oc, f_sc) in Hz of each mode the shunt couples to, from the undamped model's peaks."""
    undamped = rig.replace(c1=0.0, cp=0.0)
    grid = band_grid((band_hz[0] / 1.5, band_hz[1] * 1.5), 0.002)
    peaks = []
    for r in (undamped.replace(R=OPEN_CIRCUIT_R), undamped.replace(R=0.0, L=0.0)):
        def mag(f, r=r):
            return np.atleast_2d(magnitude(f, r, effects, "u1"))

        m = mag(grid)
        f, v = refine_peaks(grid, m, mag, k=4)
        keep = v[0] > 1.5 * np.minimum(m[0, 0], m[0, -1])  # resonances, not the grid's ends
        peaks.append(np.unique(np.round(f[0][keep], 9)))
    f_oc, f_sc = peaks
    pairs = []
    for fo in f_oc:  # each open-circuit mode with the nearest short-circuit mode at or below it
        below = f_sc[f_sc <= fo * (1 + 1e-9)]
        if below.size:
            pairs.append((float(fo), float(below.max())))
    return pairs


def closed_forms(rig: Rig, effects: Sequence[Effect], design: Sequence[str], kind: str, band_hz) -> list[dict]:
    """The classical laws that apply to this design, on this rig.

    Parameters
    ----------
    rig, effects : the model
    design : names of the design variables (RL laws need R and L; TMD laws kp and cp)
    kind : "hinf" or "h2" (the H2 TMD law is added for "h2")
    band_hz : (lo, hi) in Hz; only modes inside it are used

    Returns
    -------
    list of {"name", "design", "note"} (the caller evaluates each design)
    """
    eff_rig = effective_rig(rig, effects)
    out = []
    if {"R", "L"} <= set(design) and float(eff_rig.e) > 0:
        for f_oc, f_sc in shunt_modes(rig, effects, band_hz):
            if not band_hz[0] <= f_oc <= band_hz[1] or f_oc <= f_sc:
                continue
            kc = math.sqrt((f_oc**2 - f_sc**2)) / f_sc
            note = f"mode at {f_oc:.4g} Hz open / {f_sc:.4g} Hz short circuit, k_c = {kc:.3g}"
            Cp = float(eff_rig.Cp)
            out.append({"name": "equal-peak RL shunt (L = 1/(Cp ω_oc²), R = √(3/2)·k_c/(Cp ω_oc))",
                        "design": equal_peak_shunt(Cp, f_oc, f_sc), "note": note})
            out.append({"name": "Hagood & von Flotow RL shunt (R = √2·k_c/((1+k_c²) Cp ω_sc))",
                        "design": hagood_von_flotow_shunt(Cp, f_oc, f_sc), "note": note})
    if {"kp", "cp"} <= set(design):
        m1, k1, m2 = float(eff_rig.m1), float(eff_rig.k1), float(eff_rig.m2)
        mu = m2 / m1
        laws = [("Den Hartog", den_hartog(mu)), ("Nishihara & Asami exact H∞", nishihara_asami(mu))]
        if kind == "h2":
            laws.append(("Asami H2 (white-noise force)", asami_h2(mu)))
        for name, (ratio, zeta) in laws:
            out.append({"name": f"{name} TMD", "design": tmd_design(m1, k1, m2, ratio, zeta),
                        "note": f"μ = {mu:.4g}, frequency ratio {ratio:.5f}, damping ratio {zeta:.5f} "
                                "(undamped host, e = 0)"})
    return out

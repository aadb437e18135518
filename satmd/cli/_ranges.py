"""Usable ranges of the values the commands take, refused by the option's name as typed (issue 38)."""
from __future__ import annotations

from ..errors import SatmdError
from ..physics import Rig

RIG_SCALE = 1e6  # rig values within a factor 1e6 of the paper's rig: beyond, the model's numbers overflow


def check_rig_scale(where: str, name: str, x: float):
    """Refuse a rig value (or bound, setting, std) more than a factor `RIG_SCALE` from the paper's rig; 0 passes.

    ``where`` names the option as the user typed it; the message gives the usable range.
    """
    ref = Rig().as_dict().get(name)
    if ref and x != 0 and not (abs(ref) / RIG_SCALE <= abs(x) <= abs(ref) * RIG_SCALE):
        raise SatmdError(f"{where}: {x:g} is more than a factor {RIG_SCALE:g} from the paper's {name} = {ref:g}; "
                         f"use {abs(ref) / RIG_SCALE:g}..{abs(ref) * RIG_SCALE:g} (SI units)")


def check_element_range(where: str, element):
    """Refuse a nonlinear element's parameter outside the range satmd fits it over (its ``search`` range).

    ``where`` names the option as typed (``--nonlinear cubic_absorber_spring:k3=1e300``); beyond that range
    the time-domain integrator's numbers overflow, so the message gives the range instead.
    """
    for spec in element.parameter_specs:
        lo, hi = spec.search or spec.hard
        x = float(element.params[spec.name])
        if not lo <= x <= hi:
            raise SatmdError(f"{where}: {spec.name}={x:g} is outside the usable {lo:g}..{hi:g} {spec.unit}".rstrip())

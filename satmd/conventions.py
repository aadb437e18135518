"""Facts every package shares, written once (issue 25): parameter and channel names, SPEC ranges, constants.

This module sits at the floor of the import graph beside `satmd.physics` and imports nothing from
satmd, so every package may take its names from here. A fact that appears in two packages belongs
here; ``tests/test_structure.py`` refuses the literals of the default free set and of the
acceleration channels anywhere else.
"""
from __future__ import annotations

#: Parameters fitted by default (SPEC §9): absorber mass, absorber spring, shunt resistance, inductance.
DEFAULT_FREE = ("m2", "kp", "R", "L")

#: The measured channels: accelerations of the primary (a1) and absorber (a2) mass per unit force.
ACCEL_CHANNELS = ("a1", "a2")

#: Recording signal name -> FRF channel it gives when divided by the force.
RECORDING_CHANNELS = {"acc1": "a1", "acc2": "a2"}

#: SPEC §9: where the true values of the default free parameters may lie.
SPEC_RANGES = {"m2": (0.3, 0.8), "kp": (5e4, 2e5), "R": (5.0, 100.0), "L": (0.02, 0.5)}

#: BIC an effect or hypothesis must gain to be named; models closer than this are equivalent explanations
#: ("very strong" evidence on Kass & Raftery's scale), in linear and nonlinear discovery alike.
MIN_DELTA_BIC = 10.0

#: A positive floor for divisions and logarithms (far below any physical quantity, above 0).
TINY = 1e-300

#: The paper's band [Hz]: the default wherever a band is not given (simulation, tuning, linearisation).
PAPER_BAND_HZ = (20.0, 200.0)

#: The relative error an FRF estimated from a recording carries beyond its noise std (the estimator's own
#: model, sampling and the chain's filters): a change smaller than this everywhere is not evidence of physics.
ESTIMATE_REL_FLOOR = 1e-3

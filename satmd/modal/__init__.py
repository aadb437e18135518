"""Modal identification of measured FRFs: several modes at once, and how they move with level.

>>> fits = [fit_modes(d.freq_hz, d) for d in (level1, level2, level3)]   # doctest: +SKIP
>>> [t.to_dict() for t in track_modes(fits, [10.0, 40.0, 80.0]) if t.moves]  # doctest: +SKIP

`fit_modes` works in two steps:

1. poles: a least-squares complex-frequency fit of a rational fraction with one denominator
   common to all output channels (the rational-fraction polynomial method of Richardson &
   Formenti 1982, IMAC I; in the z-domain form of the pLSCF estimator, Guillaume, Verboven,
   Vanlanduit, Van der Auweraer & Peeters 2003, IMAC XXI), solved by its reduced normal equations
   at every model order up to ``max_order``. A pole that stays put from one order to the next
   (``STABLE_F`` in frequency, ``STABLE_ZETA`` in damping) is stable; a mode is a frequency where
   stable poles gather over many orders (the stabilisation diagram, read automatically);
2. refinement: a weighted nonlinear least-squares fit (`scipy.optimize.least_squares`) of the
   pole-residue model with residual terms, per channel o::

       H_o(ω) = Σ_r [A_or / (iω − λ_r) + A_or* / (iω − λ_r*)] + c0_o + c1_o (ω_c/ω)² + c2_o (ω/ω_c)²

   Only the poles λ_r (as f and ζ) are searched; residues A and residual terms c (complex) are
   solved linearly at every step (variable projection). The covariance of (f, ζ) is the inverse of
   JᵀJ of the weighted residual, scaled by the reduced χ² when no std is given, and also when the
   std leaves a misfit (χ²_red > 1: the data hold more than noise). A mode whose removal raises χ²
   (in those units) by less than the BIC penalty is dropped, weakest first.

`follow_modes` fits several levels of one structure from one set of modes, each level started from the
one below (a resonance that the joint damps away or splits at the top level is still followed), and
reads the trends; `track_modes` matches the modes of fits at several levels (nearest frequency, within a half-power
width) and reads per mode whether its frequency and damping move: the change from the lowest to
the highest level against its combined std, two-sided, at ``alpha`` for all modes and both
quantities together (Bonferroni).
"""
from __future__ import annotations

from .fit import ModalFit, Mode, fit_modes
from .levels import follow_modes
from .poles import stable_poles
from .shapes import ModalSurvey, survey
from .tracking import TrackedMode, read_trends, track_modes

__all__ = ["fit_modes", "survey", "ModalSurvey", "track_modes", "follow_modes", "read_trends", "stable_poles", "Mode", "ModalFit",
           "TrackedMode"]

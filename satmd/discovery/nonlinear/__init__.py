"""Nonlinear rigs: detect, locate and name what a linear FRF cannot hold (SPEC §8b, the ``nonlinear`` block of §9).

>>> rep = discover_nonlinear([rec_low, rec_high])          # doctest: +SKIP
>>> rep.detected, [f["name"] for f in rep.findings]         # doctest: +SKIP
(True, ['cubic_absorber_spring'])

Modules: `distortion` (the tests of one recording, the report), `stats` (their statistics), `periodic`
(multisine detection lines), `findings` (the block assembled), `naming` (which parameter moves, which
element), `modes` (a structure that is not a SATMD rig, resonance by resonance), `levels` (`discover` on
several recordings), `silverbox` (the verdicts on that benchmark).

Steps (each module says how):

1. detect from each recording: nonlinear distortion regressors in local
   polynomial windows, one regressor at a time in windows about a resonance wide
   (`stats.separate_linearity_test`, Bonferroni over the regressors),
   or the detection lines of a multisine (`periodic`);
2. detect from several: their FRFs against their noise
   (`stats.level_dependence`), located as bands;
3. name (SATMD rigs): which linear parameter moves with level and which way,
   by joint fits (`naming`), then the element's strength from its own
   equivalent linearisation; a generic input→output record gets a one-mode fit
   per level (hardening when the resonance rises);
4. say which experiment would settle what is open.

The level α is split: half for the distortion tests (Bonferroni over the
recordings), half for the level-dependence test.
"""
from __future__ import annotations

from .distortion import (
    EXPERIMENT_LEVEL,
    EXPERIMENT_MULTISINE,
    UNEXPLAINED_NL,
    NonlinearReport,
    concentrated_bands,
    distortion_test,
    linear_prediction,
    multisine_test,
    strongest_regressor,
)
from .stats import NonlinearTest

__all__ = ["NonlinearReport", "NonlinearTest", "distortion_test", "multisine_test", "linear_prediction",
           "strongest_regressor", "concentrated_bands", "UNEXPLAINED_NL", "EXPERIMENT_LEVEL", "EXPERIMENT_MULTISINE"]

"""Nonlinear elements fitted in the time domain (SPEC §8b): output error over every recording at once.

Modules: `fit` (`fit_nonlinear`, `predict`: one integrator driven by the measured force), `drive` (the
band-limited drive and the error on the excited band), `stats` (errors-in-variables correction and
sandwich covariance), `result` (`NonlinearFit`), `compare` (linear against nonlinear, per level).
"""
from __future__ import annotations

from .drive import band_error
from .fit import fit_nonlinear, linear_start, predict, prepare, simulate_batch
from .result import NonlinearFit

__all__ = ["fit_nonlinear", "predict", "prepare", "linear_start", "simulate_batch", "band_error", "NonlinearFit"]

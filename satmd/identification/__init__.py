"""Use case I: grey-box identification of rig and effect parameters from FRFs.

>>> from satmd import simulate, identify, Rig
>>> fit = identify(simulate(rig=Rig(m2=0.6, R=40.0)))
>>> round(fit.values["m2"], 6), round(fit.values["R"], 4)
(0.6, 40.0)
"""
from .fit import identify
from .many import identify_many
from .nonlinear.fit import fit_nonlinear, predict
from .nonlinear.result import NonlinearFit
from .problem import RIG_BOUNDS, SEARCH_RANGES, Problem
from .result import FitResult

__all__ = ["identify", "identify_many", "fit_nonlinear", "predict", "NonlinearFit", "FitResult", "Problem",
           "RIG_BOUNDS", "SEARCH_RANGES"]

"""Shunt tuning: the best R and L (or any rig parameters) for a measured or modelled rig.

>>> from satmd import Rig, tune
>>> res = tune(Rig(), band_hz=(20, 200))                 # doctest: +SKIP
>>> round(res.design["R"], 1), round(res.attenuation_db["vs_current"], 2)   # doctest: +SKIP
(46.9, 8.68)

Modules: `objective` (H∞ true peak / H2 RMS over a band, batched),
`optimiser` (Sobol + restarted Nelder–Mead in log space), `robust`
(fixed parameter draws, quantiles), `laws` (classical closed forms),
`drift` (retuning a drifting rig over time), `result` (TuneResult),
`core` (the `tune` function).
"""
from .core import tune
from .drift import RetuneResult, retune
from .result import TuneResult

__all__ = ["tune", "TuneResult", "retune", "RetuneResult"]

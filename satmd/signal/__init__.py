"""From a time recording to FRFs: the excitation, every estimator, and what the measurement chain did.

A recording (`satmd.io.Recording`) comes in once; `detect_excitation` reads what drove it (random, periodic,
impact, sweep) and the recording carries that (`with_excitation`); `estimate_frf` then calls the
estimator the excitation calls for, and every estimate says how it was made (`FRFData.estimator`).

- `excitation` (with `hits`, `sweep`): what excited the structure;
- `lpm`: the local polynomial method (random forces; the default);
- `periodic`: the mean over steady periods at the excited lines (periodic forces);
- `impact`: H1 over hits; `sweepfrf`: sine sweeps; `welch`: Welch H1/H2 on request;
- `transmissibility`: output-only recordings (A2/A1);
- `chain`, `forcefloor`: findings about the measurement chain (clipping, a force floor, leakage);
- `estimate`: `estimate_frf`, the one door; `memo`: each recording analysed once per setting;
- `every_channel`: `estimate_frfs`, the FRF of every response channel of a structure's recording.
"""
from __future__ import annotations

from .estimate import estimate_frf
from .every_channel import estimate_frfs
from .excitation import Excitation, detect_excitation
from .transmissibility import Transmissibility, model_transmissibility, save_transmissibility, transmissibility
from .welch import default_nperseg

__all__ = ["estimate_frf", "estimate_frfs", "Excitation", "detect_excitation",
           "Transmissibility", "transmissibility", "model_transmissibility", "save_transmissibility",
           "default_nperseg"]

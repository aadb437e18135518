"""Use case II: the amortized inverse, acceleration FRFs -> shunt R, L (SPEC §5).

>>> from satmd.inverse import InverseModel
>>> model = InverseModel(kind="physics", preset="paper").fit()      # doctest: +SKIP
>>> model.predict(satmd.simulate(rig=satmd.Rig(R=30.0, L=0.15)))    # doctest: +SKIP
{'R': array([30.0...]), 'L': array([0.150...]), 'R_std': ..., 'L_std': ...}

Kinds: ``physics`` (eq. 22 loss through the torch twin), ``supervised``
(MSE on labels), ``optimization`` (repeated global least squares) and
``hybrid`` (net + a few least-squares steps): strategy objects in
`satmd.inverse.strategies`. Every prediction carries a forward check
(``residual_ratio``, ``explained``), and FRFs on any grid are brought onto the
net's (`satmd.inverse.inputs`).
The NumPy parts (datasets, metadata) import without torch; the nets need it.
"""
from .dataset import (
    BLIND_PAIRS,
    BOUNDS,
    BOX_RANGE,
    OFF_CURVE_PAIRS,
    PAPER_PAIRS,
    PAPER_TABLE2,
    PAPER_TABLE2_MAE,
    InverseDataset,
    make_dataset,
    pairs_dataset,
)
from .evaluation import evaluate
from .model import InverseModel, normalised_outputs
from .strategies import KINDS, NET_KINDS

__all__ = [
    "InverseModel", "normalised_outputs", "KINDS", "NET_KINDS", "InverseDataset", "make_dataset", "pairs_dataset",
    "evaluate",
    "BOUNDS", "BOX_RANGE", "PAPER_PAIRS", "BLIND_PAIRS", "OFF_CURVE_PAIRS", "PAPER_TABLE2", "PAPER_TABLE2_MAE",
]

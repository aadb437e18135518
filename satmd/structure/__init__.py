"""Structures that are not a SATMD rig (SPEC §11): one force, any number of accelerometers, several levels.

A ground vibration test asks which connection is nonlinear, what it does, and what the structure will
do at a level that was not tested. This package answers the first two:

- `spectra`: the steady spectra of every channel of a periodic test (the mean over steady periods at
  every line), and the relative displacement and velocity of two sensors from their accelerations;
- `laws`: the joint laws of SPEC §11 (`cubic`, `softening`, `clearance`, `friction`,
  `quadratic_damping`, and `sparse`), each one object that knows its terms, their names and its
  description;
- `locate`: `locate_joint`, between which two sensors (or one sensor and the ground) a joint acts and
  which law it follows, ranked by evidence (ΔBIC) over every pair.

and then models it and predicts levels that were not measured:

- `linear`: `LinearStructure`, the lowest level as a stable pole-residue model of every channel
  (`satmd.modal.rational.vector_fit`), in time;
- `startup`: the modes above the force's band that a record's start from rest rings (its step is the only
  force there), found in time;
- `kernel`: the joint's force sample by sample (an implicit step, compiled with numba when it is there);
- `model`: `StructureModel` (the linear part and its `Joint`), `simulate`, `predict`, JSON `save`/`load`;
- `starts`: where the fit starts, the joint's law and path from the levels' spectra (the lowest level as the
  structure, or the structure under the joint from every level at once);
- `fit`: `fit_structure`, the model fitted on every level at once (from those starts, output error in time,
  the parameters' intervals; of the laws each fitted, the one that simulates best and whose sign agrees with
  its name);
- `newtons`: the joint's coefficients in newtons (its path scaled by reciprocity through the driving point),
  and the sign the modes' shapes give a path whose scale they do not fix.

How (`locate`): the nonlinear force of a joint is a feedback input to the linear structure (nonlinear
subspace identification, FNSI: Noël & Kerschen 2013). With the structure's poles from its lowest level,
the response at a higher level minus the lowest level's FRF times its force is, at every line and on
every channel, a sum of unknown smooth transfer functions (residues on the same poles) times the
spectra of the law's terms of one pair's relative motion. Every pair is one linear least-squares
problem; the pair whose motion explains the level change best is the joint's place.
"""
from __future__ import annotations

from .laws import LAWS, JointLaw, law
from .fit import fit_structure
from .linear import LinearStructure
from .locate import JointLocation, locate_joint
from .model import Joint, Prediction, StructureModel
from .spectra import transient_spectra

__all__ = ["locate_joint", "JointLocation", "JointLaw", "LAWS", "law", "fit_structure", "StructureModel", "Joint",
           "Prediction", "LinearStructure", "transient_spectra"]

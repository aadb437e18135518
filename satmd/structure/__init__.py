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

The joint's model in time and the prediction of levels that were not measured (SPEC §11's
`StructureModel`, `satmd predict`) will live here too (`model`); they are not built yet.

How (`locate`): the nonlinear force of a joint is a feedback input to the linear structure (nonlinear
subspace identification, FNSI: Noël & Kerschen 2013). With the structure's poles from its lowest level,
the response at a higher level minus the lowest level's FRF times its force is, at every line and on
every channel, a sum of unknown smooth transfer functions (residues on the same poles) times the
spectra of the law's terms of one pair's relative motion. Every pair is one linear least-squares
problem; the pair whose motion explains the level change best is the joint's place.
"""
from __future__ import annotations

from .laws import LAWS, JointLaw, law
from .locate import JointLocation, locate_joint

__all__ = ["locate_joint", "JointLocation", "JointLaw", "LAWS", "law"]

"""`StructureModel`: the structure's linear part plus its joint, simulated in time from a measured force.

Fitted by `fit_structure` on recordings at several levels (SPEC §11):

1. **Where and what** (`locate_joint`, unless given): the pair of sensors and the law.
2. **Linear part** from the lowest level (`linear.fit_linear`): a stable pole-residue model of every
   channel. The pair's relative motion is a small difference of two large accelerations, so the model
   is fitted on the channels with the pair's first sensor replaced by the difference: a few per cent of
   error on each sensor would otherwise be all of the joint's stroke. With the modes above the force's
   band that a start from rest rings (`startup.start_up_modes`).
3. **Start** in the frequency domain, every level at once: the change ``E_o = A_o − H_o F`` is the
   joint's force ``G = Σ c_j t_j(d, v)`` (from the measured relative motion) through the joint's column,
   ``A_or κ_r / (iω − λ_r)`` with a coupling ``κ_r`` per mode (reciprocity: the column of a force at two sensors
   is the force's column scaled per mode). Linear in κ at fixed c and in c at fixed κ: alternated to
   convergence; where this open-loop start makes the closed loop run away, the terms are scaled down until not.
4. **Output error** in time (`scipy.optimize.least_squares`): the responses simulated with each measured force
   (`simulate`), all levels and channels at once, each in units of its RMS; the law and the coupling free.

A periodic force is simulated from rest over one extra period before the record (a lab's record starts in steady
state: its first period answers the period before it) unless its start shows it began from rest (`warmup_of`);
any other force from rest at the first sample. NRMSE (SPEC §11): the error's RMS over the measured RMS, per channel.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from ..errors import DataError
from ..numerics import force_level
from .acquisition import Acquisition
from .bands import above_band_shares, band_top, below_nyquist, share_outside
from .kernel import joint_states
from .laws import law as law_named
from .linear import LinearStructure, as_pairs, discretise, from_pairs, modal_states, response
from .prediction import PREDICTION_SCHEMA, RAN_AWAY, Prediction, finite_nrmse, nrmse  # noqa: F401  (the model's API)
from .spectra import at_the_door, drive_force, warmup_of

SCHEMA = "satmd-structure-model/2"
#: the schemas a model may be read from: /1 had no ``stroke`` (the pair's residues were never re-solved), so a
#: reader of /1 would take /2's re-solved residues for the stroke
SCHEMAS = ("satmd-structure-model/1", SCHEMA)


@dataclass(frozen=True)
class Joint:
    """A joint between two sensors (``b`` may be ``"ground"``): its law, coefficients and path.

    Attributes
    ----------
    between : (a, b); the joint's stroke is ``d = x_a − x_b``
    law : the law's name (`satmd.structure.laws.LAWS`)
    coefficients : (J,) of the law's terms (`JointLaw.all_terms` of its form): force in N per term unit
    aux : (J,) each term's shape constant (a gap in m, a friction's smoothing in m/s)
    coupling : (n,) complex κ_r: the joint's column of residues is the force's times κ
    units : ``"N"`` when the coefficients are forces (the path scaled by reciprocity through a driving
        point), ``"relative"`` when only their product with the path is known
    ci95 : 95 % interval [lo, hi] of each fitted parameter, by the names of `parameters` (from the output-error
        fit's Jacobian, its residuals' correlation in time counted; in newtons the scale's error from the path's
        misfit to the modes' shapes too); empty when not estimated
    form : the law's own terms in the form it takes (`JointLaw.forms`; a friction's stick-slip contact or its
        memoryless Coulomb force); empty: the law's first form
    column : (C, n) complex residues of the joint's force at each channel, re-solved from the recordings
        (`outputs.resolved_outputs`); None: the force's scaled per mode by κ (`column_of`)
    stroke : (n,) complex accelerance residues of the stroke per unit force, kept when the channels' own were
        re-solved (`outputs.resolved_outputs`); None: the pair's difference of the channels' (`stroke_of`)
    """

    between: tuple
    law: str
    coefficients: np.ndarray
    aux: np.ndarray
    coupling: np.ndarray
    units: str = "relative"
    ci95: dict = field(default_factory=dict)
    form: tuple = ()
    column: np.ndarray | None = None
    stroke: np.ndarray | None = None

    @property
    def law_form(self):
        """The `JointLaw` in this joint's form."""
        return law_named(self.law).form(self.form)

    @property
    def terms(self) -> tuple:
        return self.law_form.all_terms

    def parameters(self) -> dict:
        """Each term's coefficient by its name (``k3`` of d³, ``k_contact``, ``k_stick``, ``f_slip`` ...; ``k`` and ``c``
        the change of the joint's linear stiffness and damping) and the shape constants (``gap``, ``d_slip``,
        ``v_slip``)."""
        from .laws import SHAPE_PARAMETERS, TERM_PARAMETERS

        out = {TERM_PARAMETERS[t]: float(c) for t, c in zip(self.terms, self.coefficients)}
        out |= {SHAPE_PARAMETERS[t]: float(a) for t, a in zip(self.terms, self.aux) if t in SHAPE_PARAMETERS}
        return out

    def formula(self) -> str:
        return self.law_form.formula(self.coefficients, self.aux)

    def column_of(self, linear: LinearStructure) -> np.ndarray:
        """(C, n) the joint's force's residues at each channel of ``linear``: ``column`` where it was re-solved,
        else the force's times κ."""
        return linear.residues * self.coupling[None, :] if self.column is None else self.column

    def stroke_of(self, linear: LinearStructure) -> np.ndarray:
        """(n,) the stroke's residues per unit force: ``stroke`` where the channels were re-solved, else the
        difference of the pair's."""
        return linear.pair_residues(*self.between) if self.stroke is None else self.stroke

    def to_dict(self) -> dict:
        return {"between": list(self.between), "law": self.law, "terms": list(self.terms),
                "coefficients": [float(c) for c in self.coefficients], "aux": [float(a) for a in self.aux],
                "coupling": [[float(k.real), float(k.imag)] for k in self.coupling], "units": self.units,
                "formula": self.formula(), "ci95": {k: [float(x) for x in v] for k, v in self.ci95.items()}} | (
                    {} if self.column is None else {"column": [as_pairs(r) for r in self.column]}) | (
                    {} if self.stroke is None else {"stroke": as_pairs(self.stroke)})

    @classmethod
    def from_dict(cls, d: dict) -> "Joint":
        k = np.asarray(d["coupling"], float).reshape(-1, 2)
        named = law_named(str(d["law"]))
        terms = tuple(d.get("terms") or named.all_terms)
        if terms[-2:] != ("d", "v"):
            raise ValueError(f"its {d['law']} joint's terms {', '.join(terms)} do not end in the linear d, v")
        try:
            form = named.form(terms[:-2]).term_names
        except DataError as exc:  # a model saved by a version whose law had other terms
            raise DataError(f"{exc}: fit the model again") from None
        joint = cls(tuple(d["between"]), str(d["law"]), np.asarray(d["coefficients"], float),
                    np.asarray(d["aux"], float), k[:, 0] + 1j * k[:, 1], str(d.get("units", "relative")),
                    {str(n): [float(x) for x in v] for n, v in (d.get("ci95") or {}).items()}, form,
                    None if d.get("column") is None else np.array([from_pairs(r) for r in d["column"]]),
                    None if d.get("stroke") is None else from_pairs(d["stroke"]))
        if not joint.coefficients.size == joint.aux.size == len(joint.terms):
            raise ValueError(f"{joint.coefficients.size} coefficients and {joint.aux.size} shape constants for the "
                             f"terms {', '.join(joint.terms)}")
        return joint


@dataclass(frozen=True)
class StructureModel:
    """A structure's linear part and its joint, fitted on recordings at several levels (SPEC §11).

    Attributes
    ----------
    linear : LinearStructure: the structure under the joint (with no joint, the lowest level)
    joint : Joint, or None (no joint: the structure is linear at every level)
    reference : LinearStructure of the lowest level as measured (its best linear approximation): the linear
        model the joint's model is compared with (SPEC §11 ``linear``); None: ``linear`` is that model
    levels : (lo, hi) force RMS [N] of the recordings fitted
    fit : {"metric": "nrmse", "channels": [...], "files": [...], "linear": [[...]], "nonlinear": [[...]]}
    units : {"force": "N", "response": "m/s²"}
    driving_point : the channel at the force's point, when there is one
    oversample : the joint's force is integrated at this many times the record's rate
    acquisition : the acquisition's low-pass on the joint's share above the force's band (`acquisition`), or None
    band_hz : (lo, hi) Hz the fitted recordings' forces excite: outside it the model was shown nothing of the
        structure, and a force there is flagged (`Prediction.outside_band`); None for a model saved without it
    reach : the largest force of the joint over the fitted recordings, simulated (its units): a force whose level
        lies in the fitted range can still drive the joint beyond it (a sweep dwells on a resonance a multisine of
        the same RMS spreads over its band), flagged (`Prediction.joint_reach`); None without a joint or saved before
    """

    linear: LinearStructure
    joint: Joint | None
    levels: tuple
    fit: dict = field(default_factory=dict)
    units: dict = field(default_factory=lambda: {"force": "N", "response": "m/s²"})
    driving_point: str | None = None
    oversample: int = 4
    reference: LinearStructure | None = None
    acquisition: Acquisition | None = None
    band_hz: tuple | None = None
    reach: float | None = None

    @property
    def channels(self) -> tuple:
        return self.linear.channels

    def simulate(self, force, fs_hz: float, warmup_samples: int = 0, joint: bool = True) -> np.ndarray:
        """(C, N) accelerations simulated from rest with ``force`` (N samples) preceded by its last
        ``warmup_samples`` (a periodic force's period); ``joint=False``: the linear part alone."""
        force = np.asarray(force, float)
        drive = Drive(self, force, fs_hz, warmup_samples)
        return drive.outputs(self.joint if joint else None)

    def predict(self, recording, file: str | None = None) -> Prediction:
        """Simulate a recording's force through the model and compare with its responses (SPEC §11). A recording
        of several realisations (`Recording.realisations`) is simulated one realisation at a time, each from its
        own start or going on from the one before (`_simulated_realisations`), and judged over all of them."""
        name = file or str(recording.meta.get("source", "recording"))
        missing = [c for c in self.channels if c not in recording.channels]
        if missing or "force" not in recording.channels:
            raise DataError(f"{name}: no channel {', '.join(missing or ['force'])} (the model predicts "
                            f"{', '.join(self.channels)} from the force)")
        force = np.asarray(recording["force"], float)
        measured = np.array([np.asarray(recording[c], float) for c in self.channels])
        if not (np.all(np.isfinite(force)) and np.all(np.isfinite(measured))):
            raise DataError(f"{name}: NaN or inf in the force or a response")
        parts, going_on = self._simulated_realisations(recording.realisations())
        measured, lin, nl = (np.concatenate([p[i] for p in parts], axis=1) for i in range(3))
        peaks = [p[3] for p in parts if p[3] is not None]
        peak = max(peaks) if peaks else None
        level = force_level(force)
        lo, hi = self.levels
        fs = float(recording.fs_hz)
        top = band_top(force, fs)
        split = [above_band_shares(s, m, fs, top) for s, m in zip(nl, measured)]
        return Prediction(name, level, bool(level < lo * 0.98 or level > hi * 1.02), self.channels,
                          [finite_nrmse(s, m) for s, m in zip(nl, measured)],
                          [nrmse(s, m) for s, m in zip(lin, measured)],
                          fs, {c: np.array([m, a, b]) for c, m, a, b in zip(self.channels, measured, lin, nl)},
                          top, {"nrmse": [e for e, _ in split], "measured": [t for _, t in split]},
                          self.band_hz, None if self.band_hz is None else share_outside(force, fs, self.band_hz),
                          None if not self.reach or peak is None else peak / self.reach, len(parts), going_on)

    def _simulated_realisations(self, parts):
        """(each realisation's `_simulated`, how many go on from the one before). A lab that changes the phases
        without stopping the shaker starts each realisation in the last one's motion, one that stops starts it
        at rest: each after the first is simulated both ways, and the one its responses are closer to kept (the
        one before from its own start: the structure forgets it within a realisation)."""
        out, going_on = [self._simulated(parts[0])], 0
        for before, part in zip(parts, parts[1:]):
            alone, after = self._simulated(part), self._simulated(part, before)
            misses = [sum(nrmse(s, m) for s, m in zip(sim[2], sim[0])) for sim in (alone, after)]
            out.append(after if misses[1] < misses[0] else alone)
            going_on += int(misses[1] < misses[0])
        return out, going_on

    def _simulated(self, recording, before=None):
        """(measured, linear, nonlinear, the joint's peak force) of one realisation, from its own start or
        (``before``) going on from that one's: responses (C, N) about their means (`centred`: an offset is the
        sensor's)."""
        recording = at_the_door(recording)
        measured = np.array([np.asarray(recording[c], float) for c in self.channels])
        force, warm = drive_force(recording), warmup_of(recording)
        if before is not None:
            before = at_the_door(before)
            force, warm = np.concatenate([drive_force(before), force]), 0  # it settles within the one before
        drive = Drive(self, force, float(recording.fs_hz), warm)
        n = measured.shape[1]
        lin = drive.outputs(None)[:, -n:]
        nl = drive.outputs(self.joint)[:, -n:] if self.joint is not None else lin
        return measured, lin, nl, drive.joint_peak

    def to_dict(self) -> dict:
        return {"schema": SCHEMA, "channels": list(self.channels), "units": dict(self.units),
                "levels": [float(x) for x in self.levels], "driving_point": self.driving_point,
                "oversample": int(self.oversample),
                "linear": self.linear.to_dict(),
                "reference": None if self.reference is None else self.reference.to_dict(),
                "joint": None if self.joint is None else self.joint.to_dict(), "fit": self.fit,
                "acquisition": None if self.acquisition is None else self.acquisition.to_dict(),
                "band_hz": None if self.band_hz is None else [float(x) for x in self.band_hz],
                "reach": None if self.reach is None else float(self.reach)}

    def save(self, path) -> None:
        """Write the model as JSON (never pickle), atomically."""
        from ..io.atomic import atomic_write

        with atomic_write(path, "w") as fh:
            fh.write(json.dumps(self.to_dict(), indent=1))

    @classmethod
    def from_dict(cls, d: dict) -> "StructureModel":
        if d.get("schema") not in SCHEMAS:
            raise DataError(f"not a structure model (schema {d.get('schema')!r}, expected {SCHEMA!r})")
        linear = LinearStructure.from_dict(d["linear"])
        joint = None if d.get("joint") is None else Joint.from_dict(d["joint"])
        if joint is not None and joint.column is not None and joint.column.shape != linear.residues.shape:
            raise ValueError(f"the joint's column is {joint.column.shape}, the residues {linear.residues.shape}")
        if joint is not None and joint.stroke is not None and joint.stroke.shape != linear.poles.shape:
            raise ValueError(f"the joint's stroke has {joint.stroke.size} residues for {linear.poles.size} poles")
        return cls(linear, joint, tuple(d["levels"]), d.get("fit", {}),
                   d.get("units", {"force": "N", "response": "m/s²"}), d.get("driving_point"),
                   int(d.get("oversample", 4)),
                   None if d.get("reference") is None else LinearStructure.from_dict(d["reference"]),
                   None if d.get("acquisition") is None else Acquisition.from_dict(d["acquisition"]),
                   _band(d.get("band_hz")), _reach(d.get("reach")))

    @classmethod
    def load(cls, path) -> "StructureModel":
        """Read a model written by `save`."""
        try:
            with open(path, encoding="utf-8") as fh:
                d = json.load(fh)
        except json.JSONDecodeError as exc:
            raise DataError(f"{path}: not JSON ({exc.msg} at line {exc.lineno})") from None
        try:
            return cls.from_dict(d)
        except DataError as exc:  # e.g. a law or form this version does not know
            raise DataError(f"{path}: {exc}") from None
        except (KeyError, TypeError, ValueError) as exc:
            raise DataError(f"{path}: a structure model with a missing or malformed field ({exc})") from None

    def report(self) -> str:
        lines = [f"structure model: channels {', '.join(self.channels)}, {self.linear.poles.size} poles, "
                 f"fitted at {self.levels[0]:.4g}–{self.levels[1]:.4g} N RMS"]
        if self.joint is None:
            lines.append("no joint: linear at every level")
        else:
            a, b = self.joint.between
            unit = (" N" if self.joint.units == "N" else
                    f" (relative: its path departs from the modes' shapes at the driving point {self.driving_point}, "
                    "so reciprocity does not fix its scale)" if self.driving_point else
                    " (relative: no driving point fixes its scale)")
            lines.append(f"joint between {a} and {b}: {self.joint.law}, force {self.joint.formula()}{unit}")
            if self.acquisition is not None:
                lines.append(self.acquisition.describe())
        if self.fit:
            lines.append("NRMSE (" + ", ".join(self.fit["channels"]) + "): linear → with the joint")
            for f, lin, nl in zip(self.fit["files"], self.fit["linear"], self.fit["nonlinear"]):
                lines.append(f"  {f}: " + ", ".join(f"{a:.3f} → {b:.3f}" for a, b in zip(lin, nl)))
        return "\n".join(lines)


def _band(value) -> tuple | None:
    """A saved model's fitted band: (lo, hi) Hz, 0 <= lo < hi, or None (saved before models kept it)."""
    if value is None:
        return None
    lo, hi = (float(x) for x in value)
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 <= lo < hi):
        raise ValueError(f"band_hz {value!r} is not 0 <= lo < hi")
    return lo, hi


def _reach(value) -> float | None:
    """A saved model's ``reach``: a finite number > 0, or None."""
    if value is None:
        return None
    x = float(value)
    if not (np.isfinite(x) and x > 0):
        raise ValueError(f"reach {value!r} is not a finite number > 0")
    return x


class Drive:
    """One force through the model: the linear part's response and the pair's motion, computed once.

    The joint's force runs at ``oversample`` times the sample rate (the force interpolated band-limited): a
    stick-slip or a contact makes the force change faster than the record's samples follow, and a step at
    the record's rate would smear it. Its response is taken back to the record's samples (`driven`)."""

    def __init__(self, model: StructureModel, force, fs_hz: float, warmup: int):
        from ..physics.nonlinear.integrate import band_limited, upsample

        self.model, self.fs, self.skip, self.force = model, float(fs_hz), int(warmup), force
        self.joint_peak: float | None = None  # the joint's largest force in the last `outputs` with a joint, step 1
        lin = model.linear
        u = np.concatenate([force[force.size - warmup:], force]) if warmup else force
        ub = band_limited(u, fs_hz)
        self.u, self.states = u, modal_states(ub, lin.poles, fs_hz)  # the force with its warm-up; the modes it drives
        self.linear = response(self.states, lin.residues) + lin.feedthrough[:, None] * u
        ref = model.reference
        self.base = self.linear if ref is None else (response(modal_states(ub, ref.poles, fs_hz), ref.residues)
                                                     + ref.feedthrough[:, None] * u)
        self.pair = None
        if model.joint is not None:
            self.r = r = max(1, int(model.oversample))
            fine = r * fs_hz
            uf = band_limited(upsample(u, r), fine) if r > 1 else band_limited(u, fs_hz)
            x = modal_states(uf, lin.poles, fine)
            self.psi, self.G0, self.G1 = discretise(lin.poles, fine)
            self.pair = p = model.joint.stroke_of(lin)
            self.dF, self.vF = response(x, p / lin.poles ** 2), response(x, p / lin.poles)

    def outputs(self, joint: Joint | None, step: int = 1) -> np.ndarray:
        """(C, N) responses (every ``step``-th sample) with ``joint``, or (None) the linear model of the lowest
        level (`StructureModel.reference`)."""
        keep = slice(self.skip, None, step)
        if joint is None:
            return self.base[:, keep]
        g, z = self.driven(joint, step)
        if not np.all(np.isfinite(g)):
            return np.full_like(self.linear[:, keep], np.nan)
        if step == 1:
            self.joint_peak = float(np.max(np.abs(g), initial=0.0))
        share = response(z, joint.column_of(self.model.linear))
        chain = self.model.acquisition
        return self.linear[:, keep] + (share if chain is None or step != 1 else chain.apply(share, self.fs))

    def driven(self, joint: Joint, step: int = 1):
        """(g, w) at the kept samples: the joint's force (NaN from where it ran away) and each mode's state it
        drives with its direct part, ``w_r = z_r + g / λ_r``: a force at the joint's sensors moves them at once,
        the column's flat part (receptance ~ 1/s²). The joint's share of the outputs is ``Re Σ 2 A_r κ_r w_r``.
        The direct part is low-passed below Nyquist, as an acquisition samples (`bands.below_nyquist`); the states,
        which integrate the force, fold less and are taken as they fall (docs/guide/nonlinear.md)."""
        lin = self.model.linear
        pair = self.pair * joint.coupling
        first, stride = self.r * self.skip, self.r * step  # the record's kept samples on the joint's finer steps
        g, z = joint_states(self.psi, self.G0, self.G1, 2 * pair / lin.poles ** 2, 2 * pair / lin.poles, self.dF,
                            self.vF, joint.law_form.codes, np.asarray(joint.coefficients, float),
                            np.asarray(joint.aux, float), first, stride)
        with np.errstate(invalid="ignore", over="ignore"):  # a run-away's NaN is told by ``g``
            return g[first::stride], z + below_nyquist(g, self.r)[first::stride][None, :] / lin.poles[:, None]

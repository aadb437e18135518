"""`fit_structure`: a `StructureModel` from recordings of one structure at several levels (see `model`)."""
from __future__ import annotations

from dataclasses import replace
from functools import partial

import numpy as np

from ..errors import DataError
from ..numerics import on_one_blas_thread, side_by_side
from ..validation import NAMES, Interval, Options, Whole, validate_params
from .acquisition import acquisition_of
from .choice import PLACE_LAWS, best_fitting, best_place, close_rivals, contradicts, ranked_laws
from .laws import LAWS
from .laws import law as law_named
from .linear import fit_linear
from .locate import shape_of
from .model import Drive, Joint, StructureModel
from .newtons import in_newtons
from .loop import PAIRS, with_loop_modes
from .outside import above_band, loop_poles, same_modes
from .output_error import BAND_STEPS, TOP, in_band, output_error, with_band_modes_refined
from .outputs import resolved_outputs
from .simulations import cost, drives_of, fit_span, fitted_realisations, oversampling, stable, with_table
from .spectra import at_the_door, drive_force, periodic_spectra, warmup_of
from .starts import measured_start, simulated_shape, underlying_start, with_modes_above
from .startup import band_top_hz, with_start_up_modes

#: named laws (the best by the levels' spectra) each fitted when three or more levels are given, the one that
#: simulates them best kept: the spectra rank laws by the in-band change alone, and on the F-16 (levels 1, 3, 7)
#: their best, a clearance, fitted them at mean NRMSE 0.32 and predicted level 5 at 0.37-0.62, a friction they
#: ranked fifth at 0.26 and 0.28-0.40. A middle level held out instead (fitted on two) chose quadratic damping
WEIGHED = 5
STARTS = ("measured", "underlying")
APART = 0.02  # of a mode's frequency: added modes above the band closer than this form a cluster (`kept_apart`)
BEYOND = 2.0  # the top level's force times this: a freed path must not run away there where the tied one does not
RUNAWAY = 10.0  # ... nor respond more than this times the top level's measured response, scaled by the force


@validate_params({"between": [None, NAMES], "law": [None, Options(tuple(LAWS))], "channels": [None, NAMES],
                  "n_pairs": [None, Interval(Whole, 1, 24)], "max_nfev": [Interval(Whole, 1)],
                  "driving_point": [None, str], "starts": [NAMES], "free_path": [bool], "polish": [bool]})
@on_one_blas_thread
def fit_structure(recordings, between=None, law: str | None = None, channels=None, n_pairs: int | None = None,
                  max_nfev: int = 40, files=None, driving_point: str | None = None, starts=STARTS,
                  free_path: bool = True, location=None, polish: bool = True, progress=None) -> StructureModel:
    """The structure's linear part and its joint, fitted on every recording at once (SPEC §11).

    Parameters
    ----------
    recordings : Recordings of one structure at two or more levels (a periodic force, the same channels)
    between : (a, b) the joint's sensors (``b`` may be ``"ground"``); default: `locate_joint`'s best place
    law : the law's name; default: `locate_joint`'s law
    channels : the response channels (default every channel but the force)
    n_pairs : pole pairs of the linear part (default: chosen on the lowest level, `fit_linear`)
    max_nfev : evaluations of each output-error fit (each simulates every recording)
    files : names of the recordings for the fit table (default their ``source``)
    driving_point : the channel at the force's point (default: found, `linear.driving_point`); with one the
        joint's coefficients are in newtons (reciprocity fixes the scale of its path), without one relative
    starts : the linear parts the fit starts from, each fitted to the end and the best kept: ``"measured"``
        (the lowest level's best linear approximation) and ``"underlying"`` (the structure under the joint,
        from every level at once)
    free_path : the fit's last stage moves the joint's path κ (its force's input to each mode) with the law's
        coefficients (default): the frequency-domain start finds the path from the in-band change alone, and a
        payload or a support that the joint alone moves is then off at every level (on independent ground
        vibration tests, the place and law given, it cut the worst held-out NRMSE by more than 10 % on 16 of 26
        joints and raised it on one; on the F-16 it changed level 5's by under 0.01). False: the law's
        coefficients and shape constants alone (laws are weighed so, the chosen one is then freed)
    location : a `JointLocation` of these recordings already made (default: `locate_joint` runs when the place
        or the law is not given). With three or more levels and no law given, the named laws (and the ``sparse``
        library when the spectra name it) are each fitted on every level and the model that simulates them best
        is kept (`best_fitting`): the spectra see the in-band change only
    polish : the chosen model's last two stages (default): modes above the band in the joint's loop, then the
        in-band modes refined with the joint's law, each kept where it simulates the records better (on the F-16,
        levels 1 and 7 at 5 evaluations a fit, they took 22 of the fit's 36 s, profiled). False: the model as finished, for
        a quick look (`reproduce --quick`)
    progress : callable(str) told of each stage (the CLI prints it on stderr)

    Returns
    -------
    StructureModel (``joint`` None when no place explains the change between levels)
    """
    from .locate import locate_joint

    from .._progress import stage

    say = progress or stage  # the caller's, else whoever listens (`satmd discover` prints the stages)
    if len(recordings) < 2:
        raise DataError("a structure model needs recordings at two or more levels")
    recordings = [at_the_door(r) for r in fitted_realisations(recordings)]  # each force read once, not at each start
    spectra = [periodic_spectra(r) for r in recordings]
    names = tuple(channels or spectra[0].responses)
    for s in spectra:
        missing = [c for c in names if c not in s.responses]
        if missing:
            raise DataError(f"{s.source}: no channel {', '.join(missing)} (the other levels have it)")
    files = list(files or [s.source for s in spectra])
    fit = _Fit(recordings, spectra, names, n_pairs, max_nfev, starts, driving_point, say)
    if between is None or law is None:
        if location is None:
            say("locating the joint among every pair of sensors ...")
        loc = location or locate_joint(spectra, channels=names, driving_point=driving_point)
        if not loc.detected:
            return replace(fit.linear_only(files), band_hz=fitted_band(spectra))
        place_given, law_given = between is not None, law is not None
        shape, form = None, ()
        if between is None or tuple(between) == loc.between:
            shape, form = (loc.shape, loc.form) if law is None or law == loc.law else (None, ())
        between, law = tuple(between or loc.between), law or loc.law
        weighed = [e["law"] for e in loc.laws if e["law"] != "sparse"][:WEIGHED]
        weighed = ["sparse", *weighed] if law == "sparse" else weighed
        if not law_given and len(recordings) >= 3 and tuple(between) == loc.between and len(weighed) > 1:
            say(f"{', '.join(weighed)}: each fitted on every level, the best kept ...")
            fitted = fit.laws([(between, w) for w in weighed], files)
        else:
            fitted = [fit.law(between, law, files, shape, form)]
            for other in ([] if law_given else [w for w in weighed if w != law]):
                last = fitted[-1]
                if last is None or last.joint is None or not contradicts(last):
                    break  # the spectra's law, or the next that does not contradict its name (`best_fitting`)
                fitted.append(fit.law(between, other, files))
        model = best_fitting(fitted)
        if not place_given and len(recordings) >= 3:
            laws = [law] if law_given else ranked_laws(fitted)[:PLACE_LAWS]
            others = [] if law_given else [w for w in weighed if w not in laws]
            model = best_place(fit, loc, model, laws, others, files)
    else:
        model = fit.law(tuple(between), law, files)
    model = fit.kept_apart(fit.finished_choice(model, free_path, files), free_path, files)
    if polish:
        model = fit.refined(fit.looped(model, files), files)
    return replace(model, band_hz=fitted_band(spectra), reach=fit.reach(model))


def fitted_band(spectra) -> tuple:
    """(lo, hi) Hz: the lowest and highest lines the recordings' forces excite."""
    return min(float(s.freq_hz.min()) for s in spectra), band_top_hz(spectra)


class _Fit:
    """One `fit_structure` call's recordings and settings: a law fitted at a place (`law`), the chosen model
    finished (`finished`)."""

    def __init__(self, recordings, spectra, names, n_pairs, max_nfev, starts, driving_point, say):
        self.recordings, self.spectra, self.names, self.driving_point = recordings, spectra, names, driving_point
        self.n_pairs, self.max_nfev, self.starts, self.say = n_pairs, max_nfev, starts, say
        self.ref = min(spectra, key=lambda s: s.level)
        self.levels = (min(s.level for s in spectra), max(s.level for s in spectra))
        self.span = [fit_span(r) for r in recordings]
        self.measured = [np.array([np.asarray(r[ch], float)[:n] for ch in names]) for r, n in zip(recordings, self.span)]
        self.shapes: dict = {}  # (place, law) -> (linear part, law's form, shape constants): the start of `law`
        self.references: dict = {}  # place -> the lowest level's linear part (`reference`)
        self.tried: list = []  # every law fitted at a place, as first fitted (`finished_choice`)

    def law(self, between, law, files, shape=None, form=(), apart: float = 0.0) -> StructureModel | None:
        """The linear part and (``between`` not None) the joint of ``law`` between ``between``, its path as the
        frequency-domain start found it, with its fit table; the joint's coefficients relative.

        ``apart`` > 0: the starts' modes above the band kept apart (`above_band`), from the start this law had at
        this place before; None where that changes no start's modes."""
        recordings, spectra, names, ref, say = self.recordings, self.spectra, self.names, self.ref, self.say
        for c in (between or ()):
            if c != "ground" and c not in names:
                raise DataError(f"the joint's sensor {c!r} is not a channel ({', '.join(names)})")
        if between is None:
            return self.linear_only(files)
        key = (tuple(between), law)
        d0, v0 = ref.scales(*between)
        if key not in self.shapes:  # a law fitted again at its place (``apart``) starts where it started
            reference = self.reference(tuple(between))
            lw, aux = ((law_named(law).form(form), shape) if shape is not None
                       else shape_of(spectra, between, law, names))
            self.shapes[key] = (reference, *simulated_shape(reference, spectra, between, lw, d0, v0, aux, recordings,
                                                              self.measured, self.span, self.levels))
        reference, lw, aux = self.shapes[key]
        fitted = []
        for start in self.starts:  # the lowest level as the linear part, or the structure under the joint
            if start == "underlying":
                say("the structure under the joint and the joint's path, from every level at once ...")
                try:
                    linear, c, kappa = underlying_start(reference, spectra, between, lw, d0, v0, aux)
                except np.linalg.LinAlgError:  # a vector fit that did not converge: as a start without a joint
                    linear, c = reference, np.full(len(lw.all_terms), np.nan)
                    kappa = np.zeros(reference.poles.size)
            else:
                linear, (c, kappa) = reference, measured_start(reference, spectra, between, lw, d0, v0, aux)
            if not (np.all(np.isfinite(c)) and np.all(np.isfinite(kappa))
                    and np.all(np.isfinite(linear.residues))):
                say(f"the {start} start has no finite joint: left out")
                continue
            joint = Joint(between, law, c, aux, kappa, form=lw.term_names)
            model = StructureModel(linear, joint, self.levels, reference=reference)
            wider = above_band(model, spectra, apart)
            if apart and same_modes(wider, above_band(model, spectra)):
                continue  # this start's fit is the one made without ``apart``
            model, drives = with_modes_above(model, wider, spectra[0].fs_hz, recordings, self.measured, self.span)
            say(f"output-error fit of the {law} joint between {between[0]} and {between[1]} on "
                f"{len(recordings)} recordings (from the {start} linear part) ...")
            fitted.append(output_error(stable(model, drives), drives, ref, self.max_nfev, fixed_path=True))
        if not fitted and apart:
            return None
        if not fitted:  # no start gave a joint to fit: the linear model of the lowest level, said by its table
            return with_table(StructureModel(reference, None, self.levels), recordings, files)
        # judged on the whole records: a model that slowly gathers energy shows it only over many periods
        whole = self.whole(fitted[0])
        model = min(fitted, key=lambda m: cost(m, whole))
        model = with_table(replace(model, driving_point=self.driving_point), recordings, files)
        if not apart:
            self.tried.append(model)
        return model

    def laws(self, tries, files) -> list:
        """`law` of each (place, law) of ``tries``, side by side (`side_by_side`), in their order (in `tried` too)."""
        for between in dict.fromkeys(tuple(b) for b, _ in tries):
            self.reference(between)  # once a place, before the fits share it
        n = len(self.tried)
        fitted = side_by_side([partial(self.law, b, w, files) for b, w in tries])
        self.tried[n:] = [m for m in fitted if any(m is t for t in self.tried[n:])]
        return fitted

    def finished_choice(self, model, free_path, files) -> StructureModel:
        """``model`` `finished`, and the laws at its place that came close to it as first fitted (`close_rivals`:
        for the sparse library, the best named law), each finished too; the best finished kept (`best_fitting`: the
        sparse library only where it still beats the named laws by `SPARSE_MARGIN`). As first fitted, their paths
        the start's, the library's extra terms take up what a named law's path leaves: on independent ground
        vibration tests a beam's clearance to the ground fitted its levels at mean NRMSE 0.150 against the
        library's 0.133, finished at 0.041 against 0.121."""
        rivals = close_rivals(model, self.tried)
        if rivals:
            self.say(f"{', '.join(m.joint.law for m in rivals)} against {model.joint.law}, each finished ...")
        finished = side_by_side([partial(self.finished, m, free_path, files) for m in [model, *rivals]])
        return best_fitting(finished) if rivals else finished[0]

    def finished(self, model, free_path, files) -> StructureModel:
        """``model`` finished: more modes above the band where its fitted law's harmonics ask for them (`widened`),
        its path fitted too (``free_path``), in newtons where a driving point fixes the scale, the channels off the
        joint's pair re-solved (`resolved_outputs`), and the acquisition's low-pass on the joint's harmonics
        (`acquisition_of`)."""
        if model.joint is None:
            return model
        model = self.widened(model)
        if free_path:
            a, b = model.joint.between
            self.say(f"output-error fit of the {model.joint.law} joint between {a} and {b} with its path free ...")
            drives, before = drives_of(model, self.recordings, self.measured, self.span), self.misfit(model)
            holds = self.holds_beyond(model)
            for solved in (True, False):  # the channels solved inside the fit, else tied to the path (`output_error`)
                freed = output_error(model, drives, self.ref, self.max_nfev, fixed_path=False, solved=solved)
                # fitted on the first periods, kept where the whole records say so too (a slow run-away shows there)
                if self.misfit(freed) <= before and (self.holds_beyond(freed) or not holds):
                    model = freed
                    break
        model = in_newtons(model, self.driving_point)
        model = resolved_outputs(model, self.whole(model))
        chain = acquisition_of(model, self.whole(model), band_top_hz(self.spectra))
        return with_table(replace(model, acquisition=chain), self.recordings, files)

    def looped(self, model, files) -> StructureModel:
        """``model`` (finished) with modes above the band in its joint's loop (`loop.with_loop_modes`), at the
        poles the harmonics it leaves point to, its acquisition's low-pass found again, where that simulates the
        whole records better and holds beyond the top level where ``model`` does. Once, on the chosen model: the
        fit moves the added modes' poles too (a minute on two cores where `finished` takes one or two)."""
        if model.joint is None:
            return model
        bare = replace(model, acquisition=None)
        poles = loop_poles(bare, self.spectra, PAIRS)
        if poles.size == 0:
            return model
        hz = ", ".join(f"{f:.1f}" for f in np.abs(poles) / (2 * np.pi))
        self.say(f"modes above the band in the joint's loop, from {hz} Hz ...")
        before, top_hz = self.misfit(model), band_top_hz(self.spectra)

        def with_chain(candidate):  # its acquisition's low-pass found again on the whole records
            return replace(candidate, acquisition=acquisition_of(candidate, self.whole(candidate), top_hz))

        def better(candidate) -> bool:
            return self.misfit(candidate) < before

        looped = with_loop_modes(bare, poles, self.recordings, self.measured, self.span, self.max_nfev,
                                 self.ref.fs_hz, lambda c: better(with_chain(c)))
        if looped is None:
            return model
        looped = with_chain(looped)
        if not better(looped):
            return model
        if not self.holds_beyond(looped) and self.holds_beyond(model):
            return model
        return with_table(looped, self.recordings, files)

    def refined(self, model, files) -> StructureModel:
        """``model`` with its in-band modes and its law's coefficients fitted together (`output_error.with_band_modes_refined`),
        then the modes above the band with them (their harmonics drive those), each kept where it simulates the whole
        records better and holds beyond the top level where ``model`` does. In one fit, the modes above the band took
        a test chain's in-band poles elsewhere (its fitted levels' cost twice the two fits')."""
        if model.joint is None:
            return model
        band, top = fitted_band(self.spectra), TOP * float(self.recordings[0].fs_hz) / 2
        current, holds = self.misfit(model), self.holds_beyond(model)
        for stage, (free, which) in enumerate(((band, "in the band"), ((band[0], top), "in and above the band"))):
            if stage and in_band(model.linear.poles, (band[1], top)).size == 0:
                break  # no mode above the band: the second fit would repeat the first
            self.say(f"the modes {which} refined with the joint's law ...")
            refined = with_band_modes_refined(model, self.recordings, self.measured, self.span, free,
                                              min(self.max_nfev, BAND_STEPS))
            trial = np.inf if refined is None else self.misfit(refined)
            if trial >= current:
                continue
            held = self.holds_beyond(refined)
            if holds and not held:
                continue
            model, current, holds = with_table(refined, self.recordings, files), trial, held
        return model

    def holds_beyond(self, model) -> bool:
        """Whether ``model`` stays finite driven by the top level's force `BEYOND` times over, its response within
        `RUNAWAY` times the top level's measured one scaled by the force: a path freed on the fitted levels can
        close a loop that runs away just past them (a chain's saturating spring named a softening cubic, fitted on
        1 and 8 N RMS, did at 12 N RMS where the path held to the channels predicted 0.11), and modes added in a
        joint's loop can make it ring without bound short of floating point (a chain's clearance, fitted on 1 and
        8 N RMS: 81 times at 16 N where the model without them grew as the force, 1.08; 12 N predicted at 0.93
        against 0.31)."""
        i = max(range(len(self.recordings)), key=lambda n: float(np.std(drive_force(self.recordings[n]))))
        top = self.recordings[i]
        drive = Drive(model, BEYOND * drive_force(top), float(top.fs_hz), warmup_of(top))
        with np.errstate(over="ignore", invalid="ignore"):
            y = drive.outputs(model.joint)
            if not np.all(np.isfinite(y)):
                return False
            growth = np.sqrt(np.mean(y ** 2, axis=1)) / (BEYOND * self.measured[i].std(axis=1))
        return bool(np.all(growth <= RUNAWAY))

    def reach(self, model) -> float | None:
        """The joint's largest force over the recordings, simulated (`StructureModel.reach`); None without one."""
        if model.joint is None:
            return None
        peaks = []
        for drive, _ in self.whole(model):
            drive.outputs(model.joint)
            peaks.append(drive.joint_peak)
        return max(peaks) if all(p is not None and p > 0 for p in peaks) else None

    def linear_only(self, files) -> StructureModel:
        """The lowest level's linear model, no joint, with its fit table."""
        return with_table(StructureModel(self.reference(None), None, self.levels), self.recordings, files)

    def reference(self, between):
        """The lowest level's linear part for a joint between ``between`` (None: no joint), with the modes a start
        from rest shows above the band; fitted once per place, whatever the laws tried there."""
        if between not in self.references:
            self.say(f"linear part from the lowest level ({self.ref.source}) ...")
            self.references[between] = with_start_up_modes(fit_linear(self.ref, self.names, between, self.n_pairs),
                                                           self.recordings, self.spectra, between)
        return self.references[between]

    def kept_apart(self, model, free_path, files) -> StructureModel:
        """``model`` (finished), or its law fitted again from starts whose modes above the band lie `APART` from
        each other, finished too, where that simulates the whole records better. A cluster of lightly damped
        modes added above the band can fit the fitted levels' harmonics and ring at the others; which start
        does better shows only once both are finished (on independent ground vibration tests, a chain's friction
        joint predicted its held-out levels at worst NRMSE 0.038 apart against 0.140, and fitted its own levels
        closer too, while a wing's cubic joint fitted and predicted better with its cluster: 0.43 against 0.80;
        over the 36 joints of tests 0-39, place and law given, 4 predicted better and none worse)."""
        joint = model.joint
        if joint is None:
            return model
        other = self.law(joint.between, joint.law, files, apart=APART)
        if other is None or other.joint is None:
            return model
        self.say(f"the {joint.law} joint fitted again with its modes above the band kept apart ...")
        other = self.finished(other, free_path, files)
        if contradicts(other):
            return model
        return other if self.misfit(other) < self.misfit(model) else model

    def widened(self, model) -> StructureModel:
        """``model`` with more modes above the band (`above_band`), found through its fitted law and its
        coefficients refitted, where that simulates the whole records better. The start's modes above the band
        were found through the law's frequency-domain start; on independent ground vibration tests with a stiff
        contact or a pylon's mode above the band, the fitted law's harmonics placed more (a beam's support:
        the held-out level's NRMSE 0.139 to 0.047)."""
        wider = above_band(model, self.spectra)
        if wider is model:
            return model
        self.say(f"{wider.linear.poles.size - model.linear.poles.size} more mode(s) above the band, through the "
                 f"fitted joint's harmonics ...")
        wider = replace(wider, oversample=oversampling(wider.linear, self.ref.fs_hz))
        wider = output_error(wider, drives_of(wider, self.recordings, self.measured, self.span), self.ref,
                             self.max_nfev, fixed_path=True)
        return wider if self.misfit(wider) < self.misfit(model) else model

    def misfit(self, model) -> float:
        """`cost` of ``model`` on the whole records: what every stage's choice weighs (a slow run-away shows there)."""
        return cost(model, self.whole(model))

    def whole(self, model) -> list:
        """(Drive, measured responses) of every recording, whole, through ``model``."""
        return [(Drive(model, drive_force(r), float(r.fs_hz), warmup_of(r)),
                 np.array([np.asarray(r[ch], float) for ch in self.names])) for r in self.recordings]

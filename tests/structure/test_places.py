"""The joint's place when the levels' spectra and a simulation of the levels disagree (`choice.best_place`): the next
places within reach of the best are fitted on every level, and the one that simulates them best is kept."""
from __future__ import annotations

import numpy as np

from satmd.structure import Joint, JointLocation, LinearStructure, StructureModel
from satmd.structure.choice import PLACES, best_place, ranked_laws, score

LINEAR = LinearStructure(("acc1", "acc2", "acc3"), np.array([-1.0 + 60j]), np.ones((3, 1), complex), np.zeros(3))


class _Fits:
    """`fit._Fit` as `best_place` uses it: a model per (place, law) with a given mean NRMSE and misfit on the whole
    records (``misfits``; by default the mean NRMSE), each call noted."""

    def __init__(self, scores, misfits=None):
        self.scores, self.misfits, self.calls = scores, misfits or {}, []

    def misfit(self, model):
        return self.misfits.get((model.joint.between, model.joint.law), score(model))

    @staticmethod
    def say(text):
        pass

    def law(self, between, law, files):
        self.calls.append((tuple(between), law))
        joint = Joint(tuple(between), law, np.array([1.0, 0.0, 0.0]), np.ones(3), np.ones(1, complex), "N")
        return StructureModel(LINEAR, joint, (1.0, 8.0), fit={"nonlinear": [[self.scores[(tuple(between), law)]]]})

    def laws(self, tries, files):
        return [self.law(b, w, files) for b, w in tries]


def _located(next_gap):
    places = [("acc1", "acc2"), ("acc2", "acc3"), ("acc1", "ground")]
    return JointLocation(("acc1", "acc2"), [{"between": list(p), "delta_bic": d, "law": "cubic"}
                                            for p, d in zip(places, (0.0, next_gap, 5000.0))],
                         "cubic", [{"law": w, "delta_bic": 0.0} for w in ("cubic", "softening", "friction")],
                         [], [], "L1", [1.0, 8.0], evidence=1000.0)


def test_a_next_place_that_simulates_the_levels_better_is_kept_and_its_law_weighed():
    fits = _Fits({(("acc1", "acc2"), "cubic"): 0.05, (("acc2", "acc3"), "cubic"): 0.03,
                  (("acc2", "acc3"), "softening"): 0.02, (("acc2", "acc3"), "friction"): 0.04})
    model = fits.law(("acc1", "acc2"), "cubic", None)
    chosen = best_place(fits, _located(50.0), model, ["cubic"], ["softening", "friction"], None)
    assert chosen.joint.between == ("acc2", "acc3") and chosen.joint.law == "softening"
    # the third place is 5000 behind (over a tenth of the evidence, 1000): not simulated
    assert fits.calls[1:] == [(("acc2", "acc3"), "cubic"), (("acc2", "acc3"), "softening"), (("acc2", "acc3"), "friction")]


def test_places_are_weighed_on_the_misfit_their_fits_minimise_and_laws_on_the_mean_nrmse():
    """A place's best law by mean NRMSE (`best_fitting`); of the places, the one whose model has the least squared
    misfit on the whole records. On an independent chain's clearance the true place's first fit had the higher mean
    NRMSE (0.182 against 0.150) and the lower misfit (0.229 against 0.276)."""
    true, rival = ("acc1", "acc2"), ("acc2", "acc3")
    fits = _Fits({(true, "cubic"): 0.18, (true, "softening"): 0.17, (rival, "cubic"): 0.15},
                 {(true, "cubic"): 0.20, (true, "softening"): 0.25, (rival, "cubic"): 0.27})
    model = fits.law(true, "softening", None)
    chosen = best_place(fits, _located(50.0), model, ["cubic"], [], None)
    # the rival's 0.15 mean NRMSE beats the softening's 0.17 here; by misfit the softening (0.25) beats it (0.27)
    assert chosen is model
    swapped = _Fits(fits.scores, {**fits.misfits, (rival, "cubic"): 0.24})
    assert best_place(swapped, _located(50.0), model, ["cubic"], [], None).joint.between == rival


def test_the_best_place_stays_where_no_next_place_simulates_better_or_none_is_near():
    fits = _Fits({(("acc1", "acc2"), "cubic"): 0.02, (("acc2", "acc3"), "cubic"): 0.03})
    model = fits.law(("acc1", "acc2"), "cubic", None)
    assert best_place(fits, _located(50.0), model, ["cubic"], ["softening"], None) is model
    assert fits.calls[1:] == [(("acc2", "acc3"), "cubic")]  # no law weighed at a place not kept
    far = _Fits({})
    assert best_place(far, _located(500.0), model, ["cubic"], ["softening"], None) is model and far.calls == []
    given = _Fits({(("acc2", "acc3"), "friction"): 0.01})  # a law given: the next place fitted with it, none weighed
    chosen = best_place(given, _located(50.0), model, ["friction"], [], None)
    assert chosen.joint.between == ("acc2", "acc3") and given.calls == [(("acc2", "acc3"), "friction")]


def test_places_down_to_the_fifth_are_simulated_where_near_and_none_beyond():
    places = [("acc1", "acc2"), ("acc2", "acc3"), ("acc1", "acc3"), ("acc1", "ground"), ("acc2", "ground"),
              ("acc3", "ground")]
    loc = JointLocation(("acc1", "acc2"), [{"between": list(p), "delta_bic": 10.0 * i, "law": "cubic"}
                                           for i, p in enumerate(places)],
                        "cubic", [{"law": "cubic", "delta_bic": 0.0}], [], [], "L1", [1.0, 8.0], evidence=1000.0)
    scores = {(p, "cubic"): 0.05 for p in places} | {(("acc1", "ground"), "cubic"): 0.01}
    fits = _Fits(scores)
    model = fits.law(("acc1", "acc2"), "cubic", None)
    chosen = best_place(fits, loc, model, ["cubic"], [], None)
    # a root's spring to the ground ranked fourth by the spectra (on independent wings) is found by simulation
    assert chosen.joint.between == ("acc1", "ground")
    assert [b for b, _ in fits.calls[1:]] == places[1:PLACES] and PLACES == 5  # the sixth is not simulated


def test_the_laws_tried_at_a_next_place_are_the_best_simulated_named_ones():
    fits = _Fits({(("acc1", "acc2"), w): x for w, x in (("sparse", 0.01), ("cubic", 0.04), ("friction", 0.02))})
    models = [fits.law(("acc1", "acc2"), w, None) for w in ("sparse", "cubic", "friction")]
    assert ranked_laws(models) == ["friction", "cubic", "sparse"]


def test_a_place_weighed_with_the_mode_shapes_inputs_is_not_simulated_against_the_next():
    """Where `locate_joint` weighed the places the spectra could not tell apart with each mode's input from the mode
    shapes (`choice.weighed`), the place stands: no next place is fitted (as first fitted, with free inputs, a pair
    around the true one fitted the levels of independent ground vibration tests better)."""
    fits = _Fits({(("acc1", "acc2"), "cubic"): 0.05, (("acc2", "acc3"), "cubic"): 0.01})
    model = fits.law(("acc1", "acc2"), "cubic", None)
    loc = _located(50.0)
    weighed = [{**e, "inputs": "reciprocal", "driving_point": "acc1", "spectra_delta_bic": d}
               for e, d in zip(loc.location[:2], (50.0, 0.0))]
    loc = JointLocation(loc.between, [*weighed, *loc.location[2:]], loc.law, loc.laws, [], [], "L1", [1.0, 8.0],
                        evidence=1000.0)
    assert loc.reciprocal and best_place(fits, loc, model, ["cubic"], ["softening"], None) is model
    assert fits.calls == [(("acc1", "acc2"), "cubic")]  # the located model's own fit, nothing after it


def test_a_place_the_mode_shapes_confirm_is_still_simulated_against_the_spectra_s_next():
    """Where the mode shapes' inputs keep the spectra's first place, the fits in time check it as before, the next
    places taken by their ΔBIC with free inputs (`spectra_delta_bic`), not the reciprocal one."""
    fits = _Fits({(("acc1", "acc2"), "cubic"): 0.05, (("acc2", "acc3"), "cubic"): 0.01})
    model = fits.law(("acc1", "acc2"), "cubic", None)
    loc = _located(50.0)
    weighed = [{**e, "inputs": "reciprocal", "driving_point": "acc1", "spectra_delta_bic": d, "delta_bic": r}
               for e, d, r in zip(loc.location[:2], (0.0, 50.0), (0.0, 3000.0))]
    loc = JointLocation(loc.between, [*weighed, *loc.location[2:]], loc.law, loc.laws, [], [], "L1", [1.0, 8.0],
                        evidence=1000.0)
    chosen = best_place(fits, loc, model, ["cubic"], [], None)
    assert chosen.joint.between == ("acc2", "acc3") and (("acc2", "acc3"), "cubic") in fits.calls

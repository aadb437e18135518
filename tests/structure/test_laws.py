"""The joint laws' terms (SPEC §11): each term's slopes are its value's derivatives, and the saturating spring
is what its name says."""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from satmd.structure.laws import HYSTERETIC, LAWS, SHAPE_GRID, TERM_CODES, play, slide, term


@settings(max_examples=200, deadline=None)
@given(code=st.sampled_from(sorted(set(TERM_CODES.values()) - set(HYSTERETIC))), d=st.floats(-3.0, 3.0), v=st.floats(-3.0, 3.0),
       aux=st.floats(0.05, 2.0))
def test_every_terms_slopes_are_its_derivatives(code, d, v, aux):
    """∂t/∂d and ∂t/∂v (the integrator's Newton step uses them) against central differences, away from kinks."""
    if code == 4 and abs(abs(d) - aux) < 1e-3 or code in (3, 6) and min(abs(d), abs(v)) < 1e-3:
        return  # a contact's edge, |d|'s and |v|'s kinks: one-sided slopes
    h = 1e-6
    _, td, tv = term(code, d, v, aux)
    fd = (term(code, d + h, v, aux)[0] - term(code, d - h, v, aux)[0]) / (2 * h)
    fv = (term(code, d, v + h, aux)[0] - term(code, d, v - h, aux)[0]) / (2 * h)
    assert abs(td - fd) <= 1e-5 * (1 + abs(fd)) and abs(tv - fv) <= 1e-5 * (1 + abs(fv))


def test_a_saturating_spring_is_linear_small_and_levels_off_large():
    """k_sat·d_sat·tanh(d/d_sat): slope 1 at rest, the force's limit d_sat, the cubic −d³/(3 d_sat²) between."""
    law = LAWS["softening"]
    assert law.term_names == ("tanh(d)",) and "tanh(d)" in SHAPE_GRID
    d_sat = 2e-4
    value, slope, _ = term(TERM_CODES["tanh(d)"], np.array([0.0, 1e-7, 1e-2]), 0.0, d_sat)
    assert slope[0] == 1.0 and abs(value[1] - 1e-7) < 1e-6 * 1e-7 and abs(value[2] - d_sat) < 1e-12
    d = 2e-5  # a tenth of the stroke: the Taylor series to its second term, within its third
    assert abs(term(9, d, 0.0, d_sat)[0] - (d - d ** 3 / (3 * d_sat ** 2))) <= (2 / 15) * 1.01 * d ** 5 / d_sat ** 4  # the next term
    assert law.formula([3e4, 1e3, 0.5], [d_sat, 1.0, 1.0]).startswith("3e+04·0.0002·tanh(d/0.0002)")
    assert law.shapes(1e-4, 1.0)[-1][0] == SHAPE_GRID["tanh(d)"][-1] * 1e-4  # strokes on the lowest level's scale


def test_the_best_fitting_law_is_kept_and_the_sparse_library_only_by_a_margin():
    """`best_fitting`: the model that simulates the recordings best; a sparse law's extra terms must earn their keep."""
    from types import SimpleNamespace

    from satmd.structure.choice import SPARSE_MARGIN, best_fitting

    def model(law, nrmse):
        return SimpleNamespace(joint=SimpleNamespace(law=law, units="relative", parameters=dict),
                               fit={"nonlinear": [[nrmse, nrmse], [nrmse, nrmse]]})

    clearance, friction = model("clearance", 0.32), model("friction", 0.26)
    assert best_fitting([clearance, friction]) is friction
    close = model("sparse", 0.26 * (1 - SPARSE_MARGIN / 2))
    assert best_fitting([close, clearance, friction]) is friction
    far = model("sparse", 0.26 * (1 - 2 * SPARSE_MARGIN))
    assert best_fitting([far, clearance, friction]) is far
    none = SimpleNamespace(joint=None, fit={"nonlinear": [[0.1]]})
    assert best_fitting([none, clearance]) is clearance and best_fitting([none]) is none



def test_the_sparse_library_is_weighed_against_the_best_named_law_once_both_are_finished():
    """`_Fit.finished_choice`: first fitted, the library's extra terms take up what a named law's start path
    leaves; finished, the named law may fit far better, and then it is kept. A library that still wins by the
    margin, or a law given, is kept as it is."""
    from types import SimpleNamespace

    from satmd.structure.choice import SPARSE_MARGIN
    from satmd.structure.fit import _Fit

    def model(law, nrmse, between=("acc1", "ground")):
        return SimpleNamespace(joint=SimpleNamespace(law=law, units="relative", parameters=dict, between=between),
                               fit={"nonlinear": [[nrmse]]})

    def fit_with(tried, finished):
        fit = _Fit.__new__(_Fit)
        fit.tried, fit.say = tried, lambda _: None
        fit.finished = lambda m, free_path, files: finished[id(m)]
        return fit

    sparse, clearance, cubic = model("sparse", 0.133), model("clearance", 0.150), model("cubic", 0.19)
    elsewhere = model("friction", 0.05, between=("acc2", "acc3"))
    done = {id(sparse): model("sparse", 0.121), id(clearance): model("clearance", 0.041),
            id(cubic): model("cubic", 0.03), id(elsewhere): model("friction", 0.01)}
    chosen = fit_with([sparse, clearance, cubic, elsewhere], done).finished_choice(sparse, True, [])
    assert chosen is done[id(clearance)]  # the best named at the place as first fitted, not the best finished
    done[id(sparse)] = model("sparse", 0.041 * (1 - 2 * SPARSE_MARGIN))
    assert fit_with([sparse, clearance], done).finished_choice(sparse, True, []) is done[id(sparse)]
    assert fit_with([sparse, elsewhere], done).finished_choice(sparse, True, []) is done[id(sparse)]
    assert fit_with([sparse, clearance], done).finished_choice(clearance, True, []) is done[id(clearance)]


def test_named_laws_close_to_the_chosen_one_as_first_fitted_are_finished_and_weighed_too():
    """`close_rivals`: first fits follow the start's path, which suits some laws better (an independent wing's
    stick-slip joint: cubic 0.032, softening 0.034, friction 0.036 first fitted; finished, friction 0.011 against
    0.016). Laws within `FINISH_MARGIN` at the same place, not contradicting their names, are finished too."""
    from types import SimpleNamespace

    from satmd.structure.choice import FINISH_MARGIN, FINISHED_RIVALS, close_rivals
    from satmd.structure.fit import _Fit

    def model(law, nrmse, between=("acc4", "acc6"), sign=1.0):
        values = {"k_stick": sign, "f_slip": sign, "k_sat": sign}
        return SimpleNamespace(joint=SimpleNamespace(law=law, units="N", parameters=lambda: values, between=between),
                               fit={"nonlinear": [[nrmse]]})

    cubic, softening, friction = model("cubic", 0.032), model("softening", 0.034), model("friction", 0.036)
    damping = model("quadratic_damping", 0.032 * (1 + 2 * FINISH_MARGIN))
    backwards = model("friction", 0.033, sign=-1.0)  # a friction that feeds energy: not friction
    elsewhere = model("softening", 0.01, between=("acc5", "acc6"))
    tried = [cubic, damping, friction, backwards, softening, elsewhere]
    assert close_rivals(cubic, tried) == [softening, friction]
    assert len(close_rivals(cubic, [*tried, model("clearance", 0.0321)])) == FINISHED_RIVALS
    assert close_rivals(model("sparse", 0.02), tried) == [cubic]  # the library: the best named law, however far
    assert close_rivals(SimpleNamespace(joint=None), tried) == []

    fit = _Fit.__new__(_Fit)
    fit.tried, fit.say = tried, lambda _: None
    done = {id(cubic): model("cubic", 0.016), id(softening): model("softening", 0.018),
            id(friction): model("friction", 0.011)}
    fit.finished = lambda m, free_path, files: done[id(m)]
    assert fit.finished_choice(cubic, True, []) is done[id(friction)]
    done[id(friction)] = model("friction", 0.02)
    assert fit.finished_choice(cubic, True, []) is done[id(cubic)]

def _two_modes(kappa_scale):
    """A mass-normalised two-mode structure (channels a, b; the force at a) with a joint from b to the ground whose
    path is ``kappa_scale`` times reciprocity's, and that path's law fitted in relative units."""
    from types import SimpleNamespace

    from satmd.structure.linear import LinearStructure

    w, zeta = 2 * np.pi * np.array([5.0, 12.0]), 0.02
    phi = np.array([[1.0, 0.6], [0.8, -1.1]])  # rows: channels a, b; columns: modes
    wd = w * np.sqrt(1 - zeta ** 2)
    lam = -zeta * w + 1j * wd
    residues = lam ** 2 * phi * phi[0] / (2j * wd)  # accelerance residues of a force at a
    lin = LinearStructure(("a", "b"), lam, residues, np.zeros(2))
    kappa = kappa_scale * -lin.coupling("b", "ground", "a")
    return SimpleNamespace(linear=lin, reference=lin, driving_point=None,
                           joint=SimpleNamespace(between=("b", "ground"), coupling=kappa,
                                                 stroke_of=lambda linear: linear.pair_residues("b", "ground")))


def test_the_path_gives_a_relative_coefficient_its_sign_where_the_modes_shapes_agree():
    """`path_sign`: the sign of the path's scale onto reciprocity's where they point the same way mode by mode (a
    path off in size, as fitted paths are, keeps its sign); none where they are unrelated or the point unknown."""
    from satmd.structure import Joint, LinearStructure, StructureModel
    from satmd.structure.newtons import in_newtons, path_scale, path_sign

    for scale in (3.0, -0.4):
        m = _two_modes(scale)
        d, s, misfit, agreement = path_scale(m)
        assert d == "a" and abs(s - scale) < 1e-9 * abs(scale) and misfit < 1e-9 and abs(agreement) > 1 - 1e-9
        assert path_sign(m) == (1 if scale > 0 else -1)
    m = _two_modes(1.0)
    m.joint.coupling = m.joint.coupling * np.array([2.5, 0.4])  # each mode off in size by a factor: the sign holds
    assert path_scale(m)[2] > 0.3 and path_sign(m) == 1
    lin, phys = m.linear, -m.linear.coupling("b", "ground", "a")
    w = np.abs(lin.residues[0] / lin.poles ** 2) * np.abs(phys) ** 2
    m.joint.coupling = phys * np.array([1.0, -w[0] / w[1]])  # one mode against the shapes as much as the other for
    assert abs(path_scale(m)[3]) < 1e-9 and path_sign(m) == 0  # them: unrelated, no sign
    lin = m.linear
    m.reference = m.linear = LinearStructure(lin.channels, lin.poles, -lin.residues, lin.feedthrough)
    assert path_scale(m) is None and path_sign(m) == 0  # no channel has a driving point's signs
    two = _two_modes(2.0)  # in newtons: the same simulation, the scale moved into the coefficients
    joint = Joint(("b", "ground"), "cubic", np.array([1.0, -3.0, 0.1]), np.ones(3), two.joint.coupling)
    n = in_newtons(StructureModel(two.linear, joint, (1.0, 2.0), reference=two.linear))
    assert n.joint.units == "N" and n.driving_point == "a" and np.allclose(n.joint.coefficients, [2.0, -6.0, 0.2])
    assert np.allclose(n.joint.coupling * n.joint.coefficients[0], joint.coupling * joint.coefficients[0])


def test_the_joint_own_path_gives_its_sign_without_a_driving_point():
    """`newtons.passive_sign`: a force at the pair moves its stroke as a driving point's force moves that point,
    every mode's receptance constant of one sign; a path reversed (a negative scale) reverses them all. Modes that
    cancel give no sign. With no channel at the driving point, `contradicts` reads a relative law's sign so: a
    quadratic damping on a reversed path feeds the structure (on an independent chain it ran away at 1.5 times
    the fitted level)."""
    from types import SimpleNamespace

    from satmd.structure.choice import contradicts
    from satmd.structure.linear import LinearStructure
    from satmd.structure.newtons import passive_sign, path_sign

    for scale in (0.3, 2.0, -0.5, -4.0):
        assert passive_sign(_two_modes(scale)) == (1 if scale > 0 else -1)
    m = _two_modes(1.0)
    lin = m.linear
    R = lin.pair_residues("b", "ground") * m.joint.coupling
    const = (2j * np.abs(lin.poles) * R / lin.poles ** 2).real
    m.joint.coupling = m.joint.coupling * np.array([1.0, -const[0] / const[1]])  # the modes cancel: no sign
    assert passive_sign(m) == 0
    for scale, feeds in ((2.0, False), (-2.0, True)):
        m = _two_modes(scale)
        res = m.linear.residues.copy()
        res[0, 1] *= -1  # channel a's constants of both signs: no driving point
        m.linear = m.reference = LinearStructure(m.linear.channels, m.linear.poles, res, m.linear.feedthrough)
        vars(m.joint).update(law="quadratic_damping", units="relative", parameters=lambda: {"c2": 1.0})
        assert path_sign(m) == 0 and passive_sign(m) == (-1 if feeds else 1)
        assert contradicts(SimpleNamespace(**vars(m))) is feeds


def test_a_saturating_spring_that_stiffens_is_no_softening():
    """In newtons, or in relative units with the path's sign known, a negative k_sat is a spring that stiffens with
    the stroke: not the law its name says; a friction or a quadratic damping of negative sign feeds energy in."""
    from types import SimpleNamespace

    from satmd.structure.choice import best_fitting

    def model(law, nrmse, units="N", sign=None, **par):
        joint = SimpleNamespace(law=law, units=units, parameters=lambda: par)
        if sign is None:
            return SimpleNamespace(joint=joint, fit={"nonlinear": [[nrmse]]}, driving_point=None, reference=None,
                                   linear=None)
        out = _two_modes(sign)
        vars(out.joint).update(vars(joint))
        out.fit = {"nonlinear": [[nrmse]]}
        return out

    cubic = model("cubic", 0.020)
    assert best_fitting([model("softening", 0.019, k_sat=-2e4), cubic]) is cubic
    soft = model("softening", 0.019, k_sat=2e4)
    assert best_fitting([soft, cubic]) is soft
    stiffening = model("softening", 0.019, units="relative", sign=2.0, k_sat=-3.0)
    assert best_fitting([stiffening, cubic]) is cubic
    flipped = model("softening", 0.019, units="relative", sign=-2.0, k_sat=-3.0)  # in newtons +6: it softens
    assert best_fitting([flipped, cubic]) is flipped
    unknown = model("softening", 0.019, units="relative", sign=1.0, k_sat=-3.0)
    w = np.abs(unknown.linear.residues[0] / unknown.linear.poles ** 2) * np.abs(unknown.joint.coupling) ** 2
    unknown.joint.coupling = unknown.joint.coupling * np.array([1.0, -w[0] / w[1]])  # the path's sign unknown: kept
    assert best_fitting([unknown, cubic]) is unknown
    for law, key in (("friction", "k_stick"), ("friction", "f_slip"), ("quadratic_damping", "c2")):
        assert best_fitting([model(law, 0.019, **{key: -1.0}), cubic]) is cubic
        assert best_fitting([model(law, 0.019, **{key: 1.0}), cubic]).joint.law == law


def test_a_clearance_whose_contact_gives_way_is_no_clearance():
    """In newtons a negative contact stiffness softens beyond the gap: a clearance only closes (SPEC §11)."""
    from types import SimpleNamespace

    from satmd.structure.choice import best_fitting

    def model(law, nrmse, **par):
        joint = SimpleNamespace(law=law, units="N", parameters=lambda: par)
        return SimpleNamespace(joint=joint, fit={"nonlinear": [[nrmse]]})

    soft = model("softening", 0.30, k_sat=3e4)
    assert best_fitting([model("clearance", 0.25, k_contact=-5e4, gap=1e-4), soft]) is soft
    closing = model("clearance", 0.25, k_contact=5e4, gap=1e-4)
    assert best_fitting([closing, soft]) is closing


def _bouc_wen(r0, d):
    """A stick-slip contact's state along the stroke ``d`` (in stick strokes), integrated finely: r' = (1 − (½ sign(d'r)
    + ½) r²) d' (Bouc–Wen, n = 2, β = γ = ½)."""
    from scipy.integrate import solve_ivp

    s = np.arange(d.size, dtype=float)

    def rhs(t, y):
        rate = d[min(int(t) + 1, d.size - 1)] - d[min(int(t), d.size - 1)]
        return [(1 - (0.5 * np.sign(rate * y[0]) + 0.5) * y[0] ** 2) * rate]

    return solve_ivp(rhs, (0.0, s[-1]), [r0], t_eval=s, max_step=0.05, rtol=1e-10, atol=1e-12).y[0]


@settings(max_examples=60, deadline=None)
@given(r0=st.floats(-0.99, 0.99), u=st.floats(-4.0, 4.0))
def test_a_stick_slip_step_is_the_bouc_wen_element_and_its_slope(r0, u):
    """`slide` over a monotone stroke: the element's ODE to 1e-7, its slope the central difference, |r| < 1."""
    r, slope = slide(r0, u)
    assert abs(r - _bouc_wen(r0, np.array([0.0, u]))[-1]) < 1e-7 and abs(r) < 1.0
    if abs(u) > 1e-4 and (abs(r0 + u) > 1e-4 or r0 * u >= 0):  # away from the kinks: a reversal, zero crossed
        h = 1e-6
        assert abs(slope - (slide(r0, u + h)[0] - slide(r0, u - h)[0]) / (2 * h)) < 1e-5


def test_a_stick_slip_contact_sticks_small_slides_large_and_plays_periodically():
    """Over a period of stroke: stiff at reversals (slope 1 in stick strokes), its force at most the slip force,
    a loop that holds energy; `play`'s steady state starts where it ends and is the ODE's after many periods."""
    t = np.linspace(0.0, 1.0, 400, endpoint=False)
    d = 3.0 * np.sin(2 * np.pi * t) + 0.8 * np.sin(6 * np.pi * t + 0.4)  # in stick strokes
    r = play(d, 1.0)
    assert np.max(np.abs(r)) < 1.0 and np.max(np.abs(r)) > 0.95  # it slides, at the slip force
    assert abs(slide(r[-1], d[0] - d[-1])[0] - r[0]) < 1e-10  # periodic
    loop = np.sum(r * np.gradient(d))  # ∮ r dd: the energy a period dissipates, > 0
    assert loop > 0.5
    many = _bouc_wen(0.0, np.tile(d, 6))[-d.size:]
    assert np.max(np.abs(many - r)) < 1e-4
    small = play(0.01 * d, 1.0)  # a small stroke sticks: the spring, slope 1
    assert np.allclose(small - small.mean(), 0.01 * d - np.mean(0.01 * d), atol=2e-4)


def test_friction_is_tried_in_both_of_its_forms():
    """A friction is a stick-slip contact (its first form) or a memoryless Coulomb force; both are one law."""
    friction = LAWS["friction"]
    forms = [v.term_names for v in friction.variants()]
    assert forms == [("slip(d)",), ("sign(v)",)] and all(v.name == "friction" for v in friction.variants())
    assert friction.form(("sign(v)",)).all_terms == ("sign(v)", "d", "v") and friction.form(()) is friction
    assert [v.term_names for v in LAWS["cubic"].variants()] == [("d³",)]
    import pytest

    from satmd.errors import DataError

    with pytest.raises(DataError, match="no form with the terms d³"):
        friction.form(("d³",))

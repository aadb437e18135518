"""The joint laws' terms (SPEC §11): each term's slopes are its value's derivatives, and the saturating spring
is what its name says."""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from satmd.structure.laws import LAWS, SHAPE_GRID, TERM_CODES, term


@settings(max_examples=200, deadline=None)
@given(code=st.sampled_from(sorted(TERM_CODES.values())), d=st.floats(-3.0, 3.0), v=st.floats(-3.0, 3.0),
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

    from satmd.structure.fit import SPARSE_MARGIN, best_fitting

    def model(law, nrmse):
        return SimpleNamespace(joint=SimpleNamespace(law=law, units="relative"), fit={"nonlinear": [[nrmse, nrmse], [nrmse, nrmse]]})

    clearance, friction = model("clearance", 0.32), model("friction", 0.26)
    assert best_fitting([clearance, friction]) is friction
    close = model("sparse", 0.26 * (1 - SPARSE_MARGIN / 2))
    assert best_fitting([close, clearance, friction]) is friction
    far = model("sparse", 0.26 * (1 - 2 * SPARSE_MARGIN))
    assert best_fitting([far, clearance, friction]) is far
    none = SimpleNamespace(joint=None, fit={"nonlinear": [[0.1]]})
    assert best_fitting([none, clearance]) is clearance and best_fitting([none]) is none


def test_a_saturating_spring_that_stiffens_is_no_softening():
    """In newtons a negative k_sat is a spring that stiffens with the stroke: not the law its name says."""
    from types import SimpleNamespace

    from satmd.structure.fit import best_fitting

    def model(law, nrmse, k_sat=None, units="N"):
        joint = SimpleNamespace(law=law, units=units, parameters=lambda: {} if k_sat is None else {"k_sat": k_sat})
        return SimpleNamespace(joint=joint, fit={"nonlinear": [[nrmse]]})

    cubic = model("cubic", 0.020)
    assert best_fitting([model("softening", 0.019, k_sat=-2e4), cubic]) is cubic
    soft = model("softening", 0.019, k_sat=2e4)
    assert best_fitting([soft, cubic]) is soft
    relative = model("softening", 0.019, k_sat=-2e4, units="relative")  # the path's sign leaves k_sat's open
    assert best_fitting([relative, cubic]) is relative


def test_a_clearance_whose_contact_gives_way_is_no_clearance():
    """In newtons a negative contact stiffness softens beyond the gap: a clearance only closes (SPEC §11)."""
    from types import SimpleNamespace

    from satmd.structure.fit import best_fitting

    def model(law, nrmse, **par):
        joint = SimpleNamespace(law=law, units="N", parameters=lambda: par)
        return SimpleNamespace(joint=joint, fit={"nonlinear": [[nrmse]]})

    soft = model("softening", 0.30, k_sat=3e4)
    assert best_fitting([model("clearance", 0.25, k_contact=-5e4, gap=1e-4), soft]) is soft
    closing = model("clearance", 0.25, k_contact=5e4, gap=1e-4)
    assert best_fitting([closing, soft]) is closing

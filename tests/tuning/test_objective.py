"""H∞ is the true peak (not a grid sample); H2 resolves the sharpest peak."""
import numpy as np
import pytest

from satmd import DataError, Rig
from satmd.tuning.objective import Objective, magnitude


def dense_hinf(rig, band, n=400_001):
    f = np.linspace(*band, n)
    return magnitude(f, rig, (), "u1").max()


@pytest.mark.parametrize("R", [0.5, 22.0, 300.0])
def test_hinf_is_the_true_peak(R):
    rig = Rig(R=R)
    band = (40.0, 130.0)
    value = Objective("hinf", "u1", band)(rig)[0]
    assert value >= dense_hinf(rig, band) * (1 - 1e-9)  # never below any sample
    assert value == pytest.approx(dense_hinf(rig, band), rel=1e-6)


def test_hinf_finds_a_peak_sharper_than_the_grid():
    rig = Rig(R=0.1, c1=0.0, cp=0.0)  # electrical resonance damped by 0.1 Ω only
    obj = Objective("hinf", "u1", (20.0, 200.0), rel_step=0.01)
    _, fpk, vpk = obj.evaluate(rig)
    f = fpk[0, np.argmax(vpk[0])]
    fine = np.linspace(f * (1 - 1e-5), f * (1 + 1e-5), 20001)
    assert vpk[0].max() == pytest.approx(magnitude(fine, rig, (), "u1").max(), rel=1e-4)
    assert vpk[0].max() > 10 * magnitude(obj.grid, rig, (), "u1").max()


def test_h2_matches_dense_quadrature_for_sharp_and_broad_peaks():
    band = (20.0, 200.0)
    for rig in (Rig(), Rig(R=1.0, c1=0.5, cp=0.1)):
        f = np.linspace(*band, 400_001)
        m = magnitude(f, rig, (), "u1")
        exact = np.sqrt(np.trapezoid(m**2, f) / (band[1] - band[0]))
        assert Objective("h2", "u1", band)(rig)[0] == pytest.approx(exact, rel=1e-3)


def test_batches_agree_with_single_rigs_and_a1_is_omega_squared_u1():
    R = np.array([5.0, 40.0, 400.0])
    obj = Objective("hinf", "u1", (20.0, 200.0))
    batch = obj(Rig(R=R))
    assert batch == pytest.approx([obj(Rig(R=r))[0] for r in R], rel=1e-12)
    h2a = Objective("h2", "a1", (20.0, 200.0))(Rig(R=R))
    assert np.all(h2a > 0) and h2a.shape == (3,)


@pytest.mark.parametrize("kw", [dict(kind="peak"), dict(output="u2"), dict(band=(0, 10)), dict(band=(50, 40)),
                                dict(band=(1, np.inf)), dict(band="x")])
def test_bad_objective_is_refused(kw):
    args = dict(kind="hinf", output="u1", band=(20, 200))
    args.update(kw)
    with pytest.raises(DataError):
        Objective(**args)

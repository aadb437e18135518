import numpy as np
import pytest

from satmd.explain import agreement, chain_rule_check, physical_sensitivity
from satmd.explain.attributions import per_frequency
from satmd.physics import PAPER_GRID_HZ, Rig

from .conftest import simulate


def test_jacobian_matches_finite_differences_of_the_features():
    rig = Rig(R=np.array([8.0, 35.0]), L=np.array([0.032, 0.192]))
    ps = physical_sensitivity(rig, PAPER_GRID_HZ)
    assert ps.curves.shape == (2, 2, 60)
    assert ps.jacobian.shape == (2, 240, 2)
    np.testing.assert_allclose(ps.curves.max(axis=-1), 1.0)
    for i, (R, L) in enumerate([(8.0, 0.032), (35.0, 0.192)]):
        hR, hL = 1e-5 * R, 1e-5 * L
        dR = (simulate([R + hR], [L]) - simulate([R - hR], [L]))[0] / (2 * hR)
        dL = (simulate([R], [L + hL]) - simulate([R], [L - hL]))[0] / (2 * hL)
        scale = np.abs(ps.jacobian[i]).max(axis=0)
        np.testing.assert_allclose(ps.jacobian[i, :, 0], dR, atol=1e-5 * scale[0])
        np.testing.assert_allclose(ps.jacobian[i, :, 1], dL, atol=1e-5 * scale[1])
        # the curves are |∂A/∂θ| summed over Re/Im of both channels, max-normalised
        c = per_frequency(dR, 60)
        np.testing.assert_allclose(ps.curves[i, 0], c / c.max(), atol=1e-4)


def test_agreement_measures():
    rng = np.random.default_rng(0)
    a = rng.uniform(0, 1, (3, 2, 60))
    rows = agreement(a, a)
    assert len(rows) == 3
    for r in rows:
        for k in ("cosine_R", "cosine_L", "spearman_R", "spearman_L"):
            assert r[k] == pytest.approx(1.0)
    rows = agreement(a, 1.0 - a)
    assert all(r["spearman_R"] == pytest.approx(-1.0) for r in rows)


def test_chain_rule_identity_for_an_exact_linear_inverse():
    rng = np.random.default_rng(1)
    J = rng.normal(size=(4, 240, 2))
    span = np.array([103.0, 0.5])
    G = np.linalg.pinv(J) / span[None, :, None]  # gradient of normalised outputs
    C = chain_rule_check(G, J, span)
    np.testing.assert_allclose(C, np.broadcast_to(np.eye(2), (4, 2, 2)), atol=1e-10)

"""Analytic Jacobians (forward-mode duals + closed-form solve) against central
differences, for every rig parameter and every effect parameter, single and batched."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from satmd.physics import CHANNELS, OFFSET_PARAMETERS, PAPER_GRID_HZ, Rig, effect, frf
from satmd.physics.model import parameter_names

# Central differences with one Richardson step, (4 D(h) - D(2h)) / 3: truncation O(h^4), so a
# relative step of 1e-4 keeps both truncation and round-off of the reference near 1e-8 of the
# column's maximum (a plain central difference with h = 1e-6 |x| has round-off up to 3e-5 for
# weak derivatives such as extra_mode.zeta, whose reference therefore takes a larger step).
REL_STEP = 1e-4
REL_STEP_FOR = {"extra_mode.zeta": 1e-3, "zeta": 1e-3}
TOL = 1e-6
FREQ = np.concatenate([[3.0, 20.0], PAPER_GRID_HZ[::3], [66.5, 250.0]])


def all_effects(f3=66.0, mu=0.01):
    return [
        effect("sensor_gain", gain_a1=1.05, gain_a2=0.97),
        effect("time_delay", tau_s=1e-4),
        effect("structural_damping", eta=0.02),
        effect("dielectric_loss", tan_delta=0.03),
        effect("shunt_capacitance", Cs=2e-6),
        effect("extra_mode", f_hz=f3, zeta=0.01, mass_ratio=mu),
    ]


def _locate(effects, name):
    """Index and parameter of an effect parameter: qualified ('extra_mode.f_hz') or bare ('tau_s')."""
    hits = [(i, p) for i, e in enumerate(effects) for p in e.parameter_names if name in (f"{e.name}.{p}", p)]
    assert len(hits) == 1, name
    return hits[0]


def _perturbed(rig, effects, name, delta):
    """(rig, effects) with parameter ``name`` moved by ``delta`` (array or scalar)."""
    if name in Rig.names():
        return rig.replace(**{name: np.asarray(getattr(rig, name), float) + delta}), effects
    i, p = _locate(effects, name)
    out = list(effects)
    out[i] = out[i].replace(**{p: np.asarray(out[i].params[p], float) + delta})
    return rig, out


def _value(rig, effects, name):
    if name in Rig.names():
        return np.asarray(getattr(rig, name), float)
    i, p = _locate(effects, name)
    return np.asarray(effects[i].params[p], float)


def _central(freq, rig, effects, name, h, outputs):
    hi = frf(freq, *_perturbed(rig, effects, name, h), outputs=outputs)
    lo = frf(freq, *_perturbed(rig, effects, name, -h), outputs=outputs)
    hh = np.asarray(2 * h)[..., None] if np.ndim(h) else 2 * h
    return {ch: (getattr(hi, ch) - getattr(lo, ch)) / hh for ch in outputs}


def central_differences(freq, rig, effects, name, outputs=CHANNELS):
    h = REL_STEP_FOR.get(name, REL_STEP) * np.abs(_value(rig, effects, name))
    d1 = _central(freq, rig, effects, name, h, outputs)
    d2 = _central(freq, rig, effects, name, 2 * h, outputs)
    return {ch: (4 * d1[ch] - d2[ch]) / 3 for ch in outputs}


def assert_jacobian_matches(freq, rig, effects, wrt, outputs=CHANNELS):
    res = frf(freq, rig, effects, wrt=wrt, outputs=outputs)
    plain = frf(freq, rig, effects, outputs=outputs)
    for ch in outputs:
        want = getattr(plain, ch)
        np.testing.assert_allclose(getattr(res, ch), want, rtol=1e-13, atol=1e-14 * np.max(np.abs(want)))
        assert res.jac[ch].shape == getattr(plain, ch).shape + (len(wrt),)
    for j, name in enumerate(wrt):
        fd = central_differences(freq, rig, effects, name, outputs)
        for ch in outputs:
            got = res.jac[ch][..., j]
            scale = np.max(np.abs(fd[ch]), axis=-1, keepdims=True)
            err = np.abs(got - fd[ch])
            assert np.all(err <= TOL * scale), (
                f"d{ch}/d{name}: max error {np.max(err / np.maximum(scale, 1e-300)):.2e} of the column's max")


m2s = st.floats(0.3, 0.8)
kps = st.floats(5e4, 2e5)
Rs = st.floats(1.0, 100.0)
Ls = st.floats(0.01, 0.5)


@settings(max_examples=20, deadline=None)
@given(m2=m2s, kp=kps, R=Rs, L=Ls)
def test_rig_jacobian_matches_central_differences(m2, kp, R, L):
    rig = Rig(m2=m2, kp=kp, R=R, L=L)
    assert_jacobian_matches(FREQ, rig, (), list(Rig.names()))


@settings(max_examples=15, deadline=None)
@given(m2=m2s, kp=kps, R=Rs, L=Ls, f3=st.floats(20.0, 300.0), mu=st.floats(1e-3, 0.1))
def test_jacobian_with_every_effect_matches_central_differences(m2, kp, R, L, f3, mu):
    rig = Rig(m2=m2, kp=kp, R=R, L=L)
    effects = all_effects(f3, mu)
    names = parameter_names(rig, effects)
    assert "extra_mode.f_hz" in names and "time_delay.tau_s" in names
    assert len(names) == len(Rig.names()) + 9
    assert_jacobian_matches(FREQ, rig, effects, names)


@pytest.mark.parametrize("p", OFFSET_PARAMETERS)
def test_parameter_offset_jacobian(p):
    rig = Rig()
    effects = [effect(f"parameter_offset:{p}", value=1.2 * getattr(rig, p)), effect("structural_damping", eta=0.02),
               effect("dielectric_loss", tan_delta=0.03)]
    name = f"parameter_offset:{p}.value"
    assert_jacobian_matches(FREQ, rig, effects, [name, p, "R", "L"])
    # the offset replaces the rig's own value: its derivative is zero
    res = frf(FREQ, rig, effects, wrt=[p])
    for ch in CHANNELS:
        np.testing.assert_array_equal(res.jac[ch], 0.0)


def test_jacobian_at_the_bounds_of_validity():
    """Low frequency, zero damping and a vanishing mode mass still differentiate."""
    rig = Rig(c1=0.3, cp=0.5, R=2.0)
    effects = [effect("extra_mode", f_hz=45.0, zeta=0.05, mass_ratio=1e-3)]
    assert_jacobian_matches(np.array([0.7, 10.0, 44.0, 46.0, 120.0]), rig, effects,
                            ["m2", "kp", "R", "L", "c1", "extra_mode.f_hz", "extra_mode.zeta",
                             "extra_mode.mass_ratio"])


def test_batched_jacobian_matches_central_differences_and_single_calls():
    rng = np.random.default_rng(3)
    n = 6
    rig = Rig(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n), R=rng.uniform(1, 100, n),
              L=rng.uniform(0.01, 0.5, n))
    effects = [effect("extra_mode", f_hz=rng.uniform(30, 150, n), zeta=0.02, mass_ratio=0.02),
               effect("time_delay", tau_s=5e-5), effect("sensor_gain", gain_a1=1.1, gain_a2=0.9)]
    wrt = ["m2", "kp", "R", "L", "k1", "extra_mode.f_hz", "extra_mode.mass_ratio", "tau_s", "gain_a2"]
    assert_jacobian_matches(FREQ, rig, effects, wrt)
    batch = frf(FREQ, rig, effects, wrt=wrt)
    for i in range(n):
        ri = Rig(m2=rig.m2[i], kp=rig.kp[i], R=rig.R[i], L=rig.L[i])
        ei = [effects[0].replace(f_hz=effects[0].f_hz[i])] + effects[1:]
        single = frf(FREQ, ri, ei, wrt=wrt)
        for ch in CHANNELS:
            np.testing.assert_allclose(batch.jac[ch][i], single.jac[ch], rtol=1e-13, atol=0)


def test_broadcast_2d_jacobian_shapes():
    R = np.array([5.0, 30.0])[:, None]
    L = np.array([0.02, 0.1, 0.3])
    res = frf(FREQ, Rig(R=R, L=L), wrt=["R", "L"], outputs=("a1", "a2"))
    assert res.a1.shape == (2, 3, FREQ.size)
    assert res.jac["a1"].shape == (2, 3, FREQ.size, 2)
    assert set(res.jac) == {"a1", "a2"}
    assert_jacobian_matches(FREQ, Rig(R=R, L=L), (), ["R", "L"], outputs=("a1", "q"))


def test_large_threaded_batch_jacobian_equals_serial():
    rng = np.random.default_rng(4)
    n = 2000
    rig = Rig(m2=rng.uniform(0.3, 0.8, n), kp=rng.uniform(5e4, 2e5, n), R=rng.uniform(1, 100, n),
              L=rng.uniform(0.01, 0.5, n))
    wrt = ["m2", "kp", "R", "L"]
    a = frf(PAPER_GRID_HZ, rig, wrt=wrt, outputs=("a1", "a2"))
    b = frf(PAPER_GRID_HZ, rig, wrt=wrt, outputs=("a1", "a2"), threads=1)
    for ch in ("a1", "a2"):
        np.testing.assert_array_equal(a.jac[ch], b.jac[ch])
    for i in rng.choice(n, 4, replace=False):
        single = frf(PAPER_GRID_HZ, Rig(m2=rig.m2[i], kp=rig.kp[i], R=rig.R[i], L=rig.L[i]), wrt=wrt,
                     outputs=("a1", "a2"))
        np.testing.assert_allclose(a.jac["a1"][i], single.jac["a1"], rtol=1e-13, atol=0)


def test_outputs_subset_gives_the_same_columns():
    effects = all_effects()
    wrt = ["m2", "L", "extra_mode.f_hz", "dielectric_loss.tan_delta"]
    full = frf(FREQ, Rig(), effects, wrt=wrt)
    part = frf(FREQ, Rig(), effects, wrt=wrt[::-1], outputs=("a2", "q"))
    for ch in ("a2", "q"):
        np.testing.assert_array_equal(part.jac[ch], full.jac[ch][..., ::-1])


def test_parameter_names_resolve():
    effects = [effect("time_delay", tau_s=1e-4), effect("extra_mode", f_hz=66.0, mass_ratio=0.01)]
    a = frf(FREQ, Rig(), effects, wrt=["tau_s", "f_hz"])
    b = frf(FREQ, Rig(), effects, wrt=["time_delay.tau_s", "extra_mode.f_hz"])
    np.testing.assert_array_equal(a.jac["a1"], b.jac["a1"])
    with pytest.raises(ValueError, match="no parameter"):
        frf(FREQ, Rig(), effects, wrt=["nope"])
    with pytest.raises(ValueError, match="no parameter"):
        frf(FREQ, Rig(), (), wrt=["extra_mode.f_hz"])
    two = [effect("parameter_offset:k1", value=2e5), effect("parameter_offset:m1", value=0.9)]
    with pytest.raises(ValueError, match="ambiguous"):
        frf(FREQ, Rig(), two, wrt=["value"])

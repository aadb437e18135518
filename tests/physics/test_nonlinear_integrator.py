"""Exact checks of the one time-domain integrator (issue 27 item 2).

- linear steady state against the FRF model (SPEC §2) on a periodic multisine;
- Duffing backbone of a free undamped single-DOF (the host on its cubic spring, absorber and shunt
  decoupled): first-order ω0 √(1 + ¾ (k3/k) a²) at small amplitude, the exact elliptic form
  π √(α + β a²) / (2 K(m)), m = β a² / (2 (α + β a²)), at large amplitude;
- energy balance: input work = dissipated + change of stored energy;
- segments (the fast path) against one exact pass; odd symmetry; zero strength is the linear model.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.special import ellipk

from satmd.errors import DataError
from satmd.physics import Rig, frf
from satmd.physics.nonlinear import element, integrate
from satmd.physics.nonlinear.integrate import band_limited


def _random_force(seconds, fs, seed=0, band=(20.0, 200.0)):
    n = int(seconds * fs)
    rng = np.random.default_rng(seed)
    x = np.fft.rfft(rng.standard_normal(4 * n))
    f = np.fft.rfftfreq(4 * n, 1 / fs)
    x[(f < band[0]) | (f > band[1])] = 0
    F = np.fft.irfft(x, 4 * n)[:n]
    return F / F.std()


def test_linear_steady_state_matches_frf():
    fs, T, reps = 2048.0, 2.0, 8
    n = int(T * fs)
    t = np.arange(n * reps) / fs
    freqs = np.array([30.5, 50.0, 75.5, 100.0, 150.0, 190.0])
    ph = np.random.default_rng(1).random(freqs.size) * 2 * np.pi
    F = np.sum(np.cos(2 * np.pi * freqs[:, None] * t + ph[:, None]), axis=0)
    r = integrate(Rig(), F, fs, outputs=("a1", "a2", "u1", "q"))
    h = frf(freqs, Rig(), outputs=("a1", "a2", "u1", "q"))
    k = np.round(freqs * T).astype(int)
    Fk = np.fft.rfft(F[-n:])[k]
    for ch in ("a1", "a2", "u1", "q"):
        Y = np.fft.rfft(getattr(r, ch)[-n:])[k] / Fk
        assert np.max(np.abs(Y / h.channel(ch) - 1)) < 5e-4, ch


def test_straight_line_hold_is_the_sinc2_filter():
    # without the band-limited correction the response is low by sinc²(f/fs): -0.8 % at 100 Hz, 2048 Hz
    fs, T, reps = 2048.0, 2.0, 8
    t = np.arange(int(T * fs) * reps) / fs
    F = np.cos(2 * np.pi * 100.0 * t)
    r = integrate(Rig(), F, fs, outputs=("u1",), hold="linear")
    n = int(T * fs)
    Y = np.fft.rfft(r.u1[-n:])[200] / np.fft.rfft(F[-n:])[200]
    assert abs(Y / frf([100.0], Rig(), outputs=("u1",)).u1[0] / np.sinc(100 / fs) ** 2 - 1) < 1e-3


def _free_host(k3, amplitude, fs, seconds=2.0):
    """Free vibration of the host on its cubic spring after a short pulse; (amplitude, ω)."""
    rig = Rig(c1=0.0, cp=0.0, e=0.0, kp=1e-6, R=0.0)
    n = int(seconds * fs)
    t = np.arange(n) / fs
    tp = 1e-3
    w0 = np.sqrt(rig.k1 / rig.m1)
    F = np.where(t < tp, np.sin(np.pi * t / tp), 0.0) * amplitude * w0 * rig.m1 * np.pi / (2 * tp)
    r = integrate(rig, F, fs, [element("cubic_host_spring", k3=k3)], outputs=("u1",), segments=1, hold="linear")
    keep = t > 0.01
    u, tt = r.u1[keep], t[keep]
    idx = np.flatnonzero(np.sign(u[:-1]) != np.sign(u[1:]))
    crossings = tt[idx] - u[idx] * (tt[idx + 1] - tt[idx]) / (u[idx + 1] - u[idx])
    return rig, np.abs(u).max(), np.pi / np.mean(np.diff(crossings))


def test_duffing_backbone_first_order():
    k3 = 3.2e9  # 3 k3 a² / k1 ≈ 3 %
    rig, a, w = _free_host(k3, 1e-3, 2048.0)
    w0 = np.sqrt(rig.k1 / rig.m1)
    first = w0 * np.sqrt(1 + 0.75 * k3 / rig.k1 * a * a)
    assert w / w0 - 1 > 0.003  # it did harden
    assert abs(w / first - 1) < 1e-4


def test_duffing_backbone_exact_elliptic():
    k3 = 6.5e10  # 3 k3 a² / k1 ≈ 0.8: the first-order formula is off by 7e-4
    rig, a, w = _free_host(k3, 1e-3, 8192.0, seconds=1.0)
    alpha, beta = rig.k1 / rig.m1, k3 / rig.m1
    m = beta * a * a / (2 * (alpha + beta * a * a))
    exact = np.pi * np.sqrt(alpha + beta * a * a) / (2 * ellipk(m))
    first = np.sqrt(alpha) * np.sqrt(1 + 0.75 * k3 / rig.k1 * a * a)
    assert abs(w / exact - 1) < 1e-4
    assert abs(w / exact - 1) < 0.2 * abs(first / exact - 1)


def test_energy_balance():
    fs = 4096.0
    F = _random_force(4.0, fs, seed=3)
    F[-int(0.5 * fs):] = 0.0
    rig = Rig()
    els = [element("cubic_absorber_spring", k3=5e13), element("quadratic_damping", c2=300.0),
           element("absorber_friction", Fc=0.02, v0=1e-3)]
    r = integrate(rig, F, fs, els, outputs=("u1", "u2", "q", "v1", "v2", "i"), segments=1)
    d, v = r.u2 - r.u1, r.v2 - r.v1
    b = rig.e / rig.Cp
    stored = (0.5 * rig.m1 * r.v1 ** 2 + 0.5 * rig.m2 * r.v2 ** 2 + 0.5 * rig.k1 * r.u1 ** 2 + 0.5 * rig.kp * d ** 2
              - b * r.q * d + r.q ** 2 / (2 * rig.Cp) + 0.5 * rig.L * r.i ** 2 + 5e13 * d ** 4 / 4)
    p_diss = (rig.c1 * r.v1 ** 2 + rig.cp * v ** 2 + rig.R * r.i ** 2 + 300.0 * np.abs(v) ** 3
              + 0.02 * np.tanh(v / 1e-3) * v)
    p_in = F * r.v1
    work = np.trapezoid(p_in, dx=1 / fs)
    dissipated = np.trapezoid(p_diss, dx=1 / fs)
    assert work > 0
    assert abs(work - dissipated - (stored[-1] - stored[0])) < 2e-3 * work


def test_segments_agree_with_one_pass():
    fs = 1024.0
    F = _random_force(12.0, fs, seed=5)
    for el in (element("cubic_absorber_spring", k3=2e13), element("inductor_saturation", isat=0.015)):
        exact = integrate(Rig(), F, fs, [el], segments=1, backend="numpy")
        fast = integrate(Rig(), F, fs, [el], segments=6, backend="numpy")
        assert fast.meta["segments"] == 6
        assert np.max(np.abs(fast.a1 - exact.a1)) < 1e-5 * np.std(exact.a1)


def test_zero_strength_is_linear_and_batches_agree():
    fs = 1024.0
    F = _random_force(6.0, fs, seed=7)
    lin = integrate(Rig(), F, fs)
    zero = integrate(Rig(), F, fs, [element("quadratic_damping", c2=0.0)])
    assert np.max(np.abs(zero.a2 - lin.a2)) < 1e-12 * np.max(np.abs(lin.a2))
    k3 = np.array([0.0, 1e13, 3e13])
    batch = integrate(Rig(kp=np.array([1.0e5, 1.1e5, 1.2e5])), F, fs, [element("cubic_absorber_spring", k3=k3)])
    one = integrate(Rig(kp=1.2e5), F, fs, [element("cubic_absorber_spring", k3=3e13)])
    assert batch.a1.shape == (3, F.size)
    assert np.max(np.abs(batch.a1[2] - one.a1)) < 1e-10 * np.max(np.abs(one.a1))


@settings(max_examples=6, deadline=None)
@given(name=st.sampled_from(["cubic_absorber_spring", "cubic_host_spring", "absorber_friction",
                             "quadratic_damping", "inductor_saturation"]),
       seed=st.integers(0, 1000), level=st.floats(0.3, 3.0))
def test_odd_elements_give_odd_responses(name, seed, level):
    params = {"cubic_absorber_spring": {"k3": 2e13}, "cubic_host_spring": {"k3": 5e13},
              "absorber_friction": {"Fc": 0.03}, "quadratic_damping": {"c2": 300.0},
              "inductor_saturation": {"isat": 0.02}}[name]
    F = level * _random_force(2.0, 1024.0, seed=seed)
    el = element(name, **params)
    up = integrate(Rig(), F, 1024.0, [el], segments=1)
    down = integrate(Rig(), -F, 1024.0, [el], segments=1)
    assert np.max(np.abs(up.a1 + down.a1)) < 1e-9 * np.max(np.abs(up.a1))


def test_bad_input_is_refused():
    with pytest.raises(DataError, match="force"):
        integrate(Rig(), [np.nan, 1.0, 2.0], 1000.0)
    with pytest.raises(DataError, match="L > 0"):
        integrate(Rig(L=0.0), np.ones(10), 1000.0)
    with pytest.raises(DataError, match="output"):
        integrate(Rig(), np.ones(10), 1000.0, outputs=("a3",))
    assert band_limited(np.zeros(5), 100.0).shape == (5,)


@pytest.mark.skipif(not __import__("satmd.physics.nonlinear.kernel", fromlist=["x"]).available,
                    reason="numba not installed")
def test_compiled_and_numpy_paths_agree():
    fs = 1024.0
    F = _random_force(8.0, fs, seed=9)
    rig = Rig(kp=np.array([1.0e5, 1.2e5]))
    for name, params in (("cubic_absorber_spring", {"k3": 2e13}), ("cubic_host_spring", {"k3": 5e13}),
                         ("absorber_friction", {"Fc": 0.05, "v0": 1e-3}), ("quadratic_damping", {"c2": 300.0}),
                         ("inductor_saturation", {"isat": 0.015})):
        el = element(name, **params)
        a = integrate(rig, F, fs, [el], outputs=("a1", "a2", "i"), backend="numba")
        b = integrate(rig, F, fs, [el], outputs=("a1", "a2", "i"), backend="numpy", segments=1)
        assert a.meta["backend"] == "numba"
        for ch in ("a1", "a2", "i", f"g:{name}"):
            x, y = getattr(a, ch) if ch[0] != "g" else a.signals[ch], getattr(b, ch) if ch[0] != "g" else b.signals[ch]
            assert np.max(np.abs(x - y)) <= 1e-9 * np.max(np.abs(y)) + 1e-300, (name, ch)
    two = [element("cubic_absorber_spring", k3=2e13), element("quadratic_damping", c2=300.0)]
    a = integrate(Rig(), F, fs, two, backend="numba")
    b = integrate(Rig(), F, fs, two, backend="numpy", segments=1)
    assert np.max(np.abs(a.a2 - b.a2)) <= 1e-9 * np.max(np.abs(b.a2))


def test_oversampling_converges_at_second_order():
    # the element forces' straight-line hold errs by O(Δ²): 4x the rate cuts the backbone error ~16x
    from satmd.physics.nonlinear.integrate import upsample

    x = np.random.default_rng(0).standard_normal(300)
    assert np.max(np.abs(upsample(x, 4)[::4] - x)) < 1e-12
    k3 = 6.5e10
    rig = Rig(c1=0.0, cp=0.0, e=0.0, kp=1e-6, R=0.0)
    fs, n = 2048.0, 2048
    t = np.arange(n) / fs
    F = np.where(t < 1e-3, np.sin(np.pi * t / 1e-3), 0.0) * 1e-3 * np.sqrt(rig.k1 / rig.m1) * rig.m1 * np.pi / 2e-3
    errors = []
    for k in (1, 4):
        u = integrate(rig, F, fs, [element("cubic_host_spring", k3=k3)], outputs=("u1",), hold="linear",
                      oversample=k, segments=1).u1[t > 0.01]
        a = np.abs(u).max()
        tt = t[t > 0.01]
        idx = np.flatnonzero(np.sign(u[:-1]) != np.sign(u[1:]))
        w = np.pi / np.mean(np.diff(tt[idx] - u[idx] * (tt[idx + 1] - tt[idx]) / (u[idx + 1] - u[idx])))
        alpha, beta = rig.k1 / rig.m1, k3 / rig.m1
        m = beta * a * a / (2 * (alpha + beta * a * a))
        errors.append(abs(w / (np.pi * np.sqrt(alpha + beta * a * a) / (2 * ellipk(m))) - 1))
    assert errors[1] < errors[0] / 8

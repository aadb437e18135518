"""Modes above the force's band in the joint's loop (`satmd.structure.loop`), on the independent chain."""
import numpy as np
import pytest

from satmd.structure.linear import LinearStructure
from satmd.structure.loop import static_flexibility, with_loop_modes
from satmd.structure.model import Drive, Joint, StructureModel, nrmse
from satmd.structure.outputs import resolved_outputs
from satmd.structure.outside import loop_poles
from satmd.structure.simulations import fit_span, oversampling
from satmd.structure.spectra import drive_force, periodic_spectra, warmup_of
from tests.structure.chain import chain_modes, simulate_chain

NAMES = tuple(f"acc{i}" for i in range(1, 5))
STIFF = 3e10  # N/m³: the cubic joint between masses 3 and 4, stiff enough that its harmonics ring the modes above


def test_static_flexibility_is_the_springs_compliance():
    """At rest a force on the first mass of a chain held to the ground by its first spring stretches that spring
    alone, and a pair of forces on masses 3 and 4 (the chain's free end) the spring between them alone: the modes'
    sum is exact, ``1/k``, negative for the pair (the joint's force pulls its sensors together)."""
    k = [4e4, 1e4, 2e4, 3e4]
    poles, residues, feed = chain_modes(4, k=k)
    lin = LinearStructure(NAMES, poles, residues, feed)
    assert static_flexibility(poles, residues[0]) == pytest.approx(1 / k[0], rel=1e-9)
    pair = lin.pair_residues("acc3", "acc4") * -lin.coupling("acc3", "acc4", "acc1")
    assert static_flexibility(poles, pair) == pytest.approx(-1 / k[3], rel=1e-9)


def _whole(model, recording):
    drive = Drive(model, drive_force(recording), recording.fs_hz, warmup_of(recording))
    return drive, np.array([np.asarray(recording[c], float) for c in NAMES])


def _worst(model, recording) -> float:
    drive, measured = _whole(model, recording)
    return max(nrmse(a, m) for a, m in zip(drive.outputs(model.joint), measured))


def test_the_modes_above_the_band_are_found_and_fitted_in_the_joint_s_loop():
    """A multisine to 36 Hz reaches the chain's modes at 11 and 32 Hz; a stiff cubic joint's harmonics reach its
    modes at 48.8 and 59.8 Hz too, which carry half the joint's own stroke flexibility. Given the modes in the
    band (exact) and the true law, the harmonics that are left point to the modes above (`loop_poles`), and the
    modes fitted in the loop (poles, stroke residues, the law) take the held-out level's worst NRMSE from 0.24 to
    0.06 (its records anti-aliased, 0.5 % noise)."""
    recordings = simulate_chain(n=4, joint=(2, 3), law=lambda d, v: STIFF * d ** 3, levels=(1.0, 3.0, 8.0, 5.0),
                                band=(3.0, 36.0), seed=2, noise=0.005, anti_alias=True)
    fitted, held = recordings[:3], recordings[3]
    poles, residues, feed = chain_modes(4)
    above = np.abs(poles) / (2 * np.pi) > 40
    full = LinearStructure(NAMES, poles, residues, feed)
    kappa = -full.coupling("acc3", "acc4", "acc1")
    lin = LinearStructure(NAMES, poles[~above], residues[:, ~above], feed)
    joint = Joint(("acc3", "acc4"), "cubic", np.array([STIFF, 0.0, 0.0]), np.ones(3), kappa[~above], "N")
    model = StructureModel(lin, joint, (1.0, 8.0), oversample=oversampling(lin, 256.0))
    model = resolved_outputs(model, [_whole(model, r) for r in fitted])

    starts = loop_poles(model, [periodic_spectra(r) for r in fitted], 2)
    truth = np.sort(np.abs(poles[above]))
    assert np.allclose(np.sort(np.abs(starts)), truth, rtol=0.03), np.abs(starts) / (2 * np.pi)

    span = [fit_span(r) for r in fitted]
    measured = [np.array([np.asarray(r[c], float)[:n] for c in NAMES]) for r, n in zip(fitted, span)]
    asked = []  # the caller is asked once, after the first steps gained, whether to go on
    looped = with_loop_modes(model, 0.93 * truth * 1j - 0.01 * truth, fitted, measured, span, 40, 256.0,
                             promising=lambda m: asked.append(m.linear.poles.size) or True)
    assert looped is not None and asked == [lin.poles.size + 2]
    assert with_loop_modes(model, 0.93 * truth * 1j - 0.01 * truth, fitted, measured, span, 40, 256.0,
                           promising=lambda m: False) is None  # not promising: no further steps, nothing kept
    added = np.sort(np.abs(looped.linear.poles[lin.poles.size:]))
    assert np.allclose(added, truth, rtol=0.02), added / (2 * np.pi)
    before, after = _worst(model, held), _worst(looped, held)
    assert after < 0.35 * before, (before, after)
    assert 0.8 * STIFF < looped.joint.coefficients[0] < 1.2 * STIFF and "k3" in looped.joint.ci95


def test_a_trial_whose_states_pass_floating_point_is_told_as_a_run_away():
    """A trial mode in the loop can drive a state past floating point while the joint's force stays finite (on
    `structures_predict`'s first chain): the channels' least squares would be singular; the trial is a run-away."""
    from satmd.structure.outputs import Projection

    recording = simulate_chain(n=4, joint=(2, 3), law=lambda d, v: STIFF * d ** 3, levels=(1.0,), seed=2)[0]
    poles, residues, feed = chain_modes(4)
    lin = LinearStructure(NAMES, poles, residues, feed)
    joint = Joint(("acc3", "acc4"), "cubic", np.array([STIFF, 0.0, 0.0]), np.ones(3),
                  -lin.coupling("acc3", "acc4", "acc1"), "N")
    model = StructureModel(lin, joint, (1.0, 1.0), oversample=2)
    projection = Projection(model, [_whole(model, recording)], 2)
    assert projection.solve(joint) is not None
    drive = projection.parts[0][0]
    g, w = drive.driven(joint, 2)
    drive.driven = lambda joint, step: (g, w * 1e300)
    assert projection.solve(joint) is None


def test_a_model_holds_beyond_the_top_level_where_its_response_grows_as_the_force_may():
    """`_Fit.holds_beyond`: the chain's own model, driven by twice the top level's force, responds within ten
    times the top level's measured response scaled by the force (a hardening joint: less than twice); against a
    top level measured forty times lower, the same response is a run-away in all but floating point."""
    from satmd.structure.fit import _Fit

    recordings = simulate_chain(n=4, joint=(2, 3), law=lambda d, v: STIFF * d ** 3, levels=(1.0, 3.0), seed=2)
    poles, residues, feed = chain_modes(4)
    lin = LinearStructure(NAMES, poles, residues, feed)
    joint = Joint(("acc3", "acc4"), "cubic", np.array([STIFF, 0.0, 0.0]), np.ones(3),
                  -lin.coupling("acc3", "acc4", "acc1"), "N")
    model = StructureModel(lin, joint, (1.0, 3.0), oversample=oversampling(lin, recordings[0].fs_hz))
    fit = _Fit(recordings, [periodic_spectra(r) for r in recordings], NAMES, None, 10, ("measured",), "acc1",
               lambda s: None)
    assert fit.holds_beyond(model)
    fit.measured[1] = fit.measured[1] / 40
    assert not fit.holds_beyond(model)


@pytest.mark.parametrize("mode_hz, rising", [(118.0, True), (70.0, False)])
def test_a_response_rising_to_the_lines_top_points_beyond_them(mode_hz, rising):
    """Above the band the lines stop at 0.8 of Nyquist (the anti-alias filter takes the rest): a mode at 118 Hz
    (fs 256) shows only as a response that rises toward the last line, and the loop gets a start at 0.95 of
    Nyquist for it; a mode at 70 Hz peaks among the lines, and its vector fit is what the loop starts from."""
    from satmd.structure.outside import BEYOND_AT, _column, _rising

    rng = np.random.default_rng(0)
    f = np.arange(41.0, 102.4, 0.25)
    G = (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) * np.exp(-f / 60.0)  # harmonics' roll-off
    lam = 2 * np.pi * mode_hz * (-0.01 + 1j)
    E = _column(np.array([lam]), np.array([[1e4 + 0j], [-3e3 + 0j]]), f) * G[None, :]
    E += 1e-3 * np.abs(E).mean() * rng.standard_normal(E.shape)  # noise
    blocks = [(f, G, E, np.ones(E.shape), np.arange(f.size))]
    assert _rising(blocks, np.zeros(0, complex)) is rising
    assert not _rising(blocks, np.array([lam]))  # the mode itself found: nothing left to rise
    assert BEYOND_AT * 128.0 > 118.0  # the start lies beyond the mode, which the fit then moves down to

"""The acquisition's low-pass on the joint's harmonics (`satmd.structure.acquisition`): the chain of `chain.py`
(four masses, a cubic joint between the last two, a multisine to 45 Hz) as its model simulates it, every channel
and the force through scipy's causal 8th-order elliptic low-pass at 100 Hz, as a data acquisition filters them."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy import signal

from satmd.errors import DataError
from satmd.structure import Joint, StructureModel
from satmd.structure.acquisition import Acquisition, acquisition_of
from satmd.structure.linear import fit_linear
from satmd.structure.model import Drive
from satmd.structure.spectra import periodic_spectra
from tests.structure.chain import simulate_chain

CHANNELS = ("acc1", "acc2", "acc3", "acc4")
CUTOFF = 100.0


@pytest.fixture(scope="module")
def chain():
    """The chain's model (its cubic as simulated, its modes above the band through the joint's harmonics, as
    `_Fit.widened` finds them) as the structure, and its records at every level: the model's response to the
    recorded force, then every channel, the force too, through the elliptic low-pass."""
    from satmd.structure.fit import _Fit

    raw = simulate_chain(n=4, joint=(2, 3), law=lambda d, v: 3e9 * d ** 3, band=(3.0, 45.0), levels=(1.0, 3.0, 8.0),
                         period=1024, periods=4, noise=0.003, seed=5)
    spectra = [periodic_spectra(r) for r in raw]
    linear = fit_linear(spectra[0], CHANNELS)
    joint = Joint(("acc3", "acc4"), "cubic", np.array([-3e9, 0.0, 0.0]), np.ones(3),
                  linear.coupling("acc3", "acc4", "acc1"))
    fit = _Fit(raw, spectra, CHANNELS, None, 20, ("measured",), "acc1", lambda s: None)
    model = fit.widened(StructureModel(linear, joint, (1.0, 8.0)))
    fs = raw[0].fs_hz
    sos = signal.ellip(8, 0.05, 80.0, CUTOFF, fs=fs, output="sos")
    plain, filtered = [], []
    for r in raw:
        force = np.asarray(r["force"], float)
        y = model.simulate(force, fs, 1024)
        plain.append((Drive(model, force, fs, 1024), y))
        filtered.append((Drive(model, signal.sosfilt(sos, force), fs, 1024), signal.sosfilt(sos, y, axis=1)))
    return model, plain, filtered, sos, fs


def test_the_acquisition_s_low_pass_is_found_from_the_joint_s_harmonics(chain):
    """Filtered, the records' FRF is the structure's, but the joint's harmonics lag by the filter's phase beyond
    the band: the gain found falls through -3 dB in the band across the filter's edge or the next, its phase
    within 20° of the filter's (less its delay in the band, which the force shares) where the harmonics are, and the top level is
    simulated closer with it."""
    model, _, filtered, sos, fs = chain
    found = acquisition_of(model, filtered, 45.0)
    assert found is not None
    # the first band centre below -3 dB: the band across the filter's edge or the next (5.19 Hz wide; 104.7 here)
    assert found.cutoff_hz() is not None and CUTOFF < found.cutoff_hz() < CUTOFF + 2 * 5.19, found.cutoff_hz()
    f = np.fft.rfftfreq(4096, 1.0 / fs)
    _, H = signal.sosfreqz(sos, worN=f, fs=fs)
    band = (f > 3) & (f < 45)
    delay = -np.polyfit(2 * np.pi * f[band], np.unwrap(np.angle(H[band])), 1)[0]
    at = (f > 50) & (f < 90)
    lag = np.degrees(np.angle(found.at(f[at]) / (H[at] * np.exp(2j * np.pi * f[at] * delay))))
    assert np.all(np.abs(lag) < 20.0), lag
    drive, measured = filtered[-1]
    with_it = Drive(replace(model, acquisition=found), drive.force, fs, drive.skip)
    steady = slice(1024, None)  # past the filter's own start from rest
    before = np.sqrt(np.mean((drive.outputs(model.joint) - measured)[:, steady] ** 2))
    after = np.sqrt(np.mean((with_it.outputs(model.joint) - measured)[:, steady] ** 2))
    assert after < 0.3 * before, (before, after)  # 0.183 to 0.035 here
    assert "-3 dB by" in found.describe()


def test_an_unfiltered_record_gets_no_acquisition_filter(chain):
    """The same records unfiltered: nothing beyond the band lags, and no low-pass is claimed."""
    model, plain, _, _, _ = chain
    assert acquisition_of(model, plain, 45.0) is None


def test_a_candidate_that_ran_far_away_gets_no_gain_and_no_warning(chain, recwarn):
    """A candidate's share of the records finite but far beyond them (its spectrum's power overflows): no gain,
    and no NumPy overflow warning on the user's screen (the F-16's loop modes printed one through `discover`)."""
    model, plain, _, _, fs = chain

    class FarAway:
        def __init__(self, drive):
            self.linear, self.skip, self.fs = drive.linear, drive.skip, drive.fs

        def outputs(self, joint):
            return self.linear[:, self.skip:] + 1e160 * np.sin(np.arange(self.linear.shape[1] - self.skip))

    assert acquisition_of(model, [(FarAway(d), y) for d, y in plain], 45.0) is None
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_the_gain_is_one_in_the_band_and_round_trips(tmp_path):
    gain = Acquisition(40.0, np.array([60.0, 90.0, 120.0]), np.array([0.9 - 0.2j, 0.4 - 0.5j, 0.05 + 0j]))
    f = np.array([0.0, 10.0, 40.0, 60.0, 75.0, 200.0])
    at = gain.at(f)
    assert np.allclose(at[:3], 1.0) and at[3] == pytest.approx(0.9 - 0.2j)
    assert abs(at[4]) == pytest.approx(0.5 * (abs(gain.gain[0]) + abs(gain.gain[1])))
    assert abs(at[5]) == pytest.approx(0.05)
    assert gain.cutoff_hz() == 90.0
    x = np.random.default_rng(0).standard_normal((2, 512))
    assert np.allclose(Acquisition(100.0, np.array([110.0]), np.array([1.0 + 0j])).apply(x, 256.0), x, atol=1e-12)
    back = Acquisition.from_dict(gain.to_dict())
    assert np.allclose(back.gain, gain.gain) and np.allclose(back.freq_hz, gain.freq_hz)
    doc = gain.to_dict()
    doc["gain"] = doc["gain"][:2]
    with pytest.raises(ValueError, match="acquisition gain"):
        Acquisition.from_dict(doc)


def test_the_gain_does_not_join_a_record_s_end_to_its_start():
    """Applied by FFT over the record alone, the gain's roll-off rang the step from the record's end back to its
    start; mirrored about its ends, a record's first samples come out as they do inside a longer one."""
    from tests.structure.chain import multisine

    gain = Acquisition(40.0, np.array([60.0, 100.0, 120.0]), np.array([0.9 * np.exp(-0.5j), 0.5 * np.exp(-2j),
                                                                       0.1 * np.exp(-3j)]))
    x = np.tile(multisine(1024, 256.0, 5.0, 90.0, 0), 4)
    cut, whole = gain.apply(x[None, :2500], 256.0)[0], gain.apply(x[None, :], 256.0)[0][:2500]
    assert np.max(np.abs(cut - whole)[:16]) < 1e-3 * np.std(x)
    assert np.max(np.abs(cut - whole)[500:2000]) < 1e-3 * np.std(x)  # the gain on another grid of lines


def test_a_saved_model_keeps_its_acquisition_and_a_cut_one_is_refused(tmp_path, chain):
    gain = Acquisition(40.0, np.array([60.0, 90.0]), np.array([0.9 - 0.2j, 0.5 - 0.6j]))
    model = replace(chain[0], acquisition=gain)
    path = tmp_path / "model.json"
    model.save(path)
    back = StructureModel.load(path)
    assert np.allclose(back.acquisition.gain, gain.gain)
    assert "acquisition's low-pass" in back.report()
    text = path.read_text().replace('"band_top_hz"', '"band_edge"')
    path.write_text(text)
    with pytest.raises(DataError, match="model.json"):
        StructureModel.load(path)


def test_discover_says_the_chain_s_filter_apart_from_the_joint(monkeypatch, chain):
    """`discover`'s joint finding names the acquisition's low-pass as the measurement chain's, after the joint's
    model (fakes for the location and the fit: the sentence is what is tested)."""
    from satmd.discovery.findings import NonlinearFinding
    from satmd.discovery.nonlinear import modes
    from satmd.discovery.nonlinear.distortion import NonlinearReport
    from satmd.structure import JointLocation

    gain = Acquisition(36.0, np.array([60.0, 90.0, 110.0]), np.array([0.99 - 0.3j, 0.8 - 1.2j, 0.3 + 0j]))
    fitted = replace(chain[0], acquisition=gain, fit={"metric": "nrmse", "channels": list(CHANNELS),
                                                      "linear": [[0.3] * 4], "nonlinear": [[0.02] * 4]})
    located = JointLocation(("acc3", "acc4"), [{"between": ["acc3", "acc4"], "delta_bic": 0.0, "law": "cubic"}],
                            "cubic", [{"law": "cubic", "delta_bic": 0.0}], [], [], "L1", [1.0, 8.0], evidence=1e3)
    monkeypatch.setattr("satmd.structure.locate_joint", lambda recordings, channels=None: located)
    monkeypatch.setattr(modes, "_structure_model", lambda recordings, loc, channels=None: fitted)
    report = NonlinearReport(True, [], [NonlinearFinding("nonlinear_unexplained", explanation="")])
    recordings = simulate_chain(n=4, joint=(2, 3), levels=(1.0, 8.0), period=256, periods=2, seed=1)
    text = modes.with_joint(report, recordings).findings[0].explanation
    assert "modelled" in text and "acquisition's low-pass" in text and "-3 dB by 110 Hz" in text, text

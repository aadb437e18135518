"""Lines in a random test's responses (hum, a pick-up tone) against resonances sharper than the local
polynomial's window (`satmd.signal.lpm._line_windows`): the first are the sensor chain's and left out, the second
the structure's and kept."""
from __future__ import annotations

import functools

import numpy as np
import pytest

from satmd.io import Recording
from satmd.signal import estimate_frf


@functools.cache
def _random_chain(seconds=60.0, seed=3):
    """A linear 5-mass chain (ζ = 1 % at its 9.1 Hz first mode) driven by band-limited random noise, 1 % noise."""
    from scipy import signal

    from tests.structure.chain import simulate_chain

    fs = 256.0
    rng = np.random.default_rng(seed)
    u = signal.sosfilt(signal.butter(6, [3.0, 60.0], btype="band", fs=fs, output="sos"),
                       rng.standard_normal(int(fs * seconds)))
    (rec,) = simulate_chain(joint=(2, 3), law=lambda d, v: 0.0 * d, levels=(1.0,), seed=1, force=u / u.std())
    return rec


def test_a_resonance_narrower_than_the_window_is_the_structure_s_not_a_line():
    """Under random excitation a lightly damped mode is sharper than the default 0.3 Hz window: the polynomial
    misses its peak in a bin of one channel and in five of the other. Its windows were dropped as narrowband
    interference (no point left within the mode's half-power band); they are kept, the windows narrowed to the
    mode as far as the record allows, and the short record said."""
    d = estimate_frf(_random_chain())
    found = {m["name"] for m in d.estimator["measurement"]}
    assert "narrowband_interference" not in found and "short_record" in found
    assert d.estimator["window_hz"] < 0.3
    assert np.min(np.abs(d.freq_hz - 9.06)) < 0.09  # the chain's first mode, 0.18 Hz wide at half power
    wide = estimate_frf(_random_chain(), width_hz=0.3)  # windows of 0.3 Hz kept too: bent, not a line
    assert "narrowband_interference" not in {m["name"] for m in wide.estimator["measurement"]}
    assert np.min(np.abs(wide.freq_hz - 9.06)) < 0.16


@pytest.mark.parametrize("share", [0.0005, 0.001])
def test_a_pickup_line_on_a_random_test_is_still_the_sensor_chain_s(share):
    """A faint 23.7 Hz tone on acc1 and acc2, which the force does not explain, is found and its window left out
    (in windows of 0.3 Hz: the 7-bin windows a sharp mode asks of a 60 s record leave one degree of freedom)."""
    rec = _random_chain()
    t = np.arange(rec.n_samples) / rec.fs_hz
    tone = share * np.std(rec["acc1"]) * np.sqrt(2) * np.sin(2 * np.pi * 23.7 * t + 0.3)
    hum = Recording(rec.fs_hz, {**{c: rec[c] for c in rec.channels}, "acc1": rec["acc1"] + tone,
                                "acc2": rec["acc2"] + 0.5 * tone}, meta={})
    d = estimate_frf(hum, width_hz=0.3)
    found = {m["name"]: m for m in d.estimator["measurement"]}
    assert "narrowband_interference" in found and "23.68" in found["narrowband_interference"]["explanation"]
    assert "9.12" not in found["narrowband_interference"]["explanation"]  # the mode is not among the lines
    assert np.min(np.abs(d.freq_hz - 23.7)) > 0.5 * d.estimator["window_hz"]

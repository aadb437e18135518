"""Real third-party files (../shared/data/real, see its README); skipped when the folder is absent."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from satmd.cli import main
from satmd.errors import FormatError
from satmd.io.shared import real_data
from tests.conftest import needs_real
from satmd.io import DataWarning, load_frf, load_recording
from satmd.signal import transmissibility

REAL = real_data() or Path("absent")
pytestmark = needs_real()
pytest.importorskip("pyuff")

MPSTD = REAL / "MPSTD_Set001_2024_10_08_10_27_07.uff"


def test_output_only_acceleration_records():
    rec = load_recording(MPSTD)
    assert list(rec.channels) == ["ch1", "ch2", "ch3", "ch4"]
    assert rec.fs_hz == 3200.0 and rec.n_samples == 222400 and rec.duration_s == pytest.approx(69.5)
    assert set(rec.units.values()) == {"m/s^2"} and not rec.has_force
    assert "UFF #1, 1:+Z" in rec.labels["ch1"]


def test_output_only_file_gives_a_transmissibility():
    rec = load_recording(MPSTD, channel_map="a1=#1,a2=#2")
    t = transmissibility(rec, band_hz=(1, 400))
    assert np.all(np.isfinite(t.value)) and np.all((t.coherence >= 0) & (t.coherence <= 1))
    assert t.freq_hz[0] > 0 and t.freq_hz[-1] <= 400


def test_microphone_record_ascii_and_binary_agree():
    a = load_recording(REAL / "Sample_UFF58_ascii.uff")
    b = load_recording(REAL / "Sample_UFF58b_bin.uff")
    assert a.fs_hz == b.fs_hz == 65536.0  # the 6-digit time step 1.52588e-05 s snapped back
    assert a.n_samples == b.n_samples == 79292 and a.units["ch1"] == "Pa"
    np.testing.assert_allclose(a["ch1"], b["ch1"], rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize("name", ["MPSTD_Set001_2024_10_08_10_27_07.uff", "Sample_UFF58_ascii.uff"])
def test_time_files_are_not_frfs(name):
    with pytest.raises(FormatError, match="time record.*estimate-frf"):
        load_frf(REAL / name)


def test_complex_text_frfs_need_a_frequency_axis():
    with pytest.raises(FormatError, match="no frequency axis"):
        load_frf(REAL / "meas_point_1.txt")
    for k in (1, 2, 3):
        with pytest.warns(DataWarning, match="f <= 0 Hz"):
            d = load_frf(REAL / f"meas_point_{k}.txt", freq_axis="0:1")
        assert len(d) == 1000 and d.freq_hz[0] == 1.0 and d.freq_hz[-1] == 1000.0
        assert np.all(np.isfinite(d["a1"]))


@pytest.mark.parametrize("name,expect", [
    ("MPSTD_Set001_2024_10_08_10_27_07.uff", ["4 dataset(s)", "3200 Hz", "222400 samples (69.5 s)", "m/s2",
                                              "#1, #4 share response 1:+Z"]),
    ("Sample_UFF58_ascii.uff", ["1 dataset(s)", "65536 Hz", "79292 samples", "Pressure [Pa]"]),
    ("Sample_UFF58b_bin.uff", ["58b", "65536 Hz", "Pressure [Pa]"]),
    ("meas_point_2.txt", ["1001 complex values", "--freq-axis"]),
])
def test_info_describes_each_real_file(capsys, name, expect):
    assert main(["info", str(REAL / name)]) == 0
    out = capsys.readouterr().out
    for text in expect:
        assert text in out, (text, out)

"""A structure's modes and shapes (`satmd.modal.survey`, `satmd modes`), against a chain's exact mass-normalised
modes from its matrices (Newton's law, no satmd code)."""
from __future__ import annotations

import json

import numpy as np
import pytest
from scipy import linalg

from satmd.cli import main
from satmd.errors import DataError
from satmd.io import save_recording
from satmd.modal import survey
from satmd.signal import estimate_frfs
from tests.structure.chain import chain_matrices, linear_chain_test

N = 5


def _exact(f_hz):
    """The chain's accelerances (force on mass 1) and its mass-normalised modes, φ_1 > 0."""
    M, K, C = chain_matrices(N)
    w = 2 * np.pi * np.asarray(f_hz)
    x = np.array([np.linalg.solve(K - wi ** 2 * np.diag(M) + 1j * wi * C, np.eye(N)[0]) for wi in w])
    w2, phi = linalg.eigh(K, np.diag(M))
    return (-(w ** 2)[:, None] * x).T, np.sqrt(w2) / (2 * np.pi), (phi * np.sign(phi[0])).T


def test_exact_frfs_give_the_mass_normalised_modes():
    f = np.linspace(3.0, 90.0, 600)
    H, f_n, phi = _exact(f)
    found = survey(f, {f"acc{i + 1}": H[i] for i in range(N)})
    assert found.driving_point == "acc1" and found.normalised == "mass"
    np.testing.assert_allclose([m.f_hz for m in found.fit.modes], f_n, rtol=1e-4)
    np.testing.assert_allclose(found.shapes, phi, atol=2e-3)  # light-damping constants: ζ up to 7 %
    assert np.all(found.complexity < 1e-3)  # proportional damping: real modes


def test_shapes_of_a_noisy_test_within_a_few_percent():
    frfs = estimate_frfs(linear_chain_test())
    found = survey(frfs.freq_hz, dict(zip(frfs.channels, frfs.frf)), dict(zip(frfs.channels, frfs.std)))
    _, f_n, phi = _exact([1.0])
    assert found.driving_point == "acc1" and len(found.fit.modes) == N
    np.testing.assert_allclose([m.f_hz for m in found.fit.modes], f_n, rtol=2e-3)
    assert np.max(np.abs(found.shapes - phi)) < 0.03, np.round(found.shapes - phi, 3)


def test_another_driving_point_named_is_refused_or_scaled():
    f = np.linspace(3.0, 90.0, 600)
    H, _, phi = _exact(f)
    frf = {f"acc{i + 1}": H[i] for i in range(N)}
    named = survey(f, frf, driving_point="acc3")  # taken at its word, the modes where its sign disagrees said
    assert [round(x) for x in named.other_sign_hz] == [42, 54] and "acc3's modal constants have the other sign" \
        in named.report()
    assert survey(f, frf, driving_point="acc1").other_sign_hz == ()
    with pytest.raises(DataError, match="the driving point 'acc9' is not a channel"):
        survey(f, frf, driving_point="acc9")
    unit = survey(f, {c: frf[c] for c in ("acc2", "acc3", "acc5")})  # the driving point not measured
    assert unit.driving_point is None and unit.normalised == "largest"
    top = phi[:, [1, 2, 4]] / np.take_along_axis(phi[:, [1, 2, 4]], np.argmax(np.abs(phi[:, [1, 2, 4]]), 1)[:, None], 1)
    np.testing.assert_allclose(unit.shapes, top, atol=5e-3)
    assert "name the driving point for a mass scale" in unit.report()


def test_cli_modes_from_a_recording_and_from_its_frfs(tmp_path, capsys):
    rec = linear_chain_test()
    path = save_recording(rec, tmp_path / "gvt.csv")
    assert main(["modes", str(path), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["driving_point"] == "acc1" and doc["normalised"] == "mass"
    assert [round(m["f_hz"]) for m in doc["modes"]] == [9, 26, 42, 54, 61]
    assert set(doc["modes"][0]["shape"]) == {"acc1", "acc2", "acc3", "acc4", "acc5"}
    # the first three modes alone: acc2's constants are positive on each too (φ_1 φ_2 > 0), so no sensor alone is
    # the driving point, and the shapes are scaled to their largest sensor
    assert main(["modes", str(path), "--json", "--band", "5:50"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["driving_point"] is None and doc["normalised"] == "largest" and len(doc["modes"]) == 3
    assert 5.0 <= doc["band_hz"][0] and doc["band_hz"][1] <= 50.0
    frfs = estimate_frfs(rec).save(tmp_path / "frfs.uff")
    assert main(["modes", str(frfs), "--driving-point", "acc1", "--plot", str(tmp_path / "m.png")]) == 0
    said = capsys.readouterr().out
    assert "shapes mass-normalised through the driving point acc1" in said and (tmp_path / "m.png").exists()
    assert main(["modes", str(frfs), "--driving-point", "acc9"]) == 2
    assert "the driving point 'acc9' is not a channel" in capsys.readouterr().err


def test_cli_modes_of_a_rigs_frf_file(tmp_path, capsys):
    """A SATMD rig's A1 and A2: two modes, the primary mass (a1) at the force, each FRF file alone."""
    data = tmp_path / "rig.csv"
    assert main(["simulate", "-o", str(data), "--noise", "0.01", "--seed", "1"]) == 0
    capsys.readouterr()
    assert main(["modes", str(data), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["channels"] == ["a1", "a2"] and doc["driving_point"] == "a1" and len(doc["modes"]) == 2
    assert main(["modes", str(data), str(data)]) == 2
    assert "a second FRF named 'rig:a1'" in capsys.readouterr().err


def test_cli_modes_of_a_roving_test_one_file_a_point(capsys):
    """The shared beam's accelerances (third-party, one .txt file a reference point, one response): its modes over
    the three points, each named by its file. Its driving point's constants change sign from mode to mode (the
    chain's delay or convention), so none is found, and one named is taken at its word with those modes said."""
    from satmd.io.shared import real_data

    files = [real_data(f"meas_point_{i}.txt") for i in (1, 2, 3)]
    if any(f is None for f in files):
        pytest.skip("../shared/data/real is absent")
    argv = ["modes", *map(str, files), "--freq-axis", "0:1", "--band", "20:300", "--json"]
    assert main(argv) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["channels"] == ["meas_point_1", "meas_point_2", "meas_point_3"] and doc["driving_point"] is None
    # the beam's first three bending modes; on this data (no std, damping 0.02-0.05 %) the modal fit keeps a
    # second pole beside one of them (278.5 and 278.7 Hz), which the shapes then share
    assert {52, 142, 279} <= {round(m["f_hz"]) for m in doc["modes"]} and len(doc["modes"]) <= 4
    assert main([*argv, "--driving-point", "meas_point_1"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["normalised"] == "mass" and [round(f) for f in doc["other_sign_hz"]] == [142]


def test_the_f16s_driving_point_is_found_among_sensors_in_phase():
    """The F-16's three sensors move in phase in every mode but a weak one (12.4 Hz): acc2 and acc3 pass the
    strong modes' sign test as acc1 does, and acc1, at the shaker, alone keeps its sign on every mode."""
    import warnings

    from satmd.io import load_recording
    from satmd.io.shared import real_data

    path = real_data("f16", "F16Data_FullMSine_Level1.mat")
    if path is None:
        pytest.skip("../shared/data/real/f16 is absent")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        rec = load_recording(path, channel_map="force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]")
    frfs = estimate_frfs(rec)
    found = survey(frfs.freq_hz, dict(zip(frfs.channels, frfs.frf)), dict(zip(frfs.channels, frfs.std)))
    assert found.driving_point == "acc1" and found.normalised == "mass"
    assert [round(m.f_hz, 1) for m in found.fit.modes][:6] == [3.5, 4.0, 5.2, 6.6, 7.3, 9.2]
    assert np.all(found.shapes[:6] > 0) and found.shapes[6, 0] * found.shapes[6, 1] < 0

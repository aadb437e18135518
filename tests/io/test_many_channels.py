"""Recordings with any number of accelerometers (acc1 ... accN): one naming rule, every reader and writer."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from satmd.cli import main
from satmd.errors import FormatError
from satmd.io import DataWarning, Recording, load_recording, save_recording
from satmd.io.recdata import accelerometers, is_role, ordered, role_of, si_unit
from satmd.io.shared import real_data
from tests.conftest import needs_real

FS = 1000.0
N = 400
ACCS = [f"acc{k}" for k in range(1, 7)]


def _signals(names, n=N, seed=0):
    """Distinct, smooth signals (no clipping, no glitch) for each name."""
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    return {name: (k + 1) * np.sin(2 * np.pi * (17 + 7 * k) * t + rng.uniform(0, 6)) for k, name in enumerate(names)}


def _quiet(fn, *args, **kwargs):
    """Call a loader with the DataWarnings a test does not look at (ignored variables, WAV units) silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataWarning)
        return fn(*args, **kwargs)


# --- the naming rule ------------------------------------------------------------------
def test_roles_are_force_and_any_numbered_accelerometer():
    assert all(is_role(n) for n in ("force", "acc1", "acc2", "acc3", "acc10", "acc123"))
    assert not any(is_role(n) for n in ("acc0", "acc01", "acc", "accx", "a1", "Acc3", "ch1", "mic", "", 3))
    assert accelerometers(["acc10", "mic", "acc2", "force", "acc1", "acc9"]) == ["acc1", "acc2", "acc9", "acc10"]
    assert ordered(["mic", "acc10", "acc2", "force", "ch1"]) == ["force", "acc2", "acc10", "mic", "ch1"]
    assert (si_unit("force"), si_unit("acc7"), si_unit("mic")) == ("N", "m/s^2", "")
    assert [role_of(k) for k in ("a1", "a2", "a3", "A12", "acc7", "f", "force")] == \
        ["acc1", "acc2", "acc3", "acc12", "acc7", "force", "force"]
    for bad, why in (("a0", "numbered from 1"), ("acc0", "numbered from 1"), ("accx", "a<N> or acc<N>"),
                     ("acc", "a<N> or acc<N>"), ("a2x", "a<N> or acc<N>"), ("mic", "unknown channel 'mic'")):
        with pytest.raises(ValueError, match=why):
            role_of(bad)


# --- CSV ---------------------------------------------------------------------------------
def test_six_accelerometer_csv_written_and_read_back(tmp_path):
    chans = _signals(["acc4", "force", *ACCS[:3], "acc6", "acc5"])  # any order in: written force, acc1..acc6
    p = save_recording(Recording(FS, chans), tmp_path / "gvt.csv")
    assert p.read_text().splitlines()[1] == "time_s,force,acc1,acc2,acc3,acc4,acc5,acc6"
    back = load_recording(p)
    assert list(back.channels) == ["force", *ACCS] and back.fs_hz == FS
    for name, v in chans.items():
        np.testing.assert_array_equal(back[name], v)  # 17 digits: exact
    assert back.units == {"force": "N", **{a: "m/s^2" for a in ACCS}}


def test_users_six_accelerometer_csv_is_read(tmp_path):
    chans = _signals(["force", *ACCS])
    p = tmp_path / "user.csv"  # as a user writes it: no satmd comment line
    rows = np.column_stack([np.arange(N) / FS, *chans.values()])
    np.savetxt(p, rows, delimiter=",", header="time_s,force," + ",".join(ACCS), comments="", fmt="%.17g")
    back = load_recording(p)
    assert list(back.channels) == ["force", *ACCS] and back.units["acc6"] == "m/s^2"
    np.testing.assert_array_equal(back["acc6"], chans["acc6"])


def test_csv_writer_writes_other_channels_last_and_reads_them_back(tmp_path):
    chans = _signals(["mic", "acc10", "acc2", "force", "acc9"])
    p = save_recording(Recording(FS, chans), tmp_path / "r.csv")
    assert p.read_text().splitlines()[1] == "time_s,force,acc2,acc9,acc10,mic"
    back = load_recording(p)
    assert list(back.channels) == ["force", "acc2", "acc9", "acc10", "mic"]
    np.testing.assert_array_equal(back["mic"], chans["mic"])
    assert "mic" not in back.units and back.units["acc10"] == "m/s^2"  # the CSV states no unit for it
    with pytest.raises(Exception, match="cannot be a CSV column"):
        save_recording(Recording(FS, {"acc1": chans["acc2"], "a,b": chans["mic"]}), tmp_path / "bad.csv")
    q = tmp_path / "typo.csv"  # without satmd's comment line a name that is no role is a typo
    q.write_text("time_s,force,acc_3\n0,1,2\n0.001,1,2\n")
    with pytest.raises(FormatError, match="unknown column 'acc_3'.*a channel map that names every column.*a1=acc_3"):
        load_recording(q)
    q.write_text("time_s,force,acc1,acc2,tip\n0,1,2,3,4\n0.001,1,2,3,4\n")  # the map said, with the next number
    with pytest.raises(FormatError, match="unknown column 'tip'.*a3=tip"):
        load_recording(q)
    assert list(load_recording(q, channel_map="force=force,a1=acc1,a2=acc2,a3=tip").channels) == [
        "force", "acc1", "acc2", "acc3"]


def test_lab_csv_with_acc3_to_acc5(tmp_path):
    chans = _signals(["force", "acc3", "acc4", "acc5"])
    p = tmp_path / "lab.csv"
    rows = np.column_stack([np.arange(N) / FS * 1e3, chans["force"] / 1e3, chans["acc4"],
                            chans["acc3"] / 9.80665, chans["acc5"] / 9.80665])
    np.savetxt(p, rows, delimiter=",", header="Time (ms),Force [kN],ACC4 [m/s^2],Acc3 [g],acc5 (g)", comments="",
               fmt="%.17g")
    back = load_recording(p)
    assert list(back.channels) == ["force", "acc3", "acc4", "acc5"] and back.fs_hz == pytest.approx(FS)
    for name, v in chans.items():
        np.testing.assert_allclose(back[name], v, rtol=1e-12, atol=1e-12)
    assert back.units == {"force": "N", "acc3": "m/s^2", "acc4": "m/s^2", "acc5": "m/s^2"}
    with pytest.warns(DataWarning, match=r"ignored column\(s\) ACC4"):  # a map names them as it likes
        mapped = load_recording(p, channel_map="force=Force,a1=Acc3,a7=acc5")
    assert list(mapped.channels) == ["force", "acc1", "acc7"]
    np.testing.assert_allclose(mapped["acc7"], chans["acc5"], rtol=1e-12, atol=1e-12)


# --- .npz / .mat -------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".npz", ".mat"])
def test_acceleration_matrix_mapped_row_by_row(tmp_path, suffix):
    chans = _signals(["force", "r1", "r2", "r3"])
    accel = np.vstack([chans["r1"], chans["r2"], chans["r3"]])  # 3 rows, as the F-16's Acceleration
    p = tmp_path / f"lab{suffix}"
    variables = {"Force": chans["force"], "Acceleration": accel, "Fs": np.float64(FS)}
    if suffix == ".npz":
        np.savez(p, **variables)
    else:
        from scipy.io import savemat

        savemat(p, variables)
    back = load_recording(p, channel_map="force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]")
    assert list(back.channels) == ["force", "acc1", "acc2", "acc3"] and back.fs_hz == FS
    for k in (1, 2, 3):
        np.testing.assert_array_equal(back[f"acc{k}"], chans[f"r{k}"])
    assert back.units["acc3"] == "m/s^2"
    with pytest.warns(DataWarning, match=r"ignored variable\(s\) Force"):
        swapped = load_recording(p, channel_map="a3=Acceleration[1],a1=Acceleration[3]")
    np.testing.assert_array_equal(swapped["acc3"], chans["r1"])
    unmapped = load_recording(p)  # a force and one matrix of accelerations: read as the lab wrote them
    assert list(unmapped.channels) == ["force", "acc1", "acc2", "acc3"]
    for k in (1, 2, 3):
        np.testing.assert_array_equal(unmapped[f"acc{k}"], chans[f"r{k}"])


@pytest.mark.parametrize("suffix", [".npz", ".mat"])
def test_realizations_are_read_one_at_a_time(tmp_path, suffix):
    """The F-16 benchmark's odd multisines: ``Acceleration`` channel × realization × time, ``Force`` realization ×
    time; its validation file keeps a realization axis of one (3×1×N)."""
    rng = np.random.default_rng(3)
    force, accel = rng.normal(size=(4, N)), rng.normal(size=(3, 4, N))
    every, one = tmp_path / f"est{suffix}", tmp_path / f"val{suffix}"
    for p, v in ((every, {"Force": force, "Acceleration": accel}),
                 (one, {"Force": force[1:2], "Acceleration": accel[:, 1:2]})):
        v = {**v, "Fs": np.float64(FS)}
        if suffix == ".npz":
            np.savez(p, **v)
        else:
            from scipy.io import savemat

            savemat(p, v)
    rec = load_recording(every, channel_map="force=Force[2],a1=Acceleration[1,2],a2=Acceleration[2,2],"
                                            "a3=Acceleration[3,2]")
    assert list(rec.channels) == ["force", "acc1", "acc2", "acc3"]
    np.testing.assert_array_equal(rec["force"], force[1])
    np.testing.assert_array_equal(rec["acc3"], accel[2, 1])
    for val in (load_recording(one), load_recording(one, channel_map="force=Force,a1=Acceleration[1],"
                                                                        "a2=Acceleration[2],a3=Acceleration[3]")):
        assert list(val.channels) == ["force", "acc1", "acc2", "acc3"]
        np.testing.assert_array_equal(val["acc2"], accel[1, 1])
    whole = load_recording(every)  # without a map: every realisation, one after another
    assert list(whole.channels) == ["force", "acc1", "acc2", "acc3"] and whole.n_samples == 4 * N
    assert (whole.meta["realisations"], whole.meta["realisation_samples"]) == ("4", str(N))
    parts = whole.realisations()
    assert len(parts) == 4 and parts[1].meta["realisation"] == "2"
    np.testing.assert_array_equal(parts[1]["force"], force[1])
    np.testing.assert_array_equal(parts[3]["acc3"], accel[2, 3])
    with pytest.raises(FormatError, match=r"shape 3×4×400: give one index per axis but time \(2\), e\.g\. "
                                          r"Acceleration\[1,1\]"):
        load_recording(every, channel_map="force=Force[1],a1=Acceleration[1]")
    with pytest.raises(FormatError, match=r"acc1=Acceleration\[1,5\]: .* indices run 1\.\.3, 1\.\.4"):
        load_recording(every, channel_map="force=Force[1],a1=Acceleration[1,5]")


def test_a_map_that_names_the_force_whole_reads_every_realisation(tmp_path):
    """``force=Force,a1=Acceleration[1],...`` (the F-16's map) on a file of realisations reads them all, one after
    another, as the file read without a map does (it was refused: "'Force' has shape 4×400, several signals")."""
    rng = np.random.default_rng(5)
    force, accel = rng.normal(size=(4, N)), rng.normal(size=(3, 4, N))
    p = tmp_path / "odd.npz"
    np.savez(p, Force=force, Acceleration=accel, Fs=np.float64(FS))
    mapped = load_recording(p, channel_map="force=Force,a1=Acceleration[3],a2=Acceleration[1]")
    assert list(mapped.channels) == ["force", "acc1", "acc2"] and mapped.meta["realisations"] == "4"
    np.testing.assert_array_equal(mapped.realisations()[2]["acc1"], accel[2, 2])
    np.testing.assert_array_equal(mapped["acc2"], load_recording(p)["acc1"])
    np.savez(p, Force=force, Acceleration=accel.transpose(1, 0, 2), Fs=np.float64(FS))  # realisation × channel
    np.testing.assert_array_equal(load_recording(p, channel_map="force=Force,a1=Acceleration[3]")["acc1"],
                                  accel[2].reshape(-1))
    with pytest.raises(FormatError, match=r"acc1=Acceleration\[4\]: 'Acceleration' has shape 4×3×400: its index "
                                          r"runs 1\.\.3"):
        load_recording(p, channel_map="force=Force,a1=Acceleration[4]")
    np.savez(p, Force=force, Acceleration=accel, Other=rng.normal(size=(3, N)), Fs=np.float64(FS))
    with pytest.raises(FormatError, match=r"acc2=Other: 'Other' has shape 3×400, the force Force 4×400 "
                                          r"\(realisation × time\)"):
        load_recording(p, channel_map="force=Force,a1=Acceleration[1],a2=Other")


def test_realisations_are_read_in_either_axis_order_and_a_mismatch_is_named(tmp_path):
    """Realisation × channel × time reads as channel × realisation × time does; responses with another number of
    realisations than the force are refused, naming both shapes."""
    rng = np.random.default_rng(4)
    force, accel = rng.normal(size=(3, N)), rng.normal(size=(2, 3, N))
    p = tmp_path / "swapped.npz"
    np.savez(p, Force=force, Acceleration=accel.transpose(1, 0, 2), Fs=np.float64(FS))
    rec = load_recording(p)
    assert list(rec.channels) == ["force", "acc1", "acc2"] and rec.meta["realisations"] == "3"
    np.testing.assert_array_equal(rec.realisations()[2]["acc2"], accel[1, 2])
    np.savez(p, Force=force, acc1=accel[0], acc2=accel[1, :2], Fs=np.float64(FS))
    with pytest.raises(FormatError, match=r"'acc2' has shape 2×400, the force 3×400 \(realisation × time\)"):
        load_recording(p)
    np.savez(p, Force=force, Acceleration=rng.normal(size=(2, 5, N)), Fs=np.float64(FS))
    with pytest.raises(FormatError, match=r"'Acceleration' has shape 2×5×400, the force 3×400"):
        load_recording(p)


def test_two_acceleration_matrices_are_asked_about(tmp_path):
    chans = _signals(["force", "r1", "r2", "r3"])
    p = tmp_path / "two.npz"
    np.savez(p, Force=chans["force"], AccWing=np.vstack([chans["r1"], chans["r2"]]),
             AccPayload=np.vstack([chans["r2"], chans["r3"]]), Fs=np.float64(FS))
    with pytest.raises(FormatError, match=r"say which signal is which"):
        load_recording(p)


@pytest.mark.parametrize("suffix", [".npz", ".mat"])
def test_saved_variables_keep_every_accelerometer(tmp_path, suffix):
    chans = _signals(["force", *ACCS])
    back = load_recording(save_recording(Recording(FS, chans), tmp_path / f"r{suffix}"))
    assert list(back.channels) == ["force", *ACCS]
    np.testing.assert_array_equal(back["acc6"], chans["acc6"])


# --- WAV ---------------------------------------------------------------------------------
def test_wav_with_five_channels_and_a_map(tmp_path):
    from scipy.io import wavfile

    chans = _signals(["force", "acc1", "acc2", "acc3", "acc4"])
    p = tmp_path / "five.wav"
    wavfile.write(p, int(FS), np.column_stack([v / 10 for v in chans.values()]))  # float, within ±1
    plain = _quiet(load_recording, p)
    assert list(plain.channels) == ["ch1", "ch2", "ch3", "ch4", "ch5"]  # more than 3: named only by a map
    back = _quiet(load_recording, p, channel_map="force=#1,a1=#2,a2=#3,a3=#4,a4=#5")
    assert list(back.channels) == ["force", "acc1", "acc2", "acc3", "acc4"]
    np.testing.assert_array_equal(back["acc4"], chans["acc4"] / 10)
    scaled = _quiet(load_recording, p, channel_map="force=#1,a4=#5", scale={"acc4": 10.0})
    np.testing.assert_allclose(scaled["acc4"], chans["acc4"], rtol=1e-15)
    assert scaled.units["acc4"] == "m/s^2" and scaled.units["ch2"] == "as stored"


def test_wav_written_by_satmd_keeps_its_names(tmp_path):
    chans = _signals(["acc10", "force", *ACCS])
    back = load_recording(save_recording(Recording(FS, chans), tmp_path / "r.wav"))
    assert list(back.channels) == ["force", *ACCS, "acc10"]
    np.testing.assert_array_equal(back["acc10"], chans["acc10"])
    assert back.units["acc10"] == "m/s^2"


# --- UFF ---------------------------------------------------------------------------------
def test_uff_written_by_satmd_keeps_every_accelerometer(tmp_path):
    chans = _signals(["force", *ACCS])
    p = save_recording(Recording(FS, chans), tmp_path / "r.uff")
    back = load_recording(p)
    assert list(back.channels) == ["force", *ACCS] and back.units["acc5"] == "m/s^2"
    np.testing.assert_array_equal(back["acc5"], chans["acc5"])
    mapped = load_recording(p, channel_map="force=#1,a1=6:+Z,a3=#3")  # acc<N> is written at node N, +Z
    np.testing.assert_array_equal(mapped["acc1"], chans["acc6"])
    np.testing.assert_array_equal(mapped["acc3"], chans["acc2"])


def test_uff_from_other_software_mapped_to_five_accelerometers(tmp_path):
    pyuff = pytest.importorskip("pyuff")
    t = np.arange(256) / 256.0
    chans = _signals(["force", "acc1", "acc2", "acc3", "acc4", "acc5"], n=256)

    def rec58(data, node, spec, unit):
        return pyuff.prepare_58(binary=1, func_type=1, rsp_node=node, rsp_dir=3, ref_node=0, ref_dir=0, data=data,
                                x=t, id1="daq", abscissa_spacing=1, abscissa_spec_data_type=17,
                                ordinate_spec_data_type=spec, orddenom_spec_data_type=0,
                                ordinate_axis_units_lab=unit, abscissa_axis_units_lab="s")

    p = tmp_path / "daq.uff"
    sets = [rec58(chans["force"], 100, 13, "N")]
    sets += [rec58(chans[f"acc{k}"] / 9.80665, 10 + k, 12, "g") for k in range(1, 6)]
    pyuff.UFF(str(p)).write_sets(sets, mode="add")
    assert list(load_recording(p).channels) == [f"ch{k}" for k in range(1, 7)]  # 5 responses: no guess
    back = load_recording(p, channel_map="force=#1," + ",".join(f"a{k}=1{k}:+Z" for k in range(1, 6)))
    assert set(back.channels) == {"force", "acc1", "acc2", "acc3", "acc4", "acc5"}
    for k in range(1, 6):
        np.testing.assert_allclose(back[f"acc{k}"], chans[f"acc{k}"], rtol=1e-12)
        assert back.units[f"acc{k}"] == "m/s^2"


# --- bad maps: one line, naming the file and the entry ------------------------------------
def _refused(path, channel_map, entry, why):
    with pytest.raises(FormatError) as caught:
        _quiet(load_recording, path, channel_map=channel_map)
    text = str(caught.value)
    assert "\n" not in text and str(path) in text and entry in text and why in text, text


def test_bad_maps_are_refused_in_one_line(tmp_path):
    from scipy.io import wavfile

    chans = _signals(["force", "acc1", "acc2", "acc3"])
    wav = tmp_path / "r.wav"
    wavfile.write(wav, int(FS), np.column_stack([v / 10 for v in chans.values()]))
    uff = save_recording(Recording(FS, chans), tmp_path / "r.uff")
    npz = tmp_path / "r.npz"
    np.savez(npz, Force=chans["force"], Acceleration=np.vstack([chans["acc1"], chans["acc2"]]), fs_hz=FS)
    lab = tmp_path / "lab.csv"
    np.savetxt(lab, np.column_stack([np.arange(N) / FS, *chans.values()]), delimiter=",",
               header="time,Force,Wing,Tail,Nose", comments="", fmt="%.17g")
    for path, source, other in ((wav, "#2", "#3"), (uff, "#2", "#3"), (npz, "Acceleration[1]", "Acceleration[2]"),
                                (lab, "Wing", "Tail")):
        _refused(path, f"force={other},a0={source}", f"a0={source}", "numbered from 1")
        _refused(path, f"acc0={source}", f"acc0={source}", "numbered from 1")
        _refused(path, f"accx={source}", f"accx={source}", "a<N> or acc<N>")
        _refused(path, f"a3x={source}", f"a3x={source}", "a<N> or acc<N>")
        _refused(path, f"a3={source},acc3={other}", f"acc3={other}", "given twice")
        _refused(path, f"a3={source},a4={source}", f"a4={source}", source)  # one signal cannot be two channels


# --- the F-16's three accelerometers ------------------------------------------------------
@needs_real("f16", "F16Data_FullMSine_Level1.mat")
def test_f16_reads_all_three_accelerometers():
    path = real_data("f16", "F16Data_FullMSine_Level1.mat")
    with pytest.warns(DataWarning, match="ignored variable.*Voltage"):
        rec = load_recording(path, channel_map="force=Force,a1=Acceleration[1],a2=Acceleration[2],"
                                               "a3=Acceleration[3]")
    assert list(rec.channels) == ["force", "acc1", "acc2", "acc3"]
    assert rec.fs_hz == pytest.approx(400.0) and rec.n_samples == 9 * 8192
    old = _quiet(load_recording, path, channel_map="force=Force,a1=Acceleration[2],a2=Acceleration[3]")
    np.testing.assert_array_equal(rec["acc3"], old["acc2"])  # the third accelerometer, as the old map read it
    np.testing.assert_array_equal(rec["acc2"], old["acc1"])
    assert not np.array_equal(rec["acc1"], rec["acc2"]) and np.std(rec["acc1"]) > 0
    assert rec.units == {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2", "acc3": "m/s^2"}


# --- satmd info lists every channel --------------------------------------------------------
def test_info_lists_every_channel(tmp_path, capsys):
    p = save_recording(Recording(FS, _signals(["force", *ACCS])), tmp_path / "gvt.csv")
    assert main(["info", str(p)]) == 0
    out = capsys.readouterr().out
    assert "7 channel(s)" in out
    for name in ("force", *ACCS):
        assert f"\n  {name} " in out, (name, out)
    assert "acc3, acc4, acc5, acc6: read; a rig's FRFs are acc1's and acc2's, a structure's every channel's" in out
    assert "--channels all -o FRFs.csv" in out

"""UFF 58 / 58b: exact round trip of satmd's FRFs, third-party files, mapping, units, damage."""
from __future__ import annotations

import numpy as np
import pytest

from satmd import FRFData, simulate
from satmd.errors import FormatError
from satmd.io import DataWarning, load_frf, save_frf
from satmd.io.uff import read_records

pyuff = pytest.importorskip("pyuff")


def _full_data():
    d = simulate(channels=("a1", "a2", "u1", "u2", "q"), noise=0.01, seed=3)
    coh = {"a1": np.linspace(0.2, 1.0, len(d)), "a2": np.full(len(d), 0.97)}
    return FRFData(d.freq_hz, d.channels, d.std, d.meta, coherence=coh)


def test_binary_round_trip_is_exact(tmp_path):
    d = _full_data()
    p = save_frf(d, tmp_path / "frf.uff")
    r = load_frf(p)
    assert np.array_equal(r.freq_hz, d.freq_hz)
    assert r.names == d.names
    for ch in d.names:
        assert np.array_equal(r[ch], d[ch])
        assert np.array_equal(r.std[ch], d.std[ch])
    for ch in d.coherence:
        assert np.array_equal(r.coherence[ch], d.coherence[ch])
    assert r.coherence.keys() == d.coherence.keys()


def test_unv_suffix_and_ascii_keep_13_digits(tmp_path):
    d = _full_data()
    p = save_frf(d, tmp_path / "frf.unv", binary=False)
    assert b"58b" not in p.read_bytes()[:200]  # really ASCII
    r = load_frf(p)
    np.testing.assert_allclose(r.freq_hz, d.freq_hz, rtol=1e-5)  # abscissa: 6 digits in the format
    for ch in d.names:
        np.testing.assert_allclose(r[ch], d[ch], rtol=1e-11, atol=1e-11 * np.abs(d[ch]).max())


def test_pyuff_reads_our_file_as_standard_frfs(tmp_path):
    p = save_frf(simulate(), tmp_path / "frf.uff")
    sets = pyuff.UFF(str(p)).read_sets()
    assert [s["func_type"] for s in sets] == [4, 4]
    assert [(s["rsp_node"], s["rsp_dir"]) for s in sets] == [(1, 3), (2, 3)]
    assert sets[0]["ordinate_axis_units_lab"] == "m/s^2" and sets[0]["orddenom_axis_units_lab"] == "N"
    np.testing.assert_array_equal(sets[1]["data"], simulate()["a2"])
    # the 58b header's byte count is what follows it (pyuff's own writer gets this wrong)
    header = p.read_bytes().split(b"\n")[1]
    assert int(header[31:43]) == 60 * 3 * 8


# --- files written by other software (pyuff's writer) ------------------------------
def _third_party(path, records, binary=0):
    """records: list of dicts with data, rsp, ref, units (ordinate, denominator), func_type, x."""
    f = np.linspace(40.0, 130.0, 31)
    sets = []
    for r in records:
        x = r.get("x", f)
        sets.append(pyuff.prepare_58(
            binary=binary, func_type=r.get("func_type", 4), rsp_node=r["rsp"][0], rsp_dir=r["rsp"][1],
            ref_node=r.get("ref", (1, 3))[0], ref_dir=r.get("ref", (1, 3))[1], data=r["data"], x=x,
            id1=r.get("id1", "test"), rsp_ent_name="pt", ref_ent_name="pt", abscissa_spacing=0,
            abscissa_spec_data_type=18, ordinate_spec_data_type=r.get("spec", 12), orddenom_spec_data_type=13,
            ordinate_axis_units_lab=r.get("units", ("m/s^2", "N"))[0],
            orddenom_axis_units_lab=r.get("units", ("m/s^2", "N"))[1]))
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
    return f


def _model(f):
    return simulate(f, channels=("a1", "a2", "u1", "u2"))


def test_two_responses_map_automatically_to_a1_a2(tmp_path):
    f = np.linspace(40.0, 130.0, 31)
    m = _model(f)
    p = tmp_path / "lab.uff"
    _third_party(p, [{"data": m["a1"], "rsp": (5, 3)}, {"data": m["a2"], "rsp": (9, 3)}])
    d = load_frf(p)
    assert d.names == ("a1", "a2")
    # pyuff's ASCII writer keeps 12 digits, and writes the uneven abscissa with 6
    np.testing.assert_allclose(d["a2"], m["a2"], rtol=1e-9)
    np.testing.assert_allclose(d.freq_hz, f, rtol=1e-5)


def test_units_directions_and_quantities_are_converted(tmp_path):
    f = np.linspace(40.0, 130.0, 31)
    m = _model(f)
    p = tmp_path / "lab.uff"
    _third_party(p, [
        {"data": m["a1"] / 9.80665 * 4.4482216152605, "rsp": (1, 3), "units": ("g", "lbf")},  # g/lbf
        {"data": -m["u2"] * 1e3, "rsp": (2, -3), "spec": 8, "units": ("mm", "N")},  # -Z, displacement in mm
        {"data": m["a1"], "rsp": (3, 3), "units": ("(m/s^2)/N", "NONE")},  # the whole FRF unit in one label
    ])
    d = load_frf(p, channel_map="a1=1:+Z,a2=2:3")
    np.testing.assert_allclose(d["a1"], m["a1"], rtol=1e-9)
    np.testing.assert_allclose(d["a2"], m["a2"], rtol=2e-5)  # A = -ω² U, ω from the 6-digit abscissa
    d2 = load_frf(p, channel_map="u2=#2,a1=#3")
    np.testing.assert_allclose(d2["u2"], m["u2"], rtol=1e-9)
    np.testing.assert_allclose(d2["a1"], m["a1"], rtol=1e-9)


def test_mapping_errors_are_one_line(tmp_path):
    f = np.linspace(40.0, 130.0, 31)
    m = _model(f)
    p = tmp_path / "lab.uff"
    _third_party(p, [{"data": m["a1"], "rsp": (1, 3)}, {"data": m["a2"], "rsp": (2, 3)},
                     {"data": m["a2"], "rsp": (2, 3), "ref": (4, 3)}])
    with pytest.raises(FormatError, match="3 FRF records .* channel_map a1=NODE:DIR"):
        load_frf(p)
    with pytest.raises(FormatError, match="2 FRF records match .* a2=#N"):
        load_frf(p, channel_map="a1=1:3,a2=2:3")
    with pytest.raises(FormatError, match="no FRF record with that response"):
        load_frf(p, channel_map="a1=7:3")
    with pytest.raises(FormatError, match="unknown channel 'a3'"):
        load_frf(p, channel_map="a3=1:3")
    with pytest.raises(FormatError, match="direction"):
        load_frf(p, channel_map="a1=1:Q")
    with pytest.warns(DataWarning, match="different reference DOFs"):
        d = load_frf(p, channel_map="a1=#1,a2=#3")
    assert d.names == ("a1", "a2")


def test_one_response_is_a1_with_a_warning_and_dc_is_dropped(tmp_path):
    f = np.linspace(0.0, 130.0, 27)
    m = _model(f[1:])
    p = tmp_path / "one.uff"
    _third_party(p, [{"data": np.concatenate([[0.0], m["a1"]]).astype(complex), "rsp": (1, 3), "x": f}])
    with pytest.warns(DataWarning) as caught:
        d = load_frf(p)
    messages = " ".join(str(w.message) for w in caught)
    assert "read as a1" in messages and "f <= 0 Hz" in messages
    assert d.names == ("a1",) and len(d) == 26


def test_coherence_records_of_other_software_are_attached(tmp_path):
    f = np.linspace(40.0, 130.0, 31)
    m = _model(f)
    p = tmp_path / "coh.uff"
    coh = np.linspace(0.5, 1.0, 31)
    _third_party(p, [{"data": m["a1"], "rsp": (1, 3)}, {"data": m["a2"], "rsp": (2, 3)},
                     {"data": coh, "rsp": (2, 3), "func_type": 6, "spec": 0, "units": ("NONE", "NONE")}])
    d = load_frf(p)
    assert list(d.coherence) == ["a2"]
    np.testing.assert_allclose(d.coherence["a2"], coh, rtol=1e-9)


def test_time_records_and_wrong_function_types_are_refused(tmp_path):
    t = np.arange(64) / 64.0
    p = tmp_path / "time.uff"
    sets = [pyuff.prepare_58(binary=1, func_type=1, rsp_node=1, rsp_dir=3, ref_node=0, ref_dir=0,
                             data=np.sin(9 * t), x=t, id1="acc", abscissa_spacing=1, abscissa_spec_data_type=17,
                             ordinate_spec_data_type=12, orddenom_spec_data_type=0)]
    pyuff.UFF(str(p)).write_sets(sets, mode="add")  # pyuff's binary writer breaks "overwrite"
    with pytest.raises(FormatError, match="time record.*satmd estimate-frf"):
        load_frf(p)
    p2 = tmp_path / "psd.uff"
    sets = [pyuff.prepare_58(binary=0, func_type=2, rsp_node=1, rsp_dir=3, ref_node=1, ref_dir=3,
                             data=np.abs(np.sin(9 * t)) + 1.0, x=t + 1.0, id1="psd", abscissa_spacing=1,
                             abscissa_spec_data_type=18, ordinate_spec_data_type=12, orddenom_spec_data_type=0)]
    pyuff.UFF(str(p2)).write_sets(sets, mode="overwrite")
    with pytest.raises(FormatError, match="no FRF records .* auto spectrum"):
        load_frf(p2)


def test_damaged_files_give_one_line_errors(tmp_path):
    good = save_frf(simulate(), tmp_path / "good.uff").read_bytes()
    cases = {
        "truncated": (good[: len(good) // 4], "truncated"),
        "empty": (b"", "empty file"),
        "garbage": (bytes(range(256)) * 3, "not a universal file"),
        "text": (b"hello\nworld\n", "not a universal file"),
    }
    # a header declaring more points than the binary data hold
    lines = good.split(b"\n")
    lines[8] = lines[8][:10] + b"%10d" % 61 + lines[8][20:]
    cases["count"] = (b"\n".join(lines), "declares 61 points, the data hold 60")
    ascii_ = save_frf(simulate(), tmp_path / "a.unv", binary=False).read_bytes()
    lines = ascii_.split(b"\n")
    lines[13] = b"%20s" % b"nan" + lines[13][20:]  # the first value of dataset 1
    cases["nan"] = (b"\n".join(lines), "NaN or infinite value at point 1")
    for name, (content, match) in cases.items():
        p = tmp_path / f"{name}.uff"
        p.write_bytes(content)
        with pytest.raises(FormatError, match=match) as info:
            load_frf(p)
        assert "\n" not in str(info.value) and str(info.value).startswith(str(p)), name


def test_read_records_lists_every_dataset(tmp_path):
    p = save_frf(_full_data(), tmp_path / "frf.uff")
    records, others = read_records(p)
    assert others == []
    assert [r.tag for r in records] == ["a1", "a1_std", "a1_coh", "a2", "a2_std", "a2_coh", "u1", "u1_std",
                                        "u2", "u2_std", "q", "q_std"]
    assert {r.func_type for r in records} == {0, 4, 6}
    assert records[0].line == 1 and records[1].line > 1

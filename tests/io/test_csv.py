"""The `satmd-frf v1` CSV format (SPEC §7): exact round trip and strict refusal."""
from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from satmd.errors import FormatError
from satmd.io import CHANNELS, FRFData, load_frf, save_frf
from satmd.io.csvfrf import read_csv, write_csv

# every finite double, subnormals included; -0.0 is mapped to +0.0 here (signed zeros: see below)
finite = st.floats(allow_nan=False, allow_infinity=False).map(lambda x: x + 0.0)


def _complex(re, im):
    """Complex array with exactly these real and imaginary bits (re + 1j*im can lose a -0.0)."""
    z = np.empty(len(re), dtype=complex)
    z.real, z.imag = re, im
    return z


def _bits_equal(a, b):
    a, b = np.asarray(a), np.asarray(b)
    assert a.dtype == b.dtype and a.shape == b.shape
    assert a.tobytes() == b.tobytes()


def _assert_same(a: FRFData, b: FRFData):
    _bits_equal(a.freq_hz, b.freq_hz)
    assert list(a.channels) == list(b.channels)
    for c in a.channels:
        _bits_equal(a.channels[c], b.channels[c])
    assert set(a.std) == set(b.std)
    for c in a.std:
        _bits_equal(a.std[c], b.std[c])


@st.composite
def frf_data(draw):
    n = draw(st.integers(1, 12))
    freq = np.array(sorted(draw(st.lists(st.floats(1e-3, 1e6), min_size=n, max_size=n, unique=True))))
    names = draw(st.lists(st.sampled_from(CHANNELS), min_size=1, max_size=5, unique=True))
    chans = {c: _complex(draw(st.lists(finite, min_size=n, max_size=n)), draw(st.lists(finite, min_size=n, max_size=n)))
             for c in names}
    with_std = draw(st.lists(st.sampled_from(names), unique=True))  # none, some or all channels
    std = {c: np.array(draw(st.lists(st.floats(0, 1e300), min_size=n, max_size=n))) for c in with_std}
    return FRFData(freq, chans, std)


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=frf_data())
def test_round_trip_is_bitwise_exact(tmp_path, data):
    path = tmp_path / "rt.csv"
    save_frf(data, path)
    _assert_same(load_frf(path), data)


def test_round_trip_all_five_channels_with_and_without_std(tmp_path):
    rng = np.random.default_rng(0)
    freq = np.linspace(40.0, 130.0, 60)
    chans = {c: rng.standard_normal(60) * 10.0 ** rng.uniform(-12, 3, 60)
             + 1j * rng.standard_normal(60) * 10.0 ** rng.uniform(-12, 3, 60) for c in CHANNELS}
    chans["a1"][3] = 0.0
    chans["a2"][5] = complex(5e-324, -1.7976931348623157e308)  # subnormal and the largest double
    chans["u1"][7] = complex(2.2250738585072014e-308, -4.9406564584124654e-324)
    std = {c: np.abs(chans[c]) * 1e-3 for c in CHANNELS}
    for s in (std, {}):
        data = FRFData(freq, chans, s, {"note": "round trip"})
        path = tmp_path / f"all{len(s)}.csv"
        save_frf(data, path)
        back = load_frf(path)
        _assert_same(back, data)
        assert back.meta["note"] == "round trip"
        assert back.has_std == bool(s)
    text = (tmp_path / "all5.csv").read_text().splitlines()
    assert text[0] == "# satmd-frf v1"
    header = next(line for line in text if not line.startswith("#"))
    assert header.startswith("freq_hz,")
    assert {f"{c}_{p}" for c in CHANNELS for p in ("re", "im", "std")} == set(header.split(",")[1:])


def test_round_trip_keeps_signed_zeros(tmp_path):
    data = FRFData([40.0, 50.0, 60.0], {"a1": _complex([-0.0, 0.0, -0.0], [0.0, -0.0, -0.0])})
    path = tmp_path / "zeros.csv"
    save_frf(data, path)
    assert path.read_text().splitlines()[-3:] == ["40,-0,0", "50,0,-0", "60,-0,-0"]  # the writer keeps them
    _assert_same(load_frf(path), data)


def test_reader_accepts_comments_blank_lines_and_any_column_order(tmp_path):
    path = tmp_path / "ok.csv"
    path.write_text("# satmd-frf v1\n# a comment\n\nfreq_hz,a2_im,a2_re,a2_std\n"
                    "40,1e-3,-2e-3,1e-5\n# interleaved comment\n50.5,3,4,0\n")
    d = read_csv(path)
    np.testing.assert_array_equal(d.freq_hz, [40.0, 50.5])
    np.testing.assert_array_equal(d["a2"], [-2e-3 + 1e-3j, 4 + 3j])
    np.testing.assert_array_equal(d.std["a2"], [1e-5, 0.0])
    assert d.names == ("a2",)


# ------------------------------------------------------------- malformations
HEADER = "freq_hz,a1_re,a1_im,a2_re,a2_im,a1_std,a2_std"
GOOD_ROWS = ["40.0,1e-3,2e-3,3e-3,4e-3,1e-5,1e-5", "50.0,1e-3,2e-3,3e-3,4e-3,1e-5,1e-5",
             "60.0,1e-3,2e-3,3e-3,4e-3,1e-5,1e-5"]


def _file(header=HEADER, rows=GOOD_ROWS, magic="# satmd-frf v1"):
    lines = ([magic] if magic is not None else []) + [header] + list(rows)
    return "\n".join(lines) + "\n"


def _row(k, col, value):
    cells = GOOD_ROWS[k].split(",")
    cells[col] = value
    return ",".join(cells)


def _rows_with(k, col, value):
    rows = list(GOOD_ROWS)
    rows[k] = _row(k, col, value)
    return rows


# (id, file text, expected line, expected column text or None, words in the message)
MALFORMED = [
    ("missing_im_column", _file("freq_hz,a1_re,a2_re,a2_im", ["40,1,2,3"]), 2, None, ["a1_im"]),
    ("missing_re_column", _file("freq_hz,q_im", ["40,1"]), 2, None, ["q_re"]),
    ("nan", _file(rows=_rows_with(1, 3, "nan")), 4, "4 (a2_re)", ["finite"]),
    ("NaN_in_std", _file(rows=_rows_with(0, 6, "NaN")), 3, "7 (a2_std)", ["finite"]),
    ("inf", _file(rows=_rows_with(2, 2, "inf")), 5, "3 (a1_im)", ["finite"]),
    ("minus_infinity", _file(rows=_rows_with(2, 1, "-Infinity")), 5, "2 (a1_re)", ["finite"]),
    ("inf_frequency", _file(rows=_rows_with(2, 0, "inf")), 5, "1 (freq_hz)", ["finite"]),
    ("non_increasing_frequency", _file(rows=_rows_with(2, 0, "45.0")), 5, "1 (freq_hz)", ["increasing"]),
    ("repeated_frequency", _file(rows=_rows_with(1, 0, "40.0")), 4, "1 (freq_hz)", ["increasing"]),
    ("zero_frequency", _file(rows=_rows_with(0, 0, "0")), 3, "1 (freq_hz)", ["> 0"]),
    ("negative_frequency", _file(rows=_rows_with(0, 0, "-40")), 3, "1 (freq_hz)", ["> 0"]),
    ("negative_std", _file(rows=_rows_with(1, 5, "-1e-5")), 4, "6 (a1_std)", ["negative std"]),
    ("unknown_channel", _file("freq_hz,a1_re,a1_im,a3_re,a3_im", ["40,1,2,3,4"]), 2, "4", ["unknown channel", "a3"]),
    ("bad_column_name", _file("freq_hz,a1_re,a1_imag", ["40,1,2"]), 2, "3", ["bad column name", "a1_imag"]),
    ("bare_channel_name", _file("freq_hz,a1,a1_re,a1_im", ["40,1,2,3"]), 2, "2", ["bad column name"]),
    ("empty_column_name", _file("freq_hz,a1_re,a1_im,", ["40,1,2,"]), 2, "4", ["bad column name"]),
    ("duplicate_column", _file("freq_hz,a1_re,a1_im,a1_re", ["40,1,2,3"]), 2, "4", ["duplicate", "a1_re"]),
    ("first_column_not_freq", _file("f,a1_re,a1_im", ["40,1,2"]), 2, "1", ["freq_hz"]),
    ("no_channels", _file("freq_hz", ["40"]), 2, None, ["no channel"]),
    ("too_few_fields", _file(rows=[GOOD_ROWS[0], "50.0,1e-3,2e-3", GOOD_ROWS[2]]), 4, None, ["3 fields", "7"]),
    ("too_many_fields", _file(rows=[GOOD_ROWS[0], GOOD_ROWS[1] + ",9"]), 4, None, ["8 fields", "7"]),
    ("not_a_number", _file(rows=_rows_with(1, 2, "abc")), 4, "3 (a1_im)", ["not a number", "abc"]),
    ("empty_cell", _file(rows=_rows_with(0, 4, "")), 3, "5 (a2_im)", ["not a number"]),
    ("complex_literal", _file(rows=_rows_with(0, 1, "1+2j")), 3, "2 (a1_re)", ["not a number"]),
    ("header_only", _file(rows=[]), 2, None, ["no data rows"]),
    ("comments_only", "# satmd-frf v1\n# nothing else\n", None, None, ["no column header"]),
    ("unsupported_version", _file(magic="# satmd-frf v2"), 1, None, ["unsupported", "v2"]),
    ("version_with_junk", _file(magic="# satmd-frf v1 beta"), 1, None, ["unsupported"]),
    ("late_version_line", _file(rows=GOOD_ROWS[:1] + ["# satmd-frf v9"] + GOOD_ROWS[1:]), 4, None, ["unsupported"]),
]


@pytest.mark.parametrize("name, text, line, column, words", MALFORMED, ids=[m[0] for m in MALFORMED])
def test_malformed_file_is_refused_with_file_line_and_column(tmp_path, name, text, line, column, words):
    path = tmp_path / f"{name}.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FormatError) as info:
        load_frf(path)
    err = info.value
    msg = str(err)
    assert "\n" not in msg and "\r" not in msg
    assert msg.startswith(str(path))
    if line is not None:
        assert err.line == line and re.search(rf", line {line}[,:] ", msg), msg
    if column is not None:
        assert str(err.column) == column and f"column {column}" in msg, msg
    for w in words:
        assert w in msg, msg
    assert isinstance(err, ValueError)  # the CLI's one-line error path


@pytest.mark.parametrize("name, payload", [
    ("empty", b""),
    ("whitespace", b"  \n\n\t\n"),
    ("invalid_utf8", b"# satmd-frf v1\nfreq_hz,a1_re,a1_im\n40,1,\xff\xfe\x00\x81\n"),
    ("nul_bytes", b"freq_hz,a1_re,a1_im\n40,1,2\x00\x00\n"),
    ("random_binary", bytes(np.random.default_rng(0).integers(0, 256, 4096, dtype=np.uint8))),
    ("gzip_magic", b"\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\x03" + bytes(range(256))),
    ("utf16_text", "# satmd-frf v1\nfreq_hz,a1_re,a1_im\n40,1,2\n".encode("utf-16")),
])
def test_empty_and_binary_files_are_refused(tmp_path, name, payload):
    path = tmp_path / f"{name}.csv"
    path.write_bytes(payload)
    with pytest.raises(FormatError) as info:
        load_frf(path)
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith(str(path))
    if name in ("empty", "whitespace"):
        assert "empty" in msg


def test_missing_file_directory_and_unknown_suffix(tmp_path):
    for path, word in [(tmp_path / "nope.csv", "no such file"), (tmp_path, "directory")]:
        with pytest.raises(FormatError, match=word):
            load_frf(path)
    other = tmp_path / "data.xyz"
    other.write_text(_file())
    with pytest.raises(FormatError, match="unknown file type"):
        load_frf(other)


def test_save_refuses_unknown_suffix_and_missing_folder(tmp_path):
    data = FRFData([40.0, 50.0], {"a1": [1 + 1j, 2 + 2j]})
    with pytest.raises(FormatError):
        save_frf(data, tmp_path / "x.txt")
    with pytest.raises(FormatError, match="does not exist"):
        save_frf(data, tmp_path / "no" / "x.csv")
    assert not (tmp_path / "x.txt").exists()


def test_writer_replaces_atomically(tmp_path):
    path = tmp_path / "out.csv"
    a = FRFData([40.0, 50.0], {"a1": [1 + 1j, 2 + 2j]})
    b = FRFData([41.0, 51.0, 61.0], {"q": [1j, 2j, 3j]}, {"q": [0.1, 0.2, 0.3]})
    write_csv(a, path)
    write_csv(b, path)
    _assert_same(read_csv(path), b)
    assert [p.name for p in tmp_path.iterdir()] == ["out.csv"]  # no temporary left behind


def test_metadata_keys_with_colons_survive(tmp_path):
    data = FRFData([40.0, 50.0], {"a1": np.array([1 + 1j, 2 - 1j])},
                   meta={"effect parameter_offset:k1": "value=200000"})
    path = tmp_path / "meta.csv"
    save_frf(data, path)
    assert load_frf(path).meta["effect parameter_offset:k1"] == "value=200000"

"""CLI: simulate --time, info, estimate-frf, and data options shared by every data command."""
from __future__ import annotations

import argparse

import numpy as np
import pytest

from satmd.cli import main
from satmd.cli._common import load_data
from satmd.io import load_frf, load_recording


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    path = tmp_path_factory.mktemp("cli") / "rec.csv"
    assert main(["simulate", "--time", "--duration", "12", "--fs", "500", "--noise", "0.02", "--seed", "3",
                 "-o", str(path)]) == 0
    return path


def run(capsys, *argv):
    rc = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


def test_simulate_time_writes_a_recording(recording):
    rec = load_recording(recording)
    assert list(rec.channels) == ["force", "acc1", "acc2"]
    assert rec.fs_hz == 500.0 and rec.n_samples == 6000
    assert rec.meta["noise"] == "0.02" and rec.meta["seed"] == "3"


def test_simulate_time_to_uff_and_options_checked(capsys, tmp_path):
    rc, out, _ = run(capsys, "simulate", "--time", "--duration", "2", "--fs", "400", "--force-band", "30:150",
                     "--R", "40", "-o", tmp_path / "r.uff")
    assert rc == 0 and "800 samples at 400 Hz" in out
    assert load_recording(tmp_path / "r.uff").meta["format"] == "UFF 58 time records"
    rc, _, err = run(capsys, "simulate", "--time", "--fs", "200", "--force-band", "20:150", "-o", tmp_path / "x.csv")
    assert rc == 2 and "fs/2" in err and len(err.strip().splitlines()) == 1
    rc, _, err = run(capsys, "simulate", "--time", "--noise", "0.1:0.2", "-o", tmp_path / "x.csv")
    assert rc == 2 and "REL only" in err


def test_info_on_recording_and_frf_files(capsys, recording, tmp_path):
    rc, out, _ = run(capsys, "info", recording)
    assert rc == 0
    assert "time recording: 3 channel(s), 500 Hz, 6000 samples (12 s)" in out
    assert "force  [N]" in out and "estimate-frf" in out
    assert run(capsys, "simulate", "--noise", "0.01", "--seed", "1", "-o", tmp_path / "f.uff")[0] == 0
    rc, out, _ = run(capsys, "info", tmp_path / "f.uff")
    assert rc == 0 and "4 of type 58" in out and "FRF" in out and "FRFs: 60 points, 40..130 Hz" in out
    assert "std median" in out


def test_estimate_frf_writes_frfs_with_std_and_a_plot(capsys, recording, tmp_path):
    out_csv, fig = tmp_path / "frf.csv", tmp_path / "fig.png"
    rc, out, _ = run(capsys, "estimate-frf", recording, "-o", out_csv, "--band", "30:150", "--nperseg", "1024",
                     "--plot", fig)
    assert rc == 0 and "FRFs a1, a2" in out and "nperseg=1024" in out
    d = load_frf(out_csv)
    assert d.has_std and 30 <= d.freq_hz[0] and d.freq_hz[-1] <= 150
    assert fig.stat().st_size > 10_000
    # coherence travels in UFF (and .npz/.mat), not in the SPEC §7 CSV
    rc, _, _ = run(capsys, "estimate-frf", recording, "-o", tmp_path / "frf.uff", "--estimator", "H2")
    u = load_frf(tmp_path / "frf.uff")
    assert rc == 0 and set(u.coherence) == {"a1", "a2"} and u.meta["format"] == "UFF 58 (satmd)"


def test_estimate_frf_output_only_gives_transmissibility(capsys, recording, tmp_path):
    rec = load_recording(recording)
    oo = tmp_path / "oo.npz"
    np.savez(oo, fs_hz=rec.fs_hz, acc1=rec["acc1"], acc2=rec["acc2"])
    rc, out, _ = run(capsys, "estimate-frf", oo, "-o", tmp_path / "t.csv", "--band", "40:130", "--plot",
                     tmp_path / "t.png")
    assert rc == 0 and "transmissibility A2/A1" in out
    text = (tmp_path / "t.csv").read_text()
    assert text.startswith("# satmd-transmissibility v1") and "freq_hz,t_re,t_im,t_std,coherence" in text
    rc, _, err = run(capsys, "estimate-frf", oo, "-o", tmp_path / "t.uff")
    assert rc == 2 and "written as .csv" in err


def test_errors_are_one_line_with_status_2(capsys, tmp_path):
    garbage = tmp_path / "g.uff"
    garbage.write_bytes(bytes(range(256)) * 4)
    empty = tmp_path / "e.wav"
    empty.write_bytes(b"")
    frf = tmp_path / "f.csv"
    assert run(capsys, "simulate", "-o", frf)[0] == 0
    for argv in (["info", garbage], ["info", tmp_path / "missing.csv"], ["estimate-frf", empty, "-o", "x.csv"],
                 ["estimate-frf", frf, "-o", tmp_path / "x.csv"], ["info", frf, "--map", "a1=1:3"]):
        rc, _, err = run(capsys, *argv)
        assert rc == 2, argv
        assert len(err.strip().splitlines()) == 1 and err.startswith(f"satmd {argv[0]}: error: "), err


def _args(data, **kw):
    ns = argparse.Namespace(data=str(data), band=None, map=None, freq_axis=None, command="test")
    for k, v in kw.items():
        setattr(ns, k, v)
    return ns


def test_load_data_accepts_every_format_and_a_band(capsys, recording, tmp_path):
    assert main(["simulate", "--noise", "0.01", "--seed", "2", "-o", str(tmp_path / "f.csv")]) == 0
    base = load_frf(tmp_path / "f.csv")
    for suffix in (".uff", ".npz", ".mat"):
        assert main(["simulate", "--noise", "0.01", "--seed", "2", "-o", str(tmp_path / f"f{suffix}")]) == 0
        d = load_data(_args(tmp_path / f"f{suffix}", band="50:100"))
        np.testing.assert_array_equal(d["a1"], base.band(50, 100)["a1"])
    capsys.readouterr()
    d = load_data(_args(recording, band="40:130"))  # a recording: FRFs estimated on the fly
    assert "is a time recording" in capsys.readouterr().err
    assert d.has_std and d.freq_hz[0] >= 40 and d.freq_hz[-1] <= 130
    txt = tmp_path / "v.txt"
    txt.write_text("\n".join(str(complex(1.0, k)) for k in range(5)))
    d = load_data(_args(txt, freq_axis="0:10"))
    assert "dropped 1 point" in capsys.readouterr().err and list(d.freq_hz) == [10.0, 20.0, 30.0, 40.0]


def test_identify_takes_a_recording(capsys, recording):
    pytest.importorskip("satmd.identification")
    rc, out, err = run(capsys, "identify", recording, "--band", "30:150", "--json")
    assert rc == 0 and "is a time recording" in err
    import json

    values = json.loads(out)
    assert values  # the identify command's own output; its content is tested with identify


def test_discover_on_a_recording_is_the_librarys_discover(capsys, tmp_path):
    """The CLI calls the library and nothing else (issue 36): one recording, one path, one report."""
    import json

    import satmd
    from satmd.io import load_recording

    from ._cli import run

    path = tmp_path / "rec.csv"
    assert run(capsys, "simulate", "--time", "--duration", "8", "--fs", "1024", "--seed", "3", "-o", path)[0] == 0
    rc, out, err = run(capsys, "discover", path, "--json")
    assert rc == 0 and "is a time recording: FRFs estimated by" in err
    got = json.loads(out)
    want = json.loads(json.dumps(satmd.discover(load_recording(path)).to_dict()))
    for doc in (got, want):
        doc.pop("wall_time_s", None)
    assert got == want

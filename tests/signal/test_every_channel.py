"""The FRF of every response channel (`estimate_frfs`, `satmd estimate-frf --channels`): a structure's, each
channel estimated as a rig's A1 is, against the chain's exact FRFs from its matrices."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.cli import main
from satmd.errors import DataError
from satmd.io import ChannelFRFs, Recording, load_channel_frfs, save_recording
from satmd.signal import estimate_frf, estimate_frfs
from tests.structure.chain import chain_matrices, linear_chain_test

N = 5


@pytest.fixture(scope="module")
def chain():
    """A linear five-mass chain tested with a multisine, 1 % noise on every channel (the acquisition's
    anti-alias filter on), and its exact accelerances at the force's point (mass 1)."""
    rec = linear_chain_test()
    M, K, C = chain_matrices(N)

    def exact(f_hz):
        w = 2 * np.pi * np.asarray(f_hz)
        x = np.array([np.linalg.solve(K - wi ** 2 * np.diag(M) + 1j * wi * C, np.eye(N)[0]) for wi in w])
        return (-(w ** 2)[:, None] * x).T  # (masses, frequencies): acceleration per newton on mass 1

    return rec, exact


def test_every_channel_is_estimated_as_a_rigs_a1_is(chain):
    rec, _ = chain
    frfs = estimate_frfs(rec)
    assert frfs.channels == tuple(f"acc{i}" for i in range(1, N + 1)) and frfs.frf.shape == (N, frfs.freq_hz.size)
    for name in ("acc3", "acc5"):
        alone = estimate_frf(Recording(rec.fs_hz, {"force": rec["force"], "acc1": rec[name]}))
        np.testing.assert_array_equal(frfs[name], alone.channels["a1"])
        np.testing.assert_array_equal(frfs.std[frfs.channels.index(name)], alone.std["a1"])
    assert frfs.estimator["method"] == "periodic" and frfs.units == "m/s^2/N"


def test_every_channel_matches_the_exact_frf_within_its_std(chain):
    rec, exact = chain
    frfs = estimate_frfs(rec, ["acc2", "acc4", "acc5"])
    truth = exact(frfs.freq_hz)[[1, 3, 4]]
    z2 = np.abs(frfs.frf - truth) ** 2 / (2 * frfs.std ** 2)  # σ on each of Re and Im, estimated over periods
    # z² is F(2, dof) distributed (the std from five steady periods, 2(5 − 1) = 8 degrees of freedom): 97.4 % below
    # 6. Another channel's exact FRF in place of the truth: 6 % (measured)
    assert frfs.estimator["noise_dof"] == 8
    assert 0.93 < np.mean(z2 < 6) <= 1.0, np.mean(z2 < 6)
    assert np.median(np.abs(frfs.frf - truth) / np.abs(truth)) < 0.02


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".mat"])
def test_saved_and_read_back_exactly(chain, tmp_path, suffix):
    frfs = estimate_frfs(chain[0], ["acc1", "acc4"])
    back = load_channel_frfs(frfs.save(tmp_path / f"frfs{suffix}"))
    assert back.channels == frfs.channels and back.units == frfs.units and back.estimator == frfs.estimator
    for name in ("freq_hz", "frf", "std", "coherence"):
        np.testing.assert_array_equal(getattr(back, name), getattr(frfs, name))


def test_uff_holds_one_frf_std_and_coherence_per_channel(chain, tmp_path):
    pyuff = pytest.importorskip("pyuff")
    frfs = estimate_frfs(chain[0], ["acc2", "acc5"])
    sets = pyuff.UFF(str(frfs.save(tmp_path / "frfs.uff"))).read_sets()
    assert [s["id1"] for s in sets] == ["satmd:acc2", "satmd:acc2_std", "satmd:acc2_coh", "satmd:acc5",
                                        "satmd:acc5_std", "satmd:acc5_coh"]
    assert [s["rsp_node"] for s in sets[::3]] == [2, 5] and sets[0]["func_type"] == 4
    np.testing.assert_allclose(sets[3]["data"], frfs["acc5"], rtol=1e-15)


def test_bad_channels_refused_naming_them(chain):
    rec = chain[0]
    with pytest.raises(DataError, match=r"no response channel 'acc9' \(responses: acc1, acc2, acc3, acc4, acc5\)"):
        estimate_frfs(rec, ["acc2", "acc9"])
    with pytest.raises(DataError, match="no force channel"):
        estimate_frfs(Recording(rec.fs_hz, {"acc1": rec["acc1"], "acc2": rec["acc2"]}))
    with pytest.raises(DataError, match=r"frf has shape \(1, 3\), expected \(2, 3\)"):
        ChannelFRFs(np.arange(1.0, 4.0), ("a", "b"), np.ones((1, 3)), np.ones((2, 3)), np.ones((2, 3)))


def test_cli_channels_all_writes_every_channel(chain, tmp_path, capsys):
    path = save_recording(chain[0], tmp_path / "gvt.csv")
    out = tmp_path / "frfs.csv"
    assert main(["estimate-frf", str(path), "--channels", "all", "-o", str(out), "--plot", str(tmp_path / "f.png")]) == 0
    assert (tmp_path / "f.png").stat().st_size > 0  # five channels: overlaid in one column
    said = capsys.readouterr().out
    assert f"FRFs of {N} channels (acc1, acc2, acc3, acc4, acc5) over the force" in said
    assert load_channel_frfs(out).channels == tuple(f"acc{i}" for i in range(1, N + 1))
    assert main(["estimate-frf", str(path), "--channels", "acc2,acc7", "-o", str(tmp_path / "x.csv")]) == 2
    assert "no response channel 'acc7'" in capsys.readouterr().err and not (tmp_path / "x.csv").exists()


def test_cli_without_channels_says_how_to_get_every_channel(chain, tmp_path, capsys):
    path = save_recording(chain[0], tmp_path / "gvt.csv")
    assert main(["estimate-frf", str(path), "-o", str(tmp_path / "rig.csv")]) == 0
    assert "--channels all estimates every channel's" in capsys.readouterr().err


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_info_describes_them_and_a_rigs_commands_say_what_they_hold(chain, tmp_path, capsys, suffix):
    path = estimate_frfs(chain[0], ["acc2", "acc3"]).save(tmp_path / f"frfs{suffix}")
    assert main(["info", str(path)]) == 0
    said = capsys.readouterr().out
    assert "FRFs of every channel: 2 (acc2, acc3) over the force [m/s^2/N]" in said and "median coherence" in said
    assert main(["identify", str(path)]) == 2
    assert "FRFs of every channel of a structure" in capsys.readouterr().err


def test_a_damaged_table_is_refused_naming_the_file(tmp_path):
    from satmd.io.channelfrfs import MAGIC

    path = tmp_path / "frfs.csv"
    path.write_text(f"{MAGIC}\nfreq_hz,acc1_re,acc1_im,acc1_std,acc1_coh\n1,2,3,x,1\n")
    with pytest.raises(DataError, match=r"frfs.csv: a value that is not a number"):
        load_channel_frfs(path)
    path.write_text(f"{MAGIC}\nfreq_hz,acc1_re,acc1_im\n1,2,3\n")
    with pytest.raises(DataError, match=r"frfs.csv: its header .* is not freq_hz, then <channel>_re"):
        load_channel_frfs(path)

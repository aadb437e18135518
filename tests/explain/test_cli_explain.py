"""`satmd explain` on a directory written by the inverse package (tiny training)."""
import json

import pytest

from satmd.cli import main

pytest.importorskip("torch")


@pytest.fixture(scope="module")
def model_dir(tmp_path_factory):
    inverse = pytest.importorskip("satmd.inverse")
    path = tmp_path_factory.mktemp("model")
    model = inverse.InverseModel("physics", epochs=2, warm_start_epochs=1, samples_per_pair=4, n_members=2,
                                 batch_size=64, seed=1, verbose=False, mc_samples=4)
    model.fit().save(path)
    return path


def test_explain_writes_every_figure(model_dir, tmp_path, capsys):
    out = tmp_path / "ex"
    assert main(["explain", str(model_dir), "--out", str(out), "--quick", "--no-distill"]) == 0
    figs = sorted(p.name for p in (out / "figures").iterdir())
    expected = [f"explain_{kind}_{o}_{sp}.png" for kind in ("attribution", "heatmap") for o in "RL"
                for sp in ("raw", "scaled")]
    expected += ["explain_neural_vs_physical.png", "explain_neural_vs_physical_scaled.png", "explain_latent_pca.png"]
    for name in expected:
        assert name in figs
    summary = (out / "summary.md").read_text()
    assert "Table 3" in summary and "Spearman" in summary
    res = json.loads((out / "explain.json").read_text())
    assert len(res["neural"]["agreement"]) == 6
    assert "Table 3 mean" in capsys.readouterr().out


def test_explain_errors_are_one_line(tmp_path, capsys):
    assert main(["explain", str(tmp_path / "missing")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no such model folder" in err

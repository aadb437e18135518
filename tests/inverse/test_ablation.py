import json

import pytest

pytest.importorskip("torch")
pytest.importorskip("satmd.identification")

from satmd.inverse.ablation import (ablation_markdown, headline, loop_speedup, off_curve_markdown, run_ablation,
                                    table2_markdown)


def test_quick_ablation_is_complete_and_renders():
    res = run_ablation(kinds=("physics", "supervised", "optimization", "hybrid"), noises=(0.0, 0.01),
                       presets=("paper",), quick=True, speedup=False, log=lambda m: None)
    json.dumps(res)  # JSON-ready
    cells = {(c["kind"], c["noise"]) for c in res["cells"]}
    assert cells == {(k, n) for k in ("physics", "supervised", "optimization", "hybrid") for n in (0.0, 0.01)}
    for c in res["cells"]:
        assert {"mae_R", "mae_L", "rel_R", "rel_L", "frf_error", "coverage", "train_s", "infer_s_per_frf"} <= set(c)
    # least squares recovers noise-free pairs exactly, whatever the net says
    hyb = [c for c in res["cells"] if c["kind"] == "hybrid" and c["noise"] == 0][0]
    assert hyb["mae_R"] < 1e-6 and hyb["mae_L"] < 1e-8
    assert set(res["table2"]) == {"physics", "supervised", "hybrid"}
    assert len(res["table2"]["physics"]["rows"]) == 6
    assert "paper R̂" in table2_markdown(res)
    assert ablation_markdown(res).count("\n") == len(res["cells"]) + 1
    assert "paper" in off_curve_markdown(res)
    assert headline(res).startswith("inverse:")


def test_loop_speedup_times_both():
    s = loop_speedup(epochs=1, n_loop=20)
    assert s["vectorised_epoch_s"] > 0 and s["per_sample_epoch_s"] > 0 and s["speedup"] > 1

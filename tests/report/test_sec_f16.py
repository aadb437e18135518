"""The report's F-16 section: four real levels, each resonance's trend, no SATMD element (issue 35)."""
from __future__ import annotations

import json

from satmd.report import reproduce
from tests.conftest import needs_real


@needs_real("f16", "F16Data_FullMSine_Level1.mat")
def test_f16_section_reads_the_levels_and_names_no_element(tmp_path):
    index = reproduce(tmp_path / "r", only=["f16"], quick=True, log=lambda *_: None)
    text = index.read_text()
    assert "no SATMD element is named" in text and "model adequate: False" in text
    assert "joint between acc1 and acc2" in text and "modelled" not in text  # quick: placed and named, not fitted
    row = next(line for line in text.splitlines() if line.startswith("| 7.32 Hz"))
    assert row.rstrip().endswith("| softening | rising |")
    assert (tmp_path / "r" / "figures" / "f16_levels.png").is_file()


@needs_real("f16", "F16Data_FullMSine_Level5.mat")
def test_structure_section_places_models_and_predicts_the_f16(tmp_path):
    """Quick: the joint located, a short fit on levels 1 and 7, level 5 predicted better than the linear model."""
    index = reproduce(tmp_path / "r", only=["structure"], quick=True, log=lambda *_: None)
    text = index.read_text()
    assert "between acc2 and acc3" in text
    row = next(line for line in text.splitlines() if line.startswith("| **level 5 (never seen)**"))
    pairs = [cell.strip("* ").split(" → ") for cell in row.split("|")[2:-1]]
    assert len(pairs) == 3 and all(float(b) < float(a) for a, b in pairs)  # better than linear on every channel
    assert (tmp_path / "r" / "figures" / "structure_level5.png").is_file()
    kept = json.loads((tmp_path / "r" / "results.json").read_text())["structure"]
    assert kept["law"] in text and kept["formula"] in text  # the model's law, which may not be the spectra's
    assert kept["spectra_law"] and kept["between"] == ["acc2", "acc3"]

"""The report's F-16 section: four real levels, each resonance's trend, no SATMD element (issue 35)."""
from __future__ import annotations


from satmd.report import reproduce
from tests.conftest import needs_real


@needs_real("f16", "F16Data_FullMSine_Level1.mat")
def test_f16_section_reads_the_levels_and_names_no_element(tmp_path):
    index = reproduce(tmp_path / "r", only=["f16"], log=lambda *_: None)
    text = index.read_text()
    assert "no SATMD element is named" in text and "model adequate: False" in text
    row = next(line for line in text.splitlines() if line.startswith("| 7.32 Hz"))
    assert row.rstrip().endswith("| softening | rising |")
    assert (tmp_path / "r" / "figures" / "f16_levels.png").is_file()

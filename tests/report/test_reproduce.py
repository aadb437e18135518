"""`satmd reproduce` survives a failing section (issue 23): the other sections and the report are
written, the failed one says why in one line, and the command exits 1."""
import json

import pytest

import satmd.report as report
from satmd.cli import main


def _boom(ctx):
    raise MemoryError("simulated: the section ran out of memory\nsecond line never shown")


def test_a_failing_section_loses_nothing_else(tmp_path, monkeypatch):
    forward = next(m for m in report.sections() if m.__name__.endswith(".forward"))
    tune = next(m for m in report.sections() if m.__name__.endswith(".tune"))
    monkeypatch.setattr(tune, "build", _boom)
    with pytest.raises(report.IncompleteReport) as info:
        report.reproduce(tmp_path / "r", only=["forward", "tune"], quick=True, log=lambda *_: None)
    assert set(info.value.failed) == {"tune"}
    md = (tmp_path / "r" / "index.md").read_text()
    assert f"## {forward.TITLE}" in md and f"## {tune.TITLE}" in md
    failed_line = next(line for line in md.splitlines() if "This section failed" in line)
    assert "MemoryError: simulated: the section ran out of memory" in failed_line
    assert "second line" not in md
    assert (tmp_path / "r" / "index.html").exists()
    results = json.loads((tmp_path / "r" / "results.json").read_text())
    assert "tune" in results["failed_sections"]


def test_the_cli_exits_1_and_names_the_section(tmp_path, monkeypatch, capsys):
    tune = next(m for m in report.sections() if m.__name__.endswith(".tune"))
    monkeypatch.setattr(tune, "build", _boom)
    code = main(["reproduce", "--out", str(tmp_path / "r"), "--only", "tune", "--quick"])
    err = capsys.readouterr().err
    assert code == 1 and "tune: MemoryError" in err and (tmp_path / "r" / "index.md").exists()


def test_an_interrupt_still_stops_the_run(tmp_path, monkeypatch):
    tune = next(m for m in report.sections() if m.__name__.endswith(".tune"))

    def interrupt(ctx):
        raise KeyboardInterrupt

    monkeypatch.setattr(tune, "build", interrupt)
    with pytest.raises(KeyboardInterrupt):
        report.reproduce(tmp_path / "r", only=["tune"], quick=True, log=lambda *_: None)
    assert not (tmp_path / "r" / "index.md").exists()

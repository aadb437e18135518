import sys

from satmd.report import Context


def test_section_degrades_without_the_inverse_package(monkeypatch, tmp_path):
    from satmd.report.parts import explain as sec_explain

    monkeypatch.setitem(sys.modules, "satmd.inverse", None)  # import satmd.inverse -> ImportError
    model, note = sec_explain._model(Context(tmp_path, quick=True))
    assert model is None and "skipped" in note and "inverse" in note
    assert sec_explain.ORDER == 40

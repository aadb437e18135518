"""Rules written once (issue 36): a fit's covariance comes from `satmd.numerics.jacobian_covariance`, never from
an inverse of JᵀJ written again beside it."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

SRC = Path(__file__).resolve().parents[1] / "satmd"
INVERSE = re.compile(r"linalg\.p?inv\(")
# matrix inverses that are no fit's covariance, each with its reason
NOT_A_COVARIANCE = {
    "satmd/physics/nonlinear/statespace.py": "the modal matrix's eigenvectors (a change of basis)",
    "satmd/signal/lpm.py": "the local polynomial method's own regression (Pintelon et al. 2010)",
    "satmd/signal/sweepfrf.py": "the same local fit on a sweep's windows",
}


def test_no_covariance_written_again_beside_the_shared_one():
    found = [f"{p.relative_to(SRC.parent)}:{i}" for p in SRC.rglob("*.py")
             if p.name not in ("covariance.py", "numerics.py") and str(p.relative_to(SRC.parent)) not in NOT_A_COVARIANCE
             for i, line in enumerate(p.read_text().splitlines(), 1) if INVERSE.search(line)]
    assert not found, f"inv(JᵀJ) by hand (use satmd.numerics.jacobian_covariance): {found}"


def test_jacobian_covariance_is_the_textbook_one_and_says_when_there_is_none():
    from satmd.numerics import jacobian_covariance

    rng = np.random.default_rng(0)
    J = rng.standard_normal((50, 3)) * np.array([1e-4, 1.0, 1e5])  # units apart by 9 decades
    np.testing.assert_allclose(jacobian_covariance(J, 2.0), 2.0 * np.linalg.inv(J.T @ J), rtol=1e-9)
    Jc = J + 1j * rng.standard_normal(J.shape) * np.array([1e-4, 1.0, 1e5])  # complex parameters: (JᴴJ)⁻¹
    np.testing.assert_allclose(jacobian_covariance(Jc), np.linalg.inv(Jc.conj().T @ Jc), rtol=1e-9)
    J[:, 2] = 3.0 * J[:, 1]  # two columns that cannot be told apart
    assert np.isnan(jacobian_covariance(J)).all()


def test_the_paper_band_is_written_once():
    literal = re.compile(r"\(20(\.0)?, 200(\.0)?\)")
    found = [f"{p.relative_to(SRC.parent)}:{i}" for p in SRC.rglob("*.py") if p.name != "conventions.py"
             for i, line in enumerate(p.read_text().splitlines(), 1)
             if literal.search(line) and not line.lstrip().startswith(">>>")]
    assert not found, f"the paper's band as a literal (use satmd.conventions.PAPER_BAND_HZ): {found}"


def test_the_band_scan_is_written_once():
    """Every band scan (the linear fit's mismatch, the nonlinear tests) goes through `locate.scan_bands`."""
    windowing = re.compile(r"np\.convolve\([^)]*np\.ones\(w\)")
    where = sorted(str(p.relative_to(SRC.parent)) for p in SRC.rglob("*.py") if windowing.search(p.read_text()))
    assert where == ["satmd/discovery/locate.py"], where


def test_a_recordings_drive_level_is_read_one_way():
    """"Level" was the force's std in one place and its RMS in another (issue 36): `numerics.force_level`."""
    level = re.compile(r"np\.(std|sqrt\(np\.mean)\(.*\[\"force\"\]")
    # satmd/simulation/timesim.py scales its simulated force to the RMS it is asked for: a setting, not a reading
    found = [f"{p.relative_to(SRC.parent)}:{i}" for p in SRC.rglob("*.py") if p.name not in ("numerics.py", "timesim.py")
             for i, line in enumerate(p.read_text().splitlines(), 1) if level.search(line)]
    assert not found, f"a drive level read by hand (use satmd.numerics.force_level): {found}"


def test_one_output_error_fitter():
    """The time-domain fits share `numerics.batched_least_squares` (issue 36: two fitters, each its own
    finite differences)."""
    for name in ("identification/nonlinear/fit.py", "identification/oscillator.py"):
        text = (SRC / name).read_text()
        assert "batched_least_squares(" in text and "np.eye(x.size)" not in text, name


def test_a_band_in_hz_is_spelled_band_hz():
    """Every function of the package that takes a frequency band calls it ``band_hz``; ``band=`` survives only as
    the deprecated former name beside it (`errors.renamed_keyword`)."""
    import ast

    wrong = []
    for p in SRC.rglob("*.py"):
        if "cli" in p.parts:  # argparse namespaces, not signatures
            continue
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                names = {a.arg for a in node.args.args + node.args.kwonlyargs + node.args.posonlyargs}
                if "band" in names and "band_hz" not in names:
                    wrong.append(f"{p.relative_to(SRC.parent)}:{node.lineno} {node.name}")
    assert not wrong, f"a band parameter not spelled band_hz: {wrong}"


def test_the_former_band_keyword_still_works_and_warns():
    import warnings

    from satmd.discovery.nonlinear.stats import linearity_test

    rng = np.random.default_rng(1)
    x = rng.standard_normal(4096)
    y = np.convolve(x, [1.0, 0.5, 0.2])[:4096]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = linearity_test(x, {"y": y}, 1.0, {"y3": y ** 3}, band=(0.05, 0.3))
    new = linearity_test(x, {"y": y}, 1.0, {"y3": y ** 3}, band_hz=(0.05, 0.3))
    assert any("band_hz" in str(w.message) for w in caught)
    assert old.p_value == new.p_value


def test_one_acquisition_stage_for_every_simulated_recording():
    """The linear and the nonlinear recorder add their sensors' noise and write their metadata in one place
    (`satmd.simulation.acquisition`), so a linear and a nonlinear recording of one rig are taken alike."""
    for path in ("simulation/timesim.py", "simulation/nonlinear.py"):
        text = (SRC / path).read_text()
        assert "acquire(" in text and "simulated_recording(" in text, path
        assert "standard_normal(" not in text and "Recording(" not in text, f"{path} adds noise or builds meta itself"


def test_one_time_model_protocol_for_every_recorder():
    """The recorders drive a time model (`satmd.physics.timemodel`) and nothing else: the linear convolution
    and the integrator are reached through ``respond``, never called or rewritten beside it."""
    for path in ("simulation/timesim.py", "simulation/nonlinear.py"):
        text = (SRC / path).read_text()
        assert ".respond(" in text, path
        assert "integrate(" not in text and "irfft(h" not in text, f"{path} simulates the rig itself"


def test_the_excitation_is_read_at_one_door():
    """`detect_excitation` runs in one place, `satmd.signal.excitation.received` (issue 48): every other step
    reads the excitation the recording carries (`excitation_of`), so the FRF and every test agree on it."""
    import ast

    callers = []
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and getattr(node.func, "id", getattr(node.func, "attr", None)) == "detect_excitation":
                callers.append(str(path.relative_to(SRC)))
    assert callers == ["signal/excitation.py"], callers

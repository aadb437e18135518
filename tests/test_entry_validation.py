"""Public entry points check their arguments through `satmd.validation` (issue 36 item 8): one line, a
satmd error, naming the argument, before any work."""
from __future__ import annotations

import numpy as np
import pytest

from satmd.errors import DataError, SatmdError
from satmd.errors import DataTypeError
from satmd.validation import check_data


class A:
    pass


class B:
    pass


def test_check_data_names_what_is_wrong():
    a = A()
    assert check_data(a, "x", (A, B)) is a
    assert check_data([a, B()], "x", (A, B), many=True)[0] is a
    cases = [
        (5, True, "^f: x must be A or B, or a list of them, got int$"),
        ({}, True, "^f: x must be A or B, or a list of them, got dict$"),
        ("data.csv", True, "^f: x must be A or B, or a list of them, got str 'data.csv'$"),
        ([a, 3], True, r"^f: x\[1\] must be A or B, got int$"),
        ([], True, "^f: x is empty: give at least one A or B$"),
        (a, False, "^f: x must be a list of A or B, got A$"),
    ]
    for value, single, message in cases:
        with pytest.raises(DataTypeError, match=message) as err:
            check_data(value, "x", (A, B), "f", single=single, many=True)
        assert isinstance(err.value, SatmdError) and isinstance(err.value, TypeError)


@pytest.mark.parametrize("bad, where", [(5, "data must"), ({"a1": 1}, "data must"), ([], "data is empty"),
                                        ("x.csv", "data must"), (np.zeros(3), "data must"), (None, "data must")])
def test_discover_refuses_what_is_not_data(bad, where):
    from satmd import discover

    with pytest.raises(DataTypeError, match=f"^discover: {where}") as err:
        discover(bad)
    assert "\n" not in str(err.value)


def test_discover_names_the_wrong_item_of_a_list():
    from satmd import discover, simulate

    with pytest.raises(DataTypeError, match=r"^discover: data\[1\] must be FRFData or Recording .*got dict$"):
        discover([simulate(), {"a1": 1}])


def test_the_time_domain_entry_points_check_their_arguments():
    from satmd import Rig
    from satmd.identification.nonlinear.fit import fit_nonlinear
    from satmd.signal import estimate_frf
    from satmd.physics import integrate
    from satmd.tuning.nonlinear import tune_nonlinear

    with pytest.raises(DataError, match="^integrate: fs_hz must be a number > 0"):
        integrate(Rig(), np.ones(10), 0.0)
    with pytest.raises(DataError, match="^unknown hold 'cubic' for integrate; choose from bandlimited, linear$"):
        integrate(Rig(), np.ones(10), 1000.0, hold="cubic")
    with pytest.raises(DataError, match="^unknown backend 'c' for integrate"):
        integrate(Rig(), np.ones(10), 1000.0, backend="c")
    with pytest.raises(DataError, match="^fit_nonlinear: recordings is empty: give at least one Recording$"):
        fit_nonlinear([], "quadratic_damping")
    with pytest.raises(DataTypeError, match=r"^fit_nonlinear: recordings\[0\] must be Recording, got str"):
        fit_nonlinear(["a.csv"], "quadratic_damping")
    with pytest.raises(DataError, match="^fit_nonlinear: passes must be an integer >= 1, got 0$"):
        fit_nonlinear([], "quadratic_damping", passes=0)
    with pytest.raises(DataError, match="^unknown output 'q' for tune_nonlinear; choose from u1, a1$"):
        tune_nonlinear(Rig(), [], [1.0], output="q")
    with pytest.raises(DataError, match=r"^tune_nonlinear: band_hz must be a band"):
        tune_nonlinear(Rig(), [], [1.0], band_hz=(200.0, 20.0))
    with pytest.raises(DataTypeError, match="^estimate_frf: recording must be Recording .*got str 'rec.csv'$"):
        estimate_frf("rec.csv")
    with pytest.raises(DataError, match=r"^estimate_frf: overlap must be None or a number in \[0, 1\), got 1.0$"):
        estimate_frf("rec.csv", overlap=1.0)


def test_simulate_checks_its_arguments():
    from satmd import simulate

    with pytest.raises(DataError, match="^simulate: channels must be a list of str, got 'a1'$"):
        simulate(channels="a1")
    with pytest.raises(DataError, match=r"^simulate: noise must be rel or \(rel, floor\)"):
        simulate(noise=(-0.1, 0.0))
    with pytest.raises(DataError, match="^simulate: level must be a number > 0"):
        simulate(time=True, level=0.0)


def test_modal_and_retune_entry_points_validate_their_arguments():
    """validate_params on every public entry point (issue 36): one line naming the argument."""
    import numpy as np

    from satmd import fit_modes, follow_modes, retune

    f = np.linspace(10.0, 50.0, 200)
    H = {"a1": 1.0 / (20.0 ** 2 - f ** 2 + 0.4j * f)}
    with pytest.raises(DataError, match="^fit_modes: band_hz must be"):
        fit_modes(f, H, band_hz=(50.0, 10.0))
    with pytest.raises(DataError, match="^fit_modes: n_modes must be"):
        fit_modes(f, H, n_modes=0)
    with pytest.raises(DataError, match="^follow_modes: alpha must be"):
        follow_modes(f, [H, H], alpha=1.5)
    with pytest.raises(DataError, match="^retune: band_hz must be"):
        retune([], band_hz=(200.0, 20.0))


def test_every_public_function_checks_its_arguments():
    """Every function `import satmd` exports validates through `validate_params` (its table is on it)."""
    import inspect

    import satmd

    bare = [n for n in satmd.__all__ if inspect.isfunction(getattr(satmd, n))
            and not hasattr(getattr(satmd, n), "parameter_constraints")]
    assert not bare, f"public functions without validate_params: {bare}"


@pytest.mark.parametrize("call, message", [
    (lambda s: s.load_frf(3), r"^load_frf: path must be a str or a PathLike, got 3$"),
    (lambda s: s.load_recording(None), r"^load_recording: path must be a str or a PathLike, got None$"),
    (lambda s: s.save_frf({"a1": 1}, "x.csv"), r"^save_frf: data must be a FRFData, got \{'a1': 1\}$"),
    (lambda s: s.effect(3), r"^effect: name must be a str, got 3$"),
    (lambda s: s.nonlinear_element(["cubic_host_spring"]), r"^element: name must be a str"),
    (lambda s: s.frf([50.0], threads=0), r"^frf: threads must be None or"),
    (lambda s: s.discover_many([], chunksize=0), r"^discover_many: chunksize must be"),
])
def test_a_wrong_argument_is_one_line_naming_it(call, message):
    import satmd

    with pytest.raises(DataError, match=message):
        call(satmd)

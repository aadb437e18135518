"""Hyperparameter constraints of `InverseModel`, checked in one place (as scikit-learn's ``_parameter_constraints``).

The defaults live in ``InverseModel.__init__``'s signature and nowhere
else; what depends on the preset (the size of its training set) lives in
``PRESET_SIZES``. Each constraint is a list of what a value may be: ``None``,
a type, an `Options` or an `Interval` (the vocabulary of `satmd.validation`); `validate` accepts a value that
matches any of them and otherwise raises one `SatmdError` line naming the
parameter.
"""
from __future__ import annotations

from .. import validation
from ..errors import SatmdError
from ..validation import Grid, Interval, Options  # noqa: F401 - the vocabulary InverseModel's table uses

#: Training-set size per preset when ``samples_per_pair`` / ``n_samples`` is None.
PRESET_SIZES = {"paper": {"samples_per_pair": 150}, "box": {"n_samples": 6000}}


def validate(params: dict, constraints: dict, owner: str = "InverseModel") -> None:
    """Raise a one-line `SatmdError` for the first parameter that matches none of its constraints.

    Parameters
    ----------
    params : name -> value (``get_params()``)
    constraints : name -> list of allowed forms (None, a type, `Options`, `Interval`, `Grid`)
    owner : the class named in the message

    Returns
    -------
    None
    """
    validation.validate(params, constraints, owner, SatmdError)

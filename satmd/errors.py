"""Exceptions with one-line messages meant for the person at the keyboard."""


class SatmdError(ValueError):
    """Base class: the CLI prints the message on one line and exits with status 2."""


class DataError(SatmdError):
    """Data that cannot be used (wrong shape, NaN, inconsistent channels)."""


class DataTypeError(DataError, TypeError):
    """An argument of the wrong type: a satmd error (one line, CLI exit status 2) and a `TypeError` too."""


class FormatError(DataError):
    """A malformed file; the message names the file, line and column."""

    def __init__(self, path, message, line=None, column=None):
        where = str(path)
        if line is not None:
            where += f", line {line}"
        if column is not None:
            where += f", column {column}"
        super().__init__(f"{where}: {message}")
        self.path, self.line, self.column = str(path), line, column


# --- warnings: by type, never by text ------------------------------------------------------------

class DataWarning(UserWarning):
    """Something in the data is suspicious but usable (clipping, dropped points, a poor fit).

    The CLI prints these as one line each; library users can filter them with
    ``warnings.simplefilter("error", DataWarning)``, or one kind by its subclass.
    """


class PoorFitWarning(DataWarning):
    """The fitted model reproduces the data poorly (large error, χ² beyond the noise, structured residuals)."""


class PinnedParameterWarning(DataWarning):
    """A fitted parameter ended on a bound: the data push it beyond the model's range."""


class IdentifiabilityWarning(DataWarning):
    """A parameter is not identifiable, two are strongly correlated, or the problem is ill-conditioned."""


class WarningRecord(str):
    """A warning kept on a result: its one-line text (a ``str``) with its ``category`` (a `DataWarning` class).

    Results store these instead of emitting them, so that callers decide by type (``issubclass(
    w.category, PoorFitWarning)``) whether to show or raise them; the text is what ``to_dict`` and
    the reports print.

    Parameters
    ----------
    message : the one-line text
    category : the warning class
    """

    category: type

    def __new__(cls, message: str, category: type = DataWarning):
        self = super().__new__(cls, message)
        self.category = category
        return self

    def __reduce__(self):
        return WarningRecord, (str(self), self.category)

    def emit(self, stacklevel: int = 2) -> None:
        """Emit the record as a Python warning of its category.

        Parameters
        ----------
        stacklevel : as `warnings.warn` (counted from the caller of `emit`)

        Returns
        -------
        None
        """
        import warnings

        warnings.warn(str(self), self.category, stacklevel=stacklevel + 1)


def renamed_keyword(old_value, new_value, owner: str, old: str = "band", new: str = "band_hz"):
    """``new_value``, or ``old_value`` given under a keyword's former name (with a DeprecationWarning).

    Parameters
    ----------
    old_value : what the caller gave under the former name (None: nothing).
    new_value : the value under the new name.
    owner : the function named in the warning.
    old, new : the two names.

    Returns
    -------
    object
    """
    if old_value is None:
        return new_value
    import warnings

    warnings.warn(f"{owner}: {old}= is now {new}= (the same value)", DeprecationWarning, stacklevel=4)
    return old_value

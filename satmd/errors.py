"""Exceptions with one-line messages meant for the person at the keyboard."""


class SatmdError(ValueError):
    """Base class: the CLI prints the message on one line and exits with status 2."""


class DataError(SatmdError):
    """Data that cannot be used (wrong shape, NaN, inconsistent channels)."""


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

"""Text for the terminal: library messages in the CLI's words, control characters escaped, warnings one line each."""
from __future__ import annotations

import contextlib
import sys
import warnings

# the library names its parameters; the command line calls them by their flags
_FLAGS = (("channel_map", "--map"), ("freq_axis", "--freq-axis"),
          ("calibrate with scale (", "calibrate with --scale ("))


def with_flags(text: str) -> str:
    """Library parameter names in ``text`` replaced by the CLI's flags."""
    for name, flag in _FLAGS:
        text = text.replace(name, flag)
    return text


def safe_text(text) -> str:
    """``text`` with control and format characters (ANSI escapes, bidi overrides) shown escaped, e.g. ``\\x1b``.

    File names and values echoed to the terminal go through here, so a file
    called ``\\x1b[2J.csv`` cannot clear the screen or recolour the output.
    """
    import unicodedata

    text = str(text)
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c == " " else
                   (repr(c)[1:-1] if unicodedata.category(c)[0] == "C" else c) for c in text)


def cli_text(message) -> str:
    """A library message on one line, in the CLI's words, control characters escaped."""
    return safe_text(with_flags(" ".join(str(message).split())))


@contextlib.contextmanager
def one_line_warnings(command: str):
    """Show warnings raised while loading data as one line each on stderr (no source lines)."""
    from ..io import DataWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DataWarning)  # others keep their default filters
        try:
            yield
        finally:
            seen = set()
            for w in caught:
                text = cli_text(w.message)
                if text not in seen:
                    seen.add(text)
                    print(f"satmd {command}: warning: {text}", file=sys.stderr)

"""The `satmd` command: thin subcommands over the library.

Each module in this package with a ``register(subparsers)`` function is a
subcommand, so a new command is one new file. Errors are one line on stderr
with exit status 2; nothing is written when the input is bad.
"""
from __future__ import annotations

import argparse
import sys

from ._interrupt import INTERRUPTED, catching_interrupts, interrupted

# commands listed first in `satmd --help`; any other module follows
_ORDER = ("simulate", "identify", "discover", "inverse", "explain", "info", "estimate_frf", "reproduce")


def _command_modules():
    import pkgutil

    found = [m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    return [n for n in _ORDER if n in found] + sorted(n for n in found if n not in _ORDER)


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line, like every other refusal (subcommand parsers inherit the class)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {' '.join(message.split())} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="satmd",
        description="Identification, inversion, explanation and missing-physics discovery for "
                    "semi-active shunted piezoelectric tuned mass dampers.",
    )
    from ..version import __version__

    parser.add_argument("--version", action="version", version=f"satmd {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    import importlib

    for name in _command_modules():
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


# optional dependencies: their absence is the user's setup, not a bug in satmd
_EXTRAS = {"torch", "tqdm", "matplotlib", "sympy", "pyoperon", "pysr", "pysindy", "juliacall", "h5py"}


def main(argv=None) -> int:
    """Run one command; returns the exit status (0 ok, 2 refused input, 130 interrupted).

    Only user errors are caught: `SatmdError`, `OSError` (said in words) and a
    missing optional dependency. Anything else is a bug and keeps its traceback.
    Ctrl-C, wherever it lands (while the command's modules are still being
    imported too), ends with one line, ``satmd: interrupted``, and status 130.
    """
    with catching_interrupts(exiting=argv is None):  # no argv: run as the program, which ends next
        try:
            return _main(argv)
        except KeyboardInterrupt:
            return interrupted()
    return INTERRUPTED  # pragma: no cover - a Ctrl-C after the command's own `except` (see catching_interrupts)


def _main(argv) -> int:
    from ..errors import SatmdError

    parser = build_parser()  # imports every command, and with them numpy and scipy: under the Ctrl-C handling
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version or a usage error, already printed by argparse
        return exc.code if isinstance(exc.code, int) else 2
    from ._common import one_line_warnings

    try:
        with one_line_warnings(args.command):  # library warnings as one line each, whatever raised them
            return args.func(args) or 0
    except BrokenPipeError:  # e.g. `satmd ... | head`: the reader left, nothing to report
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except SatmdError as exc:
        return _refuse(args.command, _blame(args, str(exc)))
    except OSError as exc:
        return _refuse(args.command, os_message(exc))
    except ImportError as exc:
        missing = exc if isinstance(exc, ModuleNotFoundError) else exc.__cause__
        if not (isinstance(missing, ModuleNotFoundError) and (missing.name or "").split(".")[0] in _EXTRAS):
            raise
        return _refuse(args.command, str(exc))


def _blame(args, message: str) -> str:
    """A refusal that names neither an input file nor an option is about the input: name it in front."""
    from pathlib import Path

    inputs = []
    for key in ("data", "more", "recording", "model"):  # more: the other levels of `discover DATA MORE...`
        value = getattr(args, key, None)
        inputs += value if isinstance(value, list) else [value] if value else []
    if not inputs or "--" in message or any(str(p) in message or Path(str(p)).name in message for p in inputs):
        return message
    return f"{inputs[0] if len(inputs) == 1 else ', '.join(map(str, inputs))}: {message}"


def _refuse(command, message) -> int:
    from ._common import cli_text

    message = cli_text(message) or "failed"
    print(f"satmd {command}: error: {message}", file=sys.stderr)
    return 2


def os_message(exc: OSError) -> str:
    """'out.csv: permission denied' rather than "[Errno 13] Permission denied: 'out.csv'"."""
    what = (exc.strerror or type(exc).__name__).rstrip(".")
    what = what[:1].lower() + what[1:]
    return f"{exc.filename}: {what}" if exc.filename else f"{what}"


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

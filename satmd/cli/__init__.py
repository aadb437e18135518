"""The `satmd` command: thin subcommands over the library.

Each module in this package with a ``register(subparsers)`` function is a
subcommand, so a new command is one new file. Errors are one line on stderr
with exit status 2; nothing is written when the input is bad.
"""
from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

from ..errors import SatmdError

# commands listed first in `satmd --help`; any other module follows
_ORDER = ("simulate", "identify", "discover", "inverse", "explain", "info", "estimate_frf", "reproduce")


def _command_modules():
    found = [m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")]
    return [n for n in _ORDER if n in found] + sorted(n for n in found if n not in _ORDER)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="satmd",
        description="Identification, inversion, explanation and missing-physics discovery for "
                    "semi-active shunted piezoelectric tuned mass dampers.",
    )
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"satmd {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in _command_modules():
        importlib.import_module(f"{__name__}.{name}").register(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args) or 0
    except BrokenPipeError:  # e.g. `satmd ... | head`: the reader left, nothing to report
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except (SatmdError, ValueError, OSError) as exc:
        message = " ".join(str(exc).split()) or type(exc).__name__
        print(f"satmd {args.command}: error: {message}", file=sys.stderr)
        return 2
    except ImportError as exc:
        print(f"satmd {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("satmd: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

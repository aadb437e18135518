"""satmd reproduce: the paper's results and satmd's extensions as a report."""
from __future__ import annotations

import sys
from pathlib import Path


def register(sub):
    p = sub.add_parser("reproduce", help="reproduce the paper and the discovery demo as a report",
                       description="Compute every section of the satmd report into DIR (index.md, index.html, "
                                   "figures/, results.json).")
    p.add_argument("--out", default="report", metavar="DIR", help="output folder (default: report)")
    p.add_argument("--only", default=None, metavar="SECTIONS", help="comma-separated section keys, e.g. forward")
    p.add_argument("--quick", action="store_true", help="smaller runs (for smoke tests)")
    p.add_argument("--acceptance", default=None, metavar="DIR",
                   help="folder of independent acceptance data (with discovery/) to report on too "
                        "(default: shared/acceptance beside the checkout, in the working directory or above it, or in $SATMD_SHARED)")
    p.set_defaults(func=run)


def acceptance_dir(given):
    """The acceptance folder: the one given, else ``shared/acceptance`` (`satmd.io.shared`)."""
    if given is not None:
        if not Path(given).is_dir():
            from ..errors import SatmdError

            raise SatmdError(f"--acceptance {given}: not a folder")
        return Path(given)
    from ..io.shared import shared_path

    return shared_path("acceptance")


def run(args):
    from ..report import reproduce
    from ._common import check_outputs

    from ..errors import SatmdError
    from ..report import section_keys

    check_outputs([("--out", args.out, None)])
    only = [s.strip() for s in args.only.split(",")] if args.only is not None else None
    unknown = [k for k in only or () if k not in section_keys()]
    if only is not None and (unknown or not any(only)):
        raise SatmdError(f"--only {args.only!r}: unknown section {', '.join(map(repr, unknown)) or '(none given)'}; "
                         f"choose from {', '.join(section_keys())}")
    from ..report import IncompleteReport

    try:
        index = reproduce(args.out, only=only, quick=args.quick, acceptance=acceptance_dir(args.acceptance))
    except IncompleteReport as exc:
        print(f"report written to {exc.index} (and index.html), but {len(exc.failed)} section(s) failed:",
              file=sys.stderr)
        for key, reason in exc.failed.items():
            print(f"  {key}: {reason}", file=sys.stderr)
        return 1
    print(f"report written to {index} (and index.html)")

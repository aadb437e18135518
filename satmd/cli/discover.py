"""satmd discover: locate the mismatch, name the missing physics, model it."""
from __future__ import annotations

from ..conventions import DEFAULT_FREE
from ..physics.effects import registered_names
from ._common import add_data_options, add_model_options, dumps_json, load_data, parse_list, parse_names, real


def register(sub):
    p = sub.add_parser("discover", help="find the physics the nominal model leaves out",
                       description="Fit the nominal model, test the mismatch against the noise, and explain it "
                                   "with the missing-physics vocabulary (SPEC §8); report as SPEC §9.")
    add_data_options(p)
    add_model_options(p, "parameters fitted in every model (default m2,kp,R,L)")
    p.add_argument("--candidates", default=None, help="comma-separated effect names (default: all)")
    p.add_argument("--alpha", type=real(0, 1, lo_open=True, hi_open=True), default=1e-3,
                   help="level of the mismatch test (default 1e-3)")
    p.add_argument("--json", action="store_true", help="print exactly the SPEC §9 JSON document")
    p.add_argument("--plot", default=None, metavar="FIG.png",
                   help="measured vs nominal vs augmented FRFs and residuals, bands shaded")
    p.set_defaults(func=run)


def run(args):
    from ..discovery import discover

    data = load_data(args)
    free = parse_list(args.free) or DEFAULT_FREE
    candidates = parse_names(args.candidates, registered_names(), "--candidates") if args.candidates else None
    channels = parse_list(args.channels)
    rep = discover(data, free=free, candidates=candidates, channels=channels, alpha=args.alpha)
    if args.plot:
        rep.plot(args.plot)
    if args.json:
        print(dumps_json(rep.to_dict(), "discover", indent=2))
    else:
        print(rep.report())
    return 0

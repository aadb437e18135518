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
    p.add_argument("more", nargs="*", metavar="DATA2",
                   help="more recordings (or FRF files with std) of the same rig, at other levels or repeated: "
                        "judged together, with a level-dependence test and the nonlinear block (SPEC §9)")
    add_model_options(p, "parameters fitted in every model (default m2,kp,R,L)")
    p.add_argument("--candidates", default=None, help="comma-separated effect names (default: all)")
    p.add_argument("--alpha", type=real(0, 1, lo_open=True, hi_open=True), default=1e-3,
                   help="level of the mismatch test (default 1e-3)")
    p.add_argument("--json", action="store_true", help="print exactly the SPEC §9 JSON document")
    p.add_argument("--plot", default=None, metavar="FIG.png",
                   help="measured vs nominal vs augmented FRFs and residuals, bands shaded")
    p.add_argument("--save-model", default=None, metavar="MODEL.json",
                   help="recordings of a structure at several levels: write its model (linear part and joint, "
                        "SPEC §11) for `satmd predict`")
    p.add_argument("--driving-point", default=None, metavar="NAME",
                   help="with --save-model: the channel at the shaker (default: found from its modal constants, or "
                        "none); it fixes the joint's force in newtons")
    p.add_argument("--locate-only", action="store_true",
                   help="recordings of a structure at several levels: place and name the joint, fit no model of it "
                        "(seconds where the model takes minutes)")
    p.set_defaults(func=run)


def run(args):
    from ..discovery import discover
    from ..io import is_recording
    from .._progress import stages
    from ._common import Progress, check_outputs, estimate_notes, load_recording_args, parse_band, plot_suffixes

    from ..errors import SatmdError

    if args.save_model:
        check_outputs([("--save-model", args.save_model, (".json",))], inputs=[args.data, *args.more])
    if args.driving_point and not args.save_model:
        raise SatmdError("--driving-point applies to a structure's model: give --save-model too")
    if args.locate_only and (args.save_model or not args.more):
        raise SatmdError("--locate-only applies to several recordings of a structure, without --save-model "
                         "(the model is what it leaves out)")
    free = parse_list(args.free) or DEFAULT_FREE
    candidates = parse_names(args.candidates, registered_names(), "--candidates") if args.candidates else None
    channels = parse_list(args.channels)
    told = Progress("discover")
    if args.more:  # several recordings of one rig (issue 26)
        items = [_load_one(args, path) for path in (args.data, *args.more)]
        if args.driving_point and hasattr(items[0], "fs_hz") and args.driving_point not in items[0].channels:
            raise SatmdError(f"--driving-point {args.driving_point}: no such channel in {args.data} "
                             f"(channels: {', '.join(c for c in items[0].channels if c != 'force')})")
        with stages(lambda text: told.step(text, force=True)):  # a structure's model takes minutes: say what runs
            rep = discover(items, free=free, candidates=candidates, channels=channels, alpha=args.alpha,
                           fit_joint=not args.locate_only)
    elif is_recording(args.data):  # the library's own path: estimate, discover, test linearity
        if args.plot:  # every output is checked before the first piece of work
            check_outputs([("--plot", args.plot, plot_suffixes())], inputs=[args.data])
        rec = load_recording_args(args, args.data)
        lo, hi = parse_band(getattr(args, "band", None))
        rep = discover(rec, free=free, candidates=candidates, channels=channels, alpha=args.alpha,
                       band_hz=None if lo is None and hi is None else (lo, hi))
        estimate_notes(args, rep.estimator, rep.estimator.get("measurement", []))
    else:
        rep = discover(load_data(args), free=free, candidates=candidates, channels=channels, alpha=args.alpha)
    if args.save_model:
        model = rep.model if rep.model is not None else _linear_structure(args, items if args.more else None, told)
        if args.driving_point:
            from ..structure.newtons import in_newtons

            model = in_newtons(model, args.driving_point)
        model.save(args.save_model)
    if args.plot:
        rep.plot(args.plot)
    if args.json:
        print(dumps_json(rep.to_dict(), "discover", indent=2))
    else:
        print(rep.report())
    return 0


def _linear_structure(args, items, told):
    """The model a structure with no joint gets (SPEC §11: its linear part predicts every level), or a refusal
    that says what the recordings lack."""
    from ..errors import DataError, SatmdError

    if not items or not all(hasattr(r, "fs_hz") for r in items):
        raise SatmdError("--save-model: a structure's model is fitted from time recordings at two or more levels "
                         "(a periodic force, two or more response channels); these are "
                         + ("one recording" if not items else "FRF files"))
    from ..structure import fit_structure

    told.step("no joint: the structure's linear model from the lowest level, for `satmd predict` ...", force=True)
    try:
        return fit_structure(items, channels=parse_list(args.channels), progress=lambda text: None)
    except DataError as exc:
        raise SatmdError(f"--save-model: {exc}") from None


def _load_one(args, path):
    """One of several DATA: a Recording as it is (the FRFs are estimated together), or FRFs in --band."""
    from ..io import is_recording, load_frf
    from ._common import load_recording_args, parse_band

    if is_recording(path):
        return load_recording_args(args, path)
    lo, hi = parse_band(getattr(args, "band", None))
    data = load_frf(path)
    return data.band(lo, hi) if (lo is not None or hi is not None) else data

"""satmd predict: simulate recordings' forces through a saved structure model (SPEC §11)."""
from __future__ import annotations

import sys

from ._recording import add_recording_options


def register(sub):
    p = sub.add_parser("predict", help="simulate recordings through a saved structure model",
                       description="Simulate each recording's force through a structure model written by "
                                   "`satmd discover ... --save-model` (from rest; a periodic force from one period "
                                   "before the record) and compare with its responses: NRMSE per channel, with the "
                                   "joint and without (the linear part alone). A level outside the fitted range is "
                                   "flagged `extrapolated`.")
    p.add_argument("model", metavar="MODEL.json", help="a model saved by satmd discover --save-model")
    p.add_argument("recordings", nargs="+", metavar="REC", help="time recordings with the model's channels and force")
    p.add_argument("--map", default=None, metavar="MAP",
                   help="channel names, e.g. force=Force,acc1=Acceleration[1] (the model's names on the left)")
    add_recording_options(p)
    p.add_argument("--json", action="store_true", help="print the SPEC §11 satmd-prediction/1 document")
    p.add_argument("--plot", default=None, metavar="FIG.png",
                   help="measured, linear and nonlinear responses of the first recording (time and spectrum)")
    p.set_defaults(func=run)


def run(args):
    from ..errors import SatmdError
    from ..structure.model import PREDICTION_SCHEMA, StructureModel
    from ._common import check_outputs, dumps_json, plot_suffixes
    from ._recording import load_recording_args

    if args.plot:
        check_outputs([("--plot", args.plot, plot_suffixes())], inputs=[args.model, *args.recordings])
    model = StructureModel.load(args.model)
    out = []
    for path in args.recordings:
        rec = load_recording_args(args, path)
        other = [c for c in rec.channels if c != "force" and c not in model.channels]
        if other:  # a sensor the model was not fitted with: said, not predicted (and not refused)
            print(f"satmd predict: note: {path}: {', '.join(other)} not in the model (it predicts "
                  f"{', '.join(model.channels)}): not predicted", file=sys.stderr)
        try:
            out.append(model.predict(rec, file=str(path)))
        except SatmdError as err:
            raise SatmdError(str(err) if str(path) in str(err) else f"{path}: {err}") from None
    if args.plot:
        out[0].plot(args.plot)
    if args.json:
        print(dumps_json({"schema": PREDICTION_SCHEMA, "recordings": [p.to_dict() for p in out]}, "predict", indent=2))
    else:
        print(model.report().splitlines()[0])
        print("\n".join(p.report() for p in out))
    return 0

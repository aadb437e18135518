"""satmd inverse: train, apply and evaluate the amortized inverse (use case II)."""
from __future__ import annotations

from ..errors import SatmdError
from ._common import SEED, check_outputs, dumps_json, integer, real

KINDS = ("physics", "supervised", "hybrid", "optimization")


def register(sub):
    p = sub.add_parser("inverse", help="amortized inverse: acceleration FRFs -> shunt R, L",
                       description="Train an inverse model on synthetic FRFs, predict R and L of measured FRFs, "
                                   "or evaluate on the paper's six blind pairs (SPEC §5).")
    isub = p.add_subparsers(dest="action", required=True, metavar="ACTION")

    t = isub.add_parser("train", help="train an inverse model and save it to a folder",
                        description="Train an inverse model (deep ensemble of the SPEC §5 net) and save it as "
                                    "model.json + weights.pt.")
    t.add_argument("--kind", default="physics", choices=KINDS,
                   help="physics (eq. 22 loss through the model), supervised (MSE on labels), hybrid (physics "
                        "net + least-squares refinement) or optimization (nothing to train)")
    t.add_argument("--preset", default="paper", choices=("paper", "box"),
                   help="paper: the 30 reference pairs with jitter; box: R, L independent (default paper)")
    t.add_argument("--noise", type=real(0, 1, hi_open=True), default=0.0, metavar="REL",
                   help="relative input noise during training, e.g. 0.01 (default 0)")
    t.add_argument("--epochs", type=integer(1), default=None, help="training epochs (default 90)")
    t.add_argument("--warm-start", type=integer(0), default=None, metavar="N",
                   help="supervised warm-start epochs before the physics loss (default 50)")
    t.add_argument("--samples-per-pair", type=integer(1), default=None,
                   help="paper preset: samples per pair (default 150)")
    t.add_argument("--samples", type=integer(1), default=None, help="box preset: number of samples (default 6000)")
    t.add_argument("--members", type=integer(1, 256), default=5, help="ensemble members (default 5)")
    t.add_argument("--seed", type=SEED, default=0, help="random seed (default 0)")
    t.add_argument("--device", default=None, help="cpu or cuda (default: cuda when present)")
    t.add_argument("--threads", type=integer(1), default=None,
                   help="torch CPU threads for training (default 1: the fastest for this small net)")
    t.add_argument("--quiet", action="store_true", help="no progress bar")
    t.add_argument("--out", required=True, metavar="DIR", help="folder for the saved model")
    t.set_defaults(func=run_train)

    q = isub.add_parser("predict", help="predict R and L of one FRF file",
                        description="Predict the shunt R and L (with standard deviations) of a measured FRF file "
                                    "(channels a1, a2) or time recording. Data on another grid are brought onto the "
                                    "model's (spline inside the data's span, the least-squares forward model outside "
                                    "it, with a warning), and the prediction is checked through the forward model.")
    q.add_argument("model", metavar="DIR", help="saved model folder")
    from ._common import add_data_options

    add_data_options(q)
    q.add_argument("--json", action="store_true", help="print JSON")
    q.set_defaults(func=run_predict)

    e = isub.add_parser("evaluate", help="the six blind pairs of the paper's Table 2",
                        description="Evaluate a saved model on the six blind (R, L) pairs of SPEC §5.")
    e.add_argument("model", metavar="DIR", help="saved model folder")
    e.add_argument("--noise", type=real(0, 1, hi_open=True), default=0.0, metavar="REL",
                   help="input noise on the blind FRFs (default 0)")
    e.add_argument("--seed", type=SEED, default=0, help="noise seed")
    e.add_argument("--json", action="store_true", help="print JSON")
    e.set_defaults(func=run_evaluate)


def check_device(device):
    """The library's device check (`satmd.inverse.training.check_device`), naming the option."""
    if device is None or device == "cpu":
        return
    from ..inverse.training import check_device as check

    try:
        check(device)
    except SatmdError as exc:
        raise SatmdError(f"--{exc}") from None


def _load(path):
    from ..inverse import InverseModel

    return InverseModel.load(path)


def run_train(args):
    from ..inverse import InverseModel

    # a size option of the other preset would be ignored: refuse it
    other = {"paper": ("samples", "--samples"), "box": ("samples_per_pair", "--samples-per-pair")}[args.preset]
    if getattr(args, other[0]) is not None:
        raise SatmdError(f"{other[1]} does not apply to --preset {args.preset}")
    from ..inverse.strategies import STRATEGIES

    if not STRATEGIES[args.kind].has_net:
        for flag, value in (("--epochs", args.epochs), ("--warm-start", args.warm_start)):
            if value is not None:
                raise SatmdError(f"{flag} does not apply to --kind {args.kind} (nothing is trained)")
    check_device(args.device)
    check_outputs([("--out", args.out, None)])
    given = {"epochs": args.epochs, "warm_start_epochs": args.warm_start, "samples_per_pair": args.samples_per_pair,
             "n_samples": args.samples, "threads": args.threads}
    # options left out keep the model's defaults (one source: InverseModel's signature)
    model = InverseModel(kind=args.kind, preset=args.preset, noise=args.noise, n_members=args.members, seed=args.seed,
                         device=args.device, verbose=not args.quiet,
                         **{k: v for k, v in given.items() if v is not None})
    model.fit()
    model.save(args.out)
    info = model.fit_info_
    line = (f"trained {args.kind} on preset {args.preset} (noise {args.noise:g}) in {info['train_s']:.1f} s "
            f"({info['train_cpu_s']:.0f} s CPU)")
    if "val_mae" in info:
        line += (f"; validation MAE R {info['val_mae'][0]:.4g} Ω, L {info['val_mae'][1]:.3g} H, "
                 f"2σ coverage {100 * info['val_coverage_2sd']:.1f} %")
    print(line)
    print(f"saved to {args.out}")


def run_predict(args):
    import sys
    import warnings

    from ..io import DataWarning
    from ._common import load_data

    model = _load(args.model)
    data = load_data(args)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DataWarning)
        p = model.predict_one(data)
    notes = list(dict.fromkeys(" ".join(str(w.message).split()) for w in caught if w.category is DataWarning))
    for w in caught:
        if w.category is not DataWarning:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    for note in notes:
        print(f"satmd inverse predict: warning: {note}", file=sys.stderr)
    if args.json:
        print(dumps_json({**p, "warnings": notes}, "inverse predict"))
        return
    print(f"R = {p['R']:.6g} ± {p['R_std']:.2g} Ω")
    print(f"L = {p['L']:.6g} ± {p['L_std']:.2g} H")
    verdict = "explained" if p["explained"] else "NOT explained: do not trust R, L"
    print(f"forward check: residual {p['residual']:.3g} = {p['residual_ratio']:.2g} x expected "
          f"{p['residual_expected']:.2g} (limit 3): {verdict}")


def run_evaluate(args):
    from ..inverse import PAPER_TABLE2, evaluate

    model = _load(args.model)
    res = evaluate(model, noise=args.noise, seed=args.seed)
    rows = []
    for i in range(res["n"]):
        rows.append({"R": res["R_true"][i], "L": res["L_true"][i], "R_pred": res["R"][i], "L_pred": res["L"][i],
                     "R_std": res["R_std"][i], "L_std": res["L_std"][i],
                     "abs_err_R": abs(res["R"][i] - res["R_true"][i]), "abs_err_L": abs(res["L"][i] - res["L_true"][i]),
                     "paper_R_pred": float(PAPER_TABLE2[i, 2]), "paper_L_pred": float(PAPER_TABLE2[i, 3])})
    summary = {k: res[k] for k in ("mae_R", "mae_L", "rel_R", "rel_L", "frf_error", "coverage", "infer_s_per_frf")}
    if args.json:
        print(dumps_json({"kind": model.kind, "preset": model.preset, "noise": args.noise, "rows": rows,
                          **summary, "paper": {"mae_R": 0.0823, "mae_L": 0.000572}}, "inverse evaluate", indent=1))
        return
    print(f"{model.kind} model (preset {model.preset}), six blind pairs, input noise {args.noise:g}")
    print(f"{'R':>6} {'L':>6} {'R_pred':>10} {'±':>8} {'L_pred':>9} {'±':>9} {'|eR|':>8} {'|eL|':>9}")
    for r in rows:
        print(f"{r['R']:6.1f} {r['L']:6.3f} {r['R_pred']:10.4f} {r['R_std']:8.2g} {r['L_pred']:9.5f} "
              f"{r['L_std']:9.2g} {r['abs_err_R']:8.4f} {r['abs_err_L']:9.2e}")
    print(f"MAE R {summary['mae_R']:.4f} Ω ({100 * summary['rel_R']:.2f} %), L {summary['mae_L']:.3e} H "
          f"({100 * summary['rel_L']:.2f} %); paper 0.0823 Ω, 5.72e-4 H")

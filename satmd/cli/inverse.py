"""satmd inverse: train, apply and evaluate the amortized inverse (use case II)."""
from __future__ import annotations

from ..errors import SatmdError
from ._common import SEED, check_outputs, dumps_json, integer, real

KINDS = ("physics", "supervised", "hybrid", "optimization")
MAX_EPOCHS = 10_000  # about an hour of training on the paper preset (0.3 s an epoch): more is a typo, not a plan
MAX_SAMPLES = 300_000  # training samples: 2.4 GB at SAMPLE_BYTES each
SAMPLE_BYTES = 8e3  # memory a training sample takes while training (its FRFs, features, their torch copies)
MAX_THREADS = 256  # more threads than any machine's cores only wait on each other (and torch crashes at 1e6)


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
    t.add_argument("--epochs", type=integer(1, MAX_EPOCHS), default=None,
                   help=f"training epochs, 1..{MAX_EPOCHS} (default 90)")
    t.add_argument("--warm-start", type=integer(0, MAX_EPOCHS), default=None, metavar="N",
                   help="supervised warm-start epochs before the physics loss, fewer than --epochs (default 50)")
    t.add_argument("--samples-per-pair", type=integer(1, MAX_SAMPLES // 30), default=None,
                   help=f"paper preset: samples per pair, 1..{MAX_SAMPLES // 30} (default 150)")
    t.add_argument("--samples", type=integer(2, MAX_SAMPLES), default=None,
                   help=f"box preset: number of samples, 2..{MAX_SAMPLES} (default 6000)")
    t.add_argument("--members", type=integer(1, 256), default=5, help="ensemble members (default 5)")
    t.add_argument("--seed", type=SEED, default=0, help="random seed (default 0)")
    t.add_argument("--device", default=None, help="cpu or cuda (default: cuda when present)")
    t.add_argument("--threads", type=integer(1, MAX_THREADS), default=None,
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


def _default(name):
    """An `InverseModel` default (one source: its signature)."""
    import inspect

    from ..inverse import InverseModel

    return inspect.signature(InverseModel.__init__).parameters[name].default


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
    if args.warm_start is not None and args.kind in ("physics", "hybrid"):
        epochs = args.epochs if args.epochs is not None else _default("epochs")
        if args.warm_start >= epochs:
            raise SatmdError(f"--warm-start {args.warm_start}: must be below --epochs {epochs} (the physics loss "
                             "trains in the epochs after the warm start)")
    elif args.warm_start is not None:
        raise SatmdError(f"--warm-start applies to --kind physics and hybrid (the {args.kind} kind has no physics "
                         "phase to warm up for)")
    from ..inverse import PAPER_PAIRS
    from ..io.limits import check_memory

    if args.preset == "paper" and args.samples_per_pair is not None:
        check_memory(f"--samples-per-pair {args.samples_per_pair}", SAMPLE_BYTES * len(PAPER_PAIRS) *
                     args.samples_per_pair, "use fewer samples")
    elif args.samples is not None:
        check_memory(f"--samples {args.samples}", SAMPLE_BYTES * args.samples, "use fewer samples")
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
    no_std = model._strategy().no_std(model)
    if "val_mae" in info:
        line += f"; validation MAE R {info['val_mae'][0]:.4g} Ω, L {info['val_mae'][1]:.3g} H"
        line += f", 2σ coverage {100 * info['val_coverage_2sd']:.1f} %" if not no_std else ""
    if no_std:
        line += f"; no std: {no_std.replace('train two or more members', 'train with --members 2 or more')}"
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
    p = {k: _no_std(v) if k.endswith("_std") else v for k, v in p.items()}  # NaN: no std (its reason is a warning)
    if args.json:
        print(dumps_json({**p, "warnings": notes}, "inverse predict"))
        return
    print(f"R = {_pm(p['R'], p['R_std'], 'Ω')}")
    print(f"L = {_pm(p['L'], p['L_std'], 'H')}")
    verdict = "explained" if p["explained"] else "NOT explained: do not trust R, L"
    print(f"forward check: residual {p['residual']:.3g} = {p['residual_ratio']:.2g} x expected "
          f"{p['residual_expected']:.2g} (limit 3): {verdict}")


def _no_std(x):
    """A std, or None where the model gives none (NaN): JSON null, said once by the model's warning."""
    import math

    return None if x is None or not math.isfinite(x) else x


def _pm(value, std, unit) -> str:
    """'30.1 ± 0.2 Ω', or '30.1 Ω (no std)'."""
    return f"{value:.6g} {unit} (no std)" if std is None else f"{value:.6g} ± {std:.2g} {unit}"


def run_evaluate(args):
    from ..inverse import PAPER_TABLE2, evaluate

    model = _load(args.model)
    res = evaluate(model, noise=args.noise, seed=args.seed)
    rows = []
    for i in range(res["n"]):
        rows.append({"R": res["R_true"][i], "L": res["L_true"][i], "R_pred": res["R"][i], "L_pred": res["L"][i],
                     "R_std": _no_std(res["R_std"][i]), "L_std": _no_std(res["L_std"][i]),
                     "abs_err_R": abs(res["R"][i] - res["R_true"][i]), "abs_err_L": abs(res["L"][i] - res["L_true"][i]),
                     "paper_R_pred": float(PAPER_TABLE2[i, 2]), "paper_L_pred": float(PAPER_TABLE2[i, 3])})
    summary = {k: res[k] for k in ("mae_R", "mae_L", "rel_R", "rel_L", "frf_error", "coverage", "infer_s_per_frf")}
    summary["coverage"] = _no_std(summary["coverage"])  # no std, no coverage (null, not a "not finite" note)
    if args.json:
        print(dumps_json({"kind": model.kind, "preset": model.preset, "noise": args.noise, "rows": rows,
                          **summary, "paper": {"mae_R": 0.0823, "mae_L": 0.000572}}, "inverse evaluate", indent=1))
        return
    print(f"{model.kind} model (preset {model.preset}), six blind pairs, input noise {args.noise:g}")
    print(f"{'R':>6} {'L':>6} {'R_pred':>10} {'±':>8} {'L_pred':>9} {'±':>9} {'|eR|':>8} {'|eL|':>9}")
    for r in rows:
        r_std, l_std = (f"{'-':>8}", f"{'-':>9}") if r["R_std"] is None or r["L_std"] is None else \
            (f"{r['R_std']:8.2g}", f"{r['L_std']:9.2g}")
        print(f"{r['R']:6.1f} {r['L']:6.3f} {r['R_pred']:10.4f} {r_std} {r['L_pred']:9.5f} "
              f"{l_std} {r['abs_err_R']:8.4f} {r['abs_err_L']:9.2e}")
    print(f"MAE R {summary['mae_R']:.4f} Ω ({100 * summary['rel_R']:.2f} %), L {summary['mae_L']:.3e} H "
          f"({100 * summary['rel_L']:.2f} %); paper 0.0823 Ω, 5.72e-4 H")

"""satmd identify: grey-box fit of m2, kp, R, L (or any free parameters) to an FRF file."""
from __future__ import annotations

from ..conventions import DEFAULT_FREE
from ..errors import SatmdError
from ._common import (add_data_options, add_model_options, dumps_json, load_data, one_line_warnings, parse_effect,
                      parse_kv, parse_list, real)


MAX_REG = 1e6  # the prior then outweighs the data a million times: the fit is the start (beyond, it overflows)


def register(sub):
    p = sub.add_parser("identify", help="fit model parameters to measured FRFs",
                       description="Global grey-box identification with scipy least squares and the analytic "
                                   "Jacobian; standard errors, correlations and fit statistics.")
    add_data_options(p)
    add_model_options(p, "parameters to fit (default m2,kp,R,L)")
    p.add_argument("--init", default=None, metavar="m2=0.3,...", help="start values (also the nominal values)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:key=value,...",
                   help="include a known effect in the model (repeatable)")
    p.add_argument("--reg", type=real(0, MAX_REG), default=0.0,
                   help=f"λ_reg of paper eq. 13, 0..{MAX_REG:g} (default 0: unbiased)")
    p.add_argument("--local", action="store_true", help="skip the global search (start from --init only)")
    p.add_argument("--ci", action="store_true", help="also compute 95 %% profile-likelihood intervals")
    p.add_argument("--json", action="store_true", help="print the result as JSON only")
    p.add_argument("--plot", default=None, metavar="FIG.png", help="measured vs fitted FRFs with residuals")
    p.set_defaults(func=run)


def run(args):
    from ..identification import identify
    from ..identification.intervals import describe_interval, intervals_to_dict

    data = load_data(args)
    free = parse_list(args.free) or DEFAULT_FREE
    channels = parse_list(args.channels)
    effects = [parse_effect(e) for e in args.effect]
    start = parse_kv(args.init, "--init") if args.init else None
    with one_line_warnings("identify"):  # poor fit / pinned: on stderr with --json (the report lists them)
        try:
            fit = identify(data, free=free, channels=channels, effects=effects, start=start, reg=args.reg,
                           global_search=not args.local, warn=bool(args.json))
        except SatmdError as exc:  # the library's start values are the command line's --init
            text = str(exc)
            if not (start and "start " in text and "outside the bounds" in text):
                raise
            raise SatmdError("--init " + text[text.index("start ") + len("start "):]) from None
    if args.plot:
        from ..plots import fit_figure, save

        pred = fit.prediction()
        fig = fit_figure(data, [("fitted model", pred.channels, {"color": "tab:blue", "lw": 1.2})],
                         [("fit", fit.standardised_residuals(), {"color": "tab:blue", "lw": 0.8})],
                         title=f"identify: χ²_red = {fit.chi2_reduced:.3g}, rel. error {fit.rel_error:.2e}")
        save(fig, args.plot)
    if args.json:
        out = fit.to_dict()
        if args.ci:
            ci = intervals_to_dict(fit.confidence_intervals())
            out["confidence_intervals_95"] = ci["intervals"]  # null: that side is open (see _open)
            out["confidence_intervals_95_open"] = ci["open"]
        if data.estimator:  # FRFs estimated from a recording: say how, and what the chain did (SPEC §9)
            out["estimator"] = {k: v for k, v in data.estimator.items() if k != "measurement"}
            out["measurement"] = [{k: m[k] for k in ("name", "explanation", "remedy")}
                                  for m in data.estimator.get("measurement", [])]
        print(dumps_json(out, "identify", indent=2))
        return 0
    print(fit.report())
    if args.ci:
        print("[[95 % profile-likelihood intervals]]")
        for name, (lo, hi) in fit.confidence_intervals().items():
            print(f"    {name:<10} {describe_interval(lo, hi)}")
    return 0

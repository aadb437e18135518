"""satmd tune: the best shunt setting (R, L or any rig parameters) for measured data or a model rig."""
from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from ..conventions import DEFAULT_FREE
from ..errors import DataError, SatmdError
from ._common import (check_outputs, check_rig_scale, name_list, dumps_json, load_data, one_line_warnings, parse_effect,
                      parse_kv, parse_list, parse_number, plot_suffixes, safe_text)

_DATA_TYPES = (".csv", ".uff", ".unv", ".mat", ".npz", ".txt", ".wav")


def register(sub):
    p = sub.add_parser("tune", help="best R and L (or any design) for a measured or modelled rig",
                       description="Identify the rig from DATA (running discovery and tuning on the augmented "
                                   "model when a significant mismatch is found) or take a model rig (--rig), "
                                   "then find the globally best setting: H∞ = true peak, H2 = RMS of |U1| or "
                                   "|A1| over the band. Several files or a folder: retune each step of a "
                                   "drifting rig and compare with keeping the first setting.")
    p.add_argument("data", metavar="DATA", nargs="*",
                   help="FRF file(s) or recording(s), or a folder of them (several: retuning over time)")
    p.add_argument("--rig", nargs="?", const="", default=None, metavar="KEY=VALUE,...",
                   help="tune a model rig instead of data: the paper's rig with these changes (any rig field, "
                        "e.g. m2=0.6,kp=1.2e5,R=22,L=0.064)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:key=value,...",
                   help="an effect of the model rig (with --rig; repeatable)")
    p.add_argument("--objective", choices=("hinf", "h2"), default="hinf",
                   help="hinf: true peak over the band (default); h2: RMS over the band")
    p.add_argument("--output", choices=("u1", "a1"), default="u1", help="response to reduce (default u1)")
    p.add_argument("--band", default="20:200", metavar="LO:HI", help="tuning band in Hz (default 20:200)")
    p.add_argument("--design", default="R,L", metavar="R,L", help="rig parameters to design (default R,L)")
    p.add_argument("--bounds", default=None, metavar="R=LO:HI,...",
                   help="search box per design variable (default R 0.1:1000, L 0.001:5, others ×/÷10)")
    p.add_argument("--current", default=None, metavar="R=22,L=0.064",
                   help="the current setting (default: the identified or given values)")
    p.add_argument("--robust", nargs="?", const=0.95, default=None, type=float, metavar="Q",
                   help="minimise the Q quantile (default 0.95) over the fit's parameter uncertainty")
    p.add_argument("--draws", type=int, default=128, help="parameter draws for --robust (default 128)")
    p.add_argument("--uncertainty", default=None, metavar="kp=5e3,...",
                   help="standard deviations for --robust (instead of the fit's covariance; needed with --rig)")
    p.add_argument("--free", type=name_list, default="m2,kp,R,L", help="parameters identified from DATA (default m2,kp,R,L)")
    p.add_argument("--channels", type=name_list, default=None, help="channels to fit (default a1,a2 when present)")
    p.add_argument("--force", action="store_true",
                   help="tune even when the SATMD model cannot describe DATA (model_adequate false); "
                        "without it such data are refused (exit 2)")
    p.add_argument("--no-discover", action="store_true",
                   help="tune on the nominal fit without looking for missing physics")
    p.add_argument("--data-band", default=None, metavar="LO:HI", help="use only LO <= f <= HI Hz of DATA")
    p.add_argument("--map", default=None, metavar="a1=NODE:DIR,a2=NODE:DIR", help="channel mapping for UFF files")
    p.add_argument("--freq-axis", default=None, metavar="START:STEP", help="frequency axis for .txt files")
    p.add_argument("--json", action="store_true", help="print the SPEC §10 JSON document only")
    p.add_argument("--plot", default=None, metavar="FIG.png", help="response before/after (or retuning over time)")
    p.add_argument("--levels", default=None, metavar="1,4,10",
                   help="tune R, L for a nonlinear rig: lowest worst-case peak over these drive levels (force RMS, N), "
                        "by direct simulation; with --nonlinear")
    p.add_argument("--nonlinear", action="append", default=[], metavar="NAME[:key=value,...]",
                   help="SPEC 8b element: with --rig its values (cubic_absorber_spring:k3=2e11); with DATA "
                        "(recordings) its name, fitted with m2, kp, R, L in the time domain")
    p.set_defaults(func=run)


def run(args):
    from ..tuning import retune, tune

    options = _tune_options(args)
    if (args.rig is None) == (not args.data):
        raise DataError("give DATA (a file, several files or a folder) or --rig, not both")
    files = data_files(args.data)
    if args.levels is not None or args.nonlinear:  # a nonlinear rig across drive levels
        from ._tune_levels import run_levels

        return run_levels(args, options["band_hz"], _model_rig, files)
    if args.plot:  # every output is checked before the first piece of work
        check_outputs([("--plot", args.plot, plot_suffixes())], inputs=files)
    if args.rig is not None:
        model = _model_rig(args)
        result = tune(model, effects=[parse_effect(e) for e in args.effect], **options)
    else:
        if args.effect:
            raise DataError("--effect describes a model rig (--rig); with DATA the effects are discovered")
        series = [_load(args, f) for f in files]
        if len(series) > 1:
            if args.robust is not None:
                raise DataError("--robust applies to one FRF, not to a series")
            free = parse_list(args.free) or DEFAULT_FREE
            options = {k: v for k, v in options.items() if k not in ("robust", "quantile", "n_draws", "uncertainty")}
            with one_line_warnings("tune"):
                result = retune(series, free=free, labels=[f.stem for f in files], **options)
            return _finish(args, result)
        try:
            result = tune(_identified(args, series[0]), force=args.force, **options)
        except SatmdError as exc:  # the library names its keyword; the command line names its option and the file
            raise DataError(_naming(files[0], str(exc).replace("force=True", "--force"))) from None
    return _finish(args, result)


def _naming(path, message: str) -> str:
    """``message`` about the data of ``path``, with the file named in front unless it already is."""
    return message if str(path) in message or path.name in message else f"{safe_text(path)}: {message}"


def _finish(args, result):
    if args.plot:
        result.plot(args.plot)
    if args.json:
        print(dumps_json(result.to_dict(), "tune", indent=2))
        return 0
    print(result.report())
    return 0


def _tune_options(args) -> dict:
    from ..tuning.objective import Objective
    from ..tuning.optimiser import DesignSpace

    lo, sep, hi = args.band.partition(":")
    if not sep:
        raise DataError(f"--band {args.band!r}: expected LO:HI in Hz")
    band = (parse_number(lo, "--band LO"), parse_number(hi, "--band HI"))
    _check_work(args, band)
    try:
        Objective(args.objective, args.output, band)  # validates the band now, before any work
    except DataError as exc:
        raise DataError(f"--band {args.band}: {exc}") from None
    design = parse_list(args.design)
    if not design:
        raise DataError("--design: give at least one rig parameter, e.g. R,L")
    bounds = {}
    for item in parse_list(args.bounds) or ():
        name, eq, rng = item.partition("=")
        a, colon, b = rng.partition(":")
        if not eq or not colon:
            raise DataError(f"--bounds {item!r}: expected NAME=LO:HI")
        bounds[name.strip()] = (parse_number(a, f"--bounds {name} LO"), parse_number(b, f"--bounds {name} HI"))
        for x in bounds[name.strip()]:
            _check_scale(f"--bounds {item}", name.strip(), x)
    try:  # names and bounds checked before any work
        DesignSpace.build(design, {n: 1.0 for n in design}, bounds)
    except DataError as exc:
        raise DataError(f"{'--bounds' if bounds and 'bounds' in str(exc) else '--design'}: {exc}") from None
    q = args.robust
    if q is not None and not 0.5 <= q < 1:
        raise DataError(f"--robust {q}: the quantile must lie in [0.5, 1)")
    current = parse_kv(args.current, "--current", lo=0.0) if args.current else None
    uncertainty = parse_kv(args.uncertainty, "--uncertainty", lo=0.0, lo_open=True) if args.uncertainty else None
    for flag, given in (("--current", current), ("--uncertainty", uncertainty)):
        for name, x in (given or {}).items():
            _check_scale(f"{flag} {name}={x:g}", name, x)
    if uncertainty and q is None:
        raise DataError("--uncertainty applies to --robust")
    return {"objective": args.objective, "output": args.output, "band_hz": band, "design": design,
            "bounds": bounds or None, "robust": q is not None, "quantile": q or 0.95, "n_draws": args.draws,
            "current": current, "uncertainty": uncertainty}


MAX_DRAWS = 4096  # about 4 minutes of robust tuning (55 s per 1000 draws, measured)
GRID_BYTES = 1.5e5  # memory per frequency of the tuning grid (measured: --band 1e-6:200, 4779 points, 670 MB)


def _check_scale(where, name, x):
    """A rig value (or bound, current setting, std) within a factor `RIG_SCALE` of the paper's rig (the
    optimiser's numbers overflow beyond): `satmd.cli._ranges.check_rig_scale`, one rule for every command."""
    try:
        check_rig_scale(where, name, x)
    except SatmdError as exc:
        raise DataError(str(exc)) from None


def _check_work(args, band):
    """Refuse up front what would exhaust memory (the band's grid) or run for hours (--draws)."""
    import math

    from ..io.limits import check_memory

    if not 16 <= args.draws <= MAX_DRAWS:
        raise DataError(f"--draws {args.draws}: need 16..{MAX_DRAWS} (about 55 s per 1000 draws)")
    if not 0 < band[0] < band[1]:
        raise DataError(f"--band {args.band}: need 0 < LO < HI")
    points = (math.log(band[1]) - math.log(band[0])) / 0.004  # satmd.tuning.objective.band_grid's spacing
    check_memory(f"--band {args.band} ({points:.3g} grid points)", points * GRID_BYTES, "narrow the band")


def _model_rig(args):
    from ..physics import Rig

    changes = parse_kv(args.rig, "--rig") if args.rig else {}
    for name, x in changes.items():
        if x != 0:
            _check_scale(f"--rig {name}={x:g}", name, x)
    try:
        return Rig().replace(**changes).validate()
    except ValueError as exc:
        raise DataError(f"--rig: {exc}") from None


def data_files(items) -> list[Path]:
    """DATA arguments as a list of files (a folder: its data files, sorted by name)."""
    files = []
    for item in items:
        path = Path(item)
        if path.is_dir():
            found = sorted(f for f in path.iterdir() if f.is_file() and f.suffix.lower() in _DATA_TYPES)
            if not found:
                raise DataError(f"{path}: no data files ({', '.join(_DATA_TYPES)}) in this folder")
            files += found
        elif path.is_file():
            files.append(path)
        else:
            raise DataError(f"{path}: no such file or folder")
    return files


def _load(args, path):
    ns = argparse.Namespace(data=str(path), band=args.data_band, band_flag="--data-band", map=args.map,
                            freq_axis=args.freq_axis, command="tune")
    return load_data(ns)


def _identified(args, data):
    """The model to tune: the discovery report (augmented model when a mismatch is found) or the fit."""
    free = parse_list(args.free) or DEFAULT_FREE
    channels = parse_list(args.channels)
    if args.no_discover:
        from ..identification import identify

        with one_line_warnings("tune"):
            return identify(data, free=free, channels=channels)
    from ..discovery import discover
    from ..errors import PinnedParameterWarning, PoorFitWarning

    with one_line_warnings("tune"), warnings.catch_warnings():
        for category in (PoorFitWarning, PinnedParameterWarning):  # discovery fits wrong models on purpose;
            warnings.simplefilter("ignore", category)  # its report speaks for them; other warnings are shown
        rep = discover(data, free=free, channels=channels)
    if rep.significant_mismatch and rep.model_adequate:
        found = ", ".join(rep.effect_names) or "nothing in the vocabulary"
        print(f"satmd tune: note: discovery found a significant mismatch ({found}); "
              "tuning on the augmented model", file=sys.stderr)
    return rep

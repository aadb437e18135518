"""satmd tune --levels: R, L for a nonlinear rig, worst case over drive levels (issue 27 item 4).

Two ways in:

- a model rig: ``satmd tune --rig m2=0.55 --nonlinear cubic_absorber_spring:k3=2e11 --levels 1,4,10``
- recordings of the rig (force, acc1, acc2; e.g. one per drive level):
  ``satmd tune low.csv high.csv --nonlinear cubic_absorber_spring --levels 1,4,10``: the element
  and m2, kp, R, L are fitted in the time domain (`fit_nonlinear`) and the fitted model is tuned.

Either way `satmd.tuning.nonlinear.tune_nonlinear` settles the design by direct simulation at
every level and reports what the low-level linear tuning costs.
"""
from __future__ import annotations

import math

from ..errors import DataError
from ._common import check_element_range, dumps_json, one_line_warnings, parse_kv, parse_list, parse_number

MAX_LEVELS = 12  # each level is one batched direct simulation per candidate grid (~1 s each)
MAX_LEVEL_N = 1e12  # the most force RMS a level may ask for (as `satmd simulate --level`)


def parse_levels(text: str) -> list[float]:
    """'1,4,10' -> [1.0, 4.0, 10.0]: drive levels (force RMS, N), each > 0, at most `MAX_LEVELS`.

    Parameters
    ----------
    text : comma-separated numbers.

    Returns
    -------
    list of float
    """
    items = parse_list(text) or ()
    if not items:
        raise DataError("--levels: give drive levels (force RMS in N), e.g. --levels 1,4,10")
    levels = [parse_number(x, "--levels") for x in items]
    bad = [x for x in levels if not 0 < x <= MAX_LEVEL_N]
    if bad:
        raise DataError(f"--levels {text}: every level must be a force RMS > 0 N, at most {MAX_LEVEL_N:g} N; "
                        f"got {bad[0]:g}")
    if len(levels) > MAX_LEVELS:
        raise DataError(f"--levels {text}: at most {MAX_LEVELS} levels")
    return sorted(set(levels))


def _element(text: str, fitted: bool):
    """--nonlinear NAME[:key=value,...] -> a NonlinearElement (model rig) or the name (to fit)."""
    from ..physics import NONLINEAR, nonlinear_element

    name, _, kv = text.partition(":")
    name = name.strip()
    if name not in NONLINEAR:
        raise DataError(f"--nonlinear {text!r}: unknown element; known: {', '.join(NONLINEAR)}")
    if fitted:
        if kv:
            raise DataError(f"--nonlinear {text!r}: with DATA the element's parameters are fitted; give the name only")
        return name
    if not kv:
        raise DataError(f"--nonlinear {text!r}: with --rig give the element's parameters, e.g. "
                        "cubic_absorber_spring:k3=2e11")
    try:
        element = nonlinear_element(name, **parse_kv(kv, f"--nonlinear {name}"))
        check_element_range(f"--nonlinear {text}", element)
    except (TypeError, ValueError) as exc:
        raise DataError(str(exc) if str(exc).startswith("--nonlinear") else f"--nonlinear {text!r}: {exc}") from None
    return element


def run_levels(args, band, model_rig, files) -> int:
    """Tune R, L over ``--levels`` for a model rig with ``--nonlinear`` elements, or for recordings.

    Parameters
    ----------
    args : the parsed `satmd tune` arguments.
    band : (lo, hi) tuning band [Hz] (already validated).
    model_rig : callable returning the --rig model (used when DATA is absent).
    files : DATA files (recordings).

    Returns
    -------
    int
        0 (errors raise DataError: exit 2).
    """
    from ..tuning.nonlinear import tune_nonlinear

    if args.levels is None:
        raise DataError("--nonlinear in satmd tune needs --levels (the drive levels to tune over, e.g. 1,4,10)")
    levels = parse_levels(args.levels)
    for flag, bad in (("--objective h2", args.objective != "hinf"), ("--robust", args.robust is not None),
                      ("--effect", bool(args.effect)), ("--current", args.current is not None),
                      ("--uncertainty", args.uncertainty is not None), ("--plot", args.plot is not None)):
        if bad:
            raise DataError(f"{flag} does not apply with --levels (the worst-case H∞ peak over levels is minimised)")
    if tuple(parse_list(args.design) or ()) != ("R", "L"):
        raise DataError("--levels designs R and L only (--design R,L)")
    if not args.nonlinear:
        raise DataError("--levels tunes a nonlinear rig: give --nonlinear NAME (a linear rig's tuning does not "
                        "depend on the drive level)")
    if len(args.nonlinear) > 1:
        raise DataError("--levels: give one --nonlinear element")
    fit = None
    if files:
        from ..identification.nonlinear.fit import fit_nonlinear
        from ..io import is_recording, load_recording

        recs = []
        for f in files:
            if not is_recording(f):
                raise DataError(f"{f}: --levels with DATA needs time recordings (force, acc1, acc2), not FRFs")
            recs.append(load_recording(f, channel_map=args.map))
        with one_line_warnings("tune"):
            fit = fit_nonlinear(recs, _element(args.nonlinear[0], fitted=True))
        rig, elements = fit.rig, [fit.element]
    else:
        rig = model_rig(args)
        elements = [_element(t, fitted=False) for t in args.nonlinear]
    result = tune_nonlinear(rig, elements, levels, band, output=args.output)
    if not all(math.isfinite(x) for x in (result.worst_db, *result.peaks_db)):  # the integrator overflowed
        raise DataError(f"--levels {args.levels} with --nonlinear {args.nonlinear[0]}: the direct simulation is not "
                        "finite (the element is too strong at these drive levels); lower --levels or weaken the "
                        "element")
    if args.json:
        doc = {"schema": "satmd-tune-levels/1", **result.to_dict()}
        if fit is not None:
            doc["nonlinear"] = fit.finding()
            doc["fit"] = {k: v for k, v in fit.to_dict().items() if k != "finding"}
        print(dumps_json(doc, "tune", indent=2))
        return 0
    if fit is not None:
        print(fit.report())
    print(result.report())
    return 0

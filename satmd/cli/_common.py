"""Argument parsing shared by the subcommands."""
from __future__ import annotations

import argparse
import contextlib
import sys
import warnings

import numpy as np

from ..errors import SatmdError
from ..physics import Rig, effect


def parse_number(text: str, what: str) -> float:
    try:
        x = float(text)
    except ValueError:
        raise SatmdError(f"{what}: {text!r} is not a number") from None
    if not np.isfinite(x):
        raise SatmdError(f"{what}: {text!r} is not finite")
    return x


def parse_freq(text: str) -> np.ndarray:
    """LO:HI:N -> linspace(LO, HI, N)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise SatmdError(f"--freq {text!r}: expected LO:HI:N, e.g. 40:130:60")
    lo, hi = parse_number(parts[0], "--freq LO"), parse_number(parts[1], "--freq HI")
    try:
        n = int(parts[2])
    except ValueError:
        raise SatmdError(f"--freq {text!r}: N must be an integer") from None
    if not (0 < lo < hi) or n < 2:
        raise SatmdError(f"--freq {text!r}: need 0 < LO < HI and N >= 2")
    return np.linspace(lo, hi, n)


def parse_band(text: str | None):
    if not text:
        return None, None
    lo, sep, hi = text.partition(":")
    if not sep:
        raise SatmdError(f"--band {text!r}: expected LO:HI in Hz")
    lo = parse_number(lo, "--band LO") if lo else None
    hi = parse_number(hi, "--band HI") if hi else None
    if lo is not None and hi is not None and lo >= hi:
        raise SatmdError(f"--band {text!r}: LO must be below HI")
    return lo, hi


def parse_kv(text: str, what: str) -> dict:
    """'a=1,b=2' -> {'a': 1.0, 'b': 2.0}."""
    out = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise SatmdError(f"{what}: {item!r} is not key=value")
        out[key.strip()] = parse_number(value.strip(), f"{what} {key.strip()}")
    return out


def parse_effect(text: str):
    """'extra_mode:f_hz=66,zeta=0.01' or 'parameter_offset:k1:value=2e5' -> Effect."""
    name, params = text, {}
    if "=" in text:
        name, _, kv = text.rpartition(":")
        if not name:
            raise SatmdError(f"--effect {text!r}: expected NAME:key=value,...")
        params = parse_kv(kv, f"--effect {name}")
    try:
        return effect(name, **params)
    except (TypeError, ValueError) as exc:
        raise SatmdError(f"--effect {text!r}: {exc}") from None


def parse_list(text: str | None) -> tuple[str, ...] | None:
    """'a, b,c' -> ('a', 'b', 'c'); None or '' -> None."""
    if not text:
        return None
    return tuple(s.strip() for s in text.split(",") if s.strip()) or None


def add_model_options(parser: argparse.ArgumentParser, free_help: str):
    """--free and --channels, shared by the commands that fit the model."""
    parser.add_argument("--free", default="m2,kp,R,L", help=free_help)
    parser.add_argument("--channels", default=None, help="channels to fit (default a1,a2 when present)")


def parse_names(text: str, allowed, what: str) -> tuple[str, ...]:
    names = parse_list(text) or ()
    bad = [n for n in names if n not in allowed]
    if bad or not names:
        raise SatmdError(f"{what}: unknown {', '.join(bad) or '(empty)'}; choose from {', '.join(allowed)}")
    return names


def add_rig_options(parser: argparse.ArgumentParser, names=("m2", "kp", "R", "L")):
    for n in names:
        parser.add_argument(f"--{n}", type=float, default=None, help=f"{n} (default {getattr(Rig(), n):g})")


def rig_from_args(args, names=("m2", "kp", "R", "L")) -> Rig:
    changes = {n: getattr(args, n) for n in names if getattr(args, n, None) is not None}
    return Rig().replace(**changes).validate()


def add_data_options(parser: argparse.ArgumentParser):
    """DATA positional plus the options every data-taking command shares."""
    parser.add_argument("data", metavar="DATA",
                        help="FRF file (.csv, .uff/.unv, .mat, .npz, .txt) or a time recording "
                             "(.csv, .uff, .wav, .npz, .mat; FRFs are then estimated with default settings)")
    parser.add_argument("--band", default=None, metavar="LO:HI", help="use only LO <= f <= HI Hz")
    parser.add_argument("--map", default=None, metavar="a1=NODE:DIR,a2=NODE:DIR",
                        help="channel mapping for UFF files with more than two responses (or a1=#N: dataset N)")
    parser.add_argument("--freq-axis", default=None, metavar="START:STEP",
                        help="frequency axis in Hz for .txt files of complex values (one per line)")


@contextlib.contextmanager
def one_line_warnings(command: str):
    """Show warnings raised while loading data as one line each on stderr (no source lines)."""
    from ..io import DataWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DataWarning)  # others keep their default filters
        try:
            yield
        finally:
            seen = set()
            for w in caught:
                text = " ".join(str(w.message).split())
                if text not in seen:
                    seen.add(text)
                    print(f"satmd {command}: warning: {text}", file=sys.stderr)


def load_data(args):
    """Load DATA with the --band, --map and --freq-axis options applied.

    A time recording is turned into FRFs with `satmd.io.estimate_frf`'s
    defaults (a note on stderr says so; `satmd estimate-frf` gives control).
    """
    from ..io import estimate_frf, is_recording, load_frf, load_recording

    command = getattr(args, "command", None) or "satmd"
    lo, hi = parse_band(getattr(args, "band", None))
    with one_line_warnings(command):
        if is_recording(args.data):
            rec = load_recording(args.data, channel_map=getattr(args, "map", None))
            data = estimate_frf(rec, band=(lo, hi))
            m = data.meta
            print(f"satmd {command}: note: {args.data} is a time recording: FRFs estimated with {m['estimator']}, "
                  f"nperseg={m['nperseg']} ({m['resolution_hz']} Hz), {m['segments']} averages "
                  f"(use `satmd estimate-frf` for control)", file=sys.stderr)
            return data
        options = {}
        if getattr(args, "map", None):
            options["channel_map"] = args.map
        if getattr(args, "freq_axis", None):
            options["freq_axis"] = args.freq_axis
        data = load_frf(args.data, **options)
    return data.band(lo, hi) if (lo is not None or hi is not None) else data

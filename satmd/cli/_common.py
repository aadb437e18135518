"""Argument parsing shared by the subcommands."""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from numbers import Integral, Real
from pathlib import Path

import numpy as np

from ..validation import Interval
from ..conventions import DEFAULT_FREE
from ..errors import FormatError, SatmdError
from ..physics import Rig, effect
from ._ranges import check_element_range, check_rig_scale  # noqa: F401 - the commands take them from here

# Upper bounds that keep memory bounded (one place: satmd.io.limits); refused up front with the number asked for.
from ..io.limits import MAX_FREQ_POINTS, MAX_SAMPLES  # noqa: E402,F401 - the commands import them from here


# --- option types: argparse names the option in its message ---------------------
def _bounded(convert, allowed, noun: str, finite: bool):
    """An argparse ``type`` converting with `convert` and checking `allowed`; `noun` names the kind in messages."""

    def parse(text):
        try:
            x = convert(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {noun}") from None
        if finite and not math.isfinite(x):
            raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
        if not allowed.accepts(x):
            raise argparse.ArgumentTypeError(f"{text} must be {allowed.bounds_text()}")
        return x

    parse.__name__ = noun.split()[-1]
    return parse


def real(lo=None, hi=None, *, lo_open=False, hi_open=False):
    """An argparse ``type``: a finite float within [lo, hi] (open ends with lo_open / hi_open)."""
    allowed = Interval(Real, lo, hi, {(0, 0): "", (1, 0): "lo", (0, 1): "hi", (1, 1): "both"}[bool(lo_open), bool(hi_open)])
    return _bounded(float, allowed, "a number", finite=True)


def integer(lo=None, hi=None):
    """An argparse ``type``: an integer within [lo, hi]."""
    return _bounded(int, Interval(Integral, lo, hi), "an integer", finite=False)


SEED = integer(0, 2 ** 32 - 1)  # numpy and torch take non-negative seeds


def refuse_unused(args, parser_defaults: dict, when: str):
    """Refuse options that do not apply in this mode (instead of ignoring them silently).

    ``parser_defaults`` maps dest -> (flag, default); an option counts as given
    when its value differs from the default. ``when`` completes "X applies ...".
    """
    given = [flag for dest, (flag, default) in parser_defaults.items() if getattr(args, dest, default) != default]
    if given:
        raise SatmdError(f"{', '.join(given)} {'applies' if len(given) == 1 else 'apply'} {when}")


class OptionGroup:
    """An argparse argument group that keeps the actions added to it (argparse's own list is private)."""

    def __init__(self, group):
        self.group, self.actions = group, []

    def add_argument(self, *args, **kwargs):
        """``group.add_argument``, remembering the action it returns."""
        self.actions.append(self.group.add_argument(*args, **kwargs))
        return self.actions[-1]


def option_defaults(actions) -> dict:
    """dest -> (flag, default) of argparse actions (those `add_argument` returned; for `refuse_unused`)."""
    return {a.dest: (a.option_strings[0], a.default) for a in actions if a.option_strings}


# --- outputs: checked before any work ---------------------------------------------
def plot_suffixes() -> tuple[str, ...]:
    """Figure formats matplotlib's Agg backend writes (raw buffers aside)."""
    from ..plots import pyplot

    pyplot()
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    return tuple(sorted("." + s for s in FigureCanvasAgg.get_supported_filetypes() if s not in ("raw", "rgba")))


def check_outputs(outputs, inputs=()):
    """Refuse unusable outputs before any work is done.

    ``outputs``: (flag, path, allowed suffixes or None for a folder) for each
    output given; ``inputs``: paths read by the command. An output must not be
    an input, another output, or (for a file) an existing folder; its folder
    must exist and be writable; a file needs a suffix from ``allowed``.
    """
    seen = {}
    real_inputs = {os.path.realpath(p): str(p) for p in inputs if p}
    for flag, path, allowed in outputs:
        if path is None:
            continue
        path = Path(path)
        where = f"{flag} {path}"
        key = os.path.realpath(path)
        if key in real_inputs:
            raise SatmdError(f"{where}: is also the input {real_inputs[key]}; choose another output name")
        if key in seen:
            raise SatmdError(f"{where}: also given as {seen[key]}; choose different names")
        seen[key] = flag
        if allowed is None:  # a folder, created when missing
            parent = path
            while not parent.exists() and parent != parent.parent:  # the folders up to it are created
                parent = parent.parent
            if not parent.is_dir():
                raise SatmdError(f"{where}: {parent} exists and is not a folder")
        else:
            if path.is_dir():
                raise SatmdError(f"{where}: is a folder; give a file name")
            if path.suffix.lower() not in allowed:
                raise SatmdError(f"{where}: cannot write {path.suffix or 'files without a suffix'!r} "
                                 f"(use {', '.join(allowed)})")
            parent = path.parent
            if not parent.is_dir():
                raise SatmdError(f"{where}: folder {parent} does not exist")
        if parent.exists() and not os.access(parent, os.W_OK | os.X_OK):
            raise SatmdError(f"{where}: folder {parent} is not writable")


# --- JSON: never NaN or Infinity ---------------------------------------------------
def dumps_json(obj, command: str, **kw) -> str:
    """JSON text with non-finite numbers written as null (standard JSON has no NaN); a note names them."""
    from ..jsonsafe import jsonable

    nulled: list[str] = []
    text = json.dumps(jsonable(obj, nulled), allow_nan=False, **kw)
    if nulled:
        shown = ", ".join(nulled[:6]) + (f" and {len(nulled) - 6} more" if len(nulled) > 6 else "")
        print(f"satmd {command}: note: not finite, written as null: {shown}", file=sys.stderr)
    return text


# --- progress on stderr --------------------------------------------------------------
class Progress:
    """Stage lines for long work on stderr, at most one every ``every`` seconds unless forced.

    ``satmd explain`` and friends call ``step(text)``; ``quiet`` silences it.
    """

    def __init__(self, command: str, quiet: bool = False, every: float = 5.0):
        self.command, self.quiet, self.every = command, quiet, every
        self.t0 = self.last = time.perf_counter()

    def step(self, text: str, force: bool = False):
        now = time.perf_counter()
        if self.quiet or (not force and now - self.last < self.every):
            return
        self.last = now
        print(f"satmd {self.command}: [{now - self.t0:5.0f} s] {text}", file=sys.stderr, flush=True)


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
    if lo < 1e-9 or hi > 1e9:
        raise SatmdError(f"--freq {text!r}: LO and HI must lie in 1e-9..1e9 Hz")
    if n > MAX_FREQ_POINTS:
        raise SatmdError(f"--freq {text!r}: {n} points is more than the {MAX_FREQ_POINTS} satmd computes at once")
    return np.linspace(lo, hi, n)


def parse_band(text: str | None, what: str = "--band"):
    """'LO:HI' (either may be empty) -> (lo, hi) in Hz; ``what`` names the option in messages."""
    if not text:
        return None, None
    lo_text, sep, hi_text = text.partition(":")
    if not sep:
        raise SatmdError(f"{what} {text!r}: expected LO:HI in Hz")
    lo = parse_number(lo_text, f"{what} LO") if lo_text else None
    hi = parse_number(hi_text, f"{what} HI") if hi_text else None
    if lo is not None and hi is not None and lo >= hi:
        raise SatmdError(f"{what} {text!r}: LO must be below HI")
    for x, end in ((lo, "LO"), (hi, "HI")):
        if x is not None and not 0 <= x <= 1e9:
            raise SatmdError(f"{what} {text!r}: {end} must lie in 0..1e9 Hz")
    return lo, hi


def parse_kv(text: str, what: str, lo: float | None = None, lo_open: bool = False) -> dict:
    """'a=1,b=2' -> {'a': 1.0, 'b': 2.0}; a key given twice, or a value below ``lo``, is refused."""
    out = {}
    for item in filter(None, (s.strip() for s in text.split(","))):
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise SatmdError(f"{what}: {item!r} is not key=value")
        key = key.strip()
        if key in out:
            raise SatmdError(f"{what}: {key} given twice")
        x = parse_number(value.strip(), f"{what} {key}")
        if lo is not None and (x < lo or (lo_open and x == lo)):
            raise SatmdError(f"{what} {key}={value.strip()}: must be {'>' if lo_open else '>='} {lo:g}")
        out[key] = x
    if not out:
        raise SatmdError(f"{what} {text!r}: give key=value pairs")
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


def name_list(text: str) -> str:
    """An argparse ``type``: a comma-separated list, not empty ('--free ""' is a mistake), no name twice."""
    names = parse_list(text)
    if not names:
        raise argparse.ArgumentTypeError(f"{text!r} names nothing; give comma-separated names")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise argparse.ArgumentTypeError(f"{text!r} names {', '.join(twice)} twice (the data would count twice)")
    return text


def add_model_options(parser: argparse.ArgumentParser, free_help: str):
    """--free and --channels, shared by the commands that fit the model."""
    parser.add_argument("--free", type=name_list, default="m2,kp,R,L", help=free_help)
    parser.add_argument("--channels", type=name_list, default=None, help="channels to fit (default a1,a2 when present)")


def parse_names(text: str, allowed, what: str) -> tuple[str, ...]:
    names = parse_list(text) or ()
    bad = [n for n in names if n not in allowed]
    if bad or not names:
        raise SatmdError(f"{what}: unknown {', '.join(bad) or '(empty)'}; choose from {', '.join(allowed)}")
    return names


def add_rig_options(parser: argparse.ArgumentParser, names=DEFAULT_FREE):
    for n in names:
        parser.add_argument(f"--{n}", type=real(), default=None, help=f"{n} (default {getattr(Rig(), n):g})")


def rig_from_args(args, names=DEFAULT_FREE) -> Rig:
    changes = {n: getattr(args, n) for n in names if getattr(args, n, None) is not None}
    for n, x in changes.items():
        check_rig_scale(f"--{n} {x:g}", n, x)
    try:
        return Rig().replace(**changes).validate()
    except ValueError as exc:  # name the option: "--m2 -1: rig parameter m2 must be > 0"
        bad = next((n for n in changes if f" {n} " in f" {exc} "), None)
        raise SatmdError(f"--{bad} {changes[bad]:g}: {exc}" if bad else str(exc)) from None


def add_data_options(parser: argparse.ArgumentParser):
    """DATA positional plus the options every data-taking command shares."""
    parser.add_argument("data", metavar="DATA",
                        help="FRF file (.csv, .uff/.unv, .mat, .npz, .txt) or a time recording "
                             "(.csv, .uff, .wav, .npz, .mat; FRFs are then estimated with default settings)")
    parser.add_argument("--band", default=None, metavar="LO:HI", help="use only LO <= f <= HI Hz")
    parser.add_argument("--map", default=None, metavar="a1=NODE:DIR,a2=NODE:DIR",
                        help="which record/column is which channel: UFF (a1=NODE:DIR or a1=#N), WAV (#N), .mat/.npz "
                             "(force=Force,a1=Acceleration[2]: a variable or a row), a lab's CSV (a1=Acc wing); a recording "
                             "takes a3, a4, ... too (FRFs use a1 and a2)")
    parser.add_argument("--freq-axis", default=None, metavar="START:STEP",
                        help="frequency axis in Hz for .txt files of complex values (one per line)")
    add_recording_options(parser)


from ._recording import add_recording_options, load_recording_args  # noqa: E402,F401 - shared by the commands
from ._text import cli_text, one_line_warnings, safe_text, with_flags  # noqa: E402,F401 - shared by the commands


def estimate_notes(args, estimator: dict, measurement) -> None:
    """The stderr notes on FRFs estimated from a time recording: how, and what the chain did to them."""
    from ..signal.estimate import describe_estimate

    if not estimator:
        return
    command = getattr(args, "command", None) or "satmd"
    print(f"satmd {command}: note: {safe_text(args.data)} is a time recording: FRFs estimated by "
          f"{describe_estimate(estimator)} (use `satmd estimate-frf` for control)", file=sys.stderr)
    for finding in measurement:
        if isinstance(finding, dict) and "remedy" in finding:
            print(f"satmd {command}: measurement: {finding['explanation']}; remedy: {finding['remedy']}",
                  file=sys.stderr)


def load_data(args):
    """Load DATA with the --band, --map and --freq-axis options applied.

    ``args.band_flag``, when set, is what the command calls its --band option
    (``tune``: ``--data-band``), so that refusals name the option as typed.

    A time recording is turned into FRFs with `satmd.signal.estimate_frf`'s
    defaults (a note on stderr says so; `satmd estimate-frf` gives control).
    """
    from ..io import is_recording, load_frf
    from ..signal import estimate_frf

    command = getattr(args, "command", None) or "satmd"
    if getattr(args, "plot", None):  # every output is checked before the first piece of work
        check_outputs([("--plot", args.plot, plot_suffixes())], inputs=[args.data])
    flag = getattr(args, "band_flag", None) or "--band"  # the option as the command calls it (tune: --data-band)
    lo, hi = parse_band(getattr(args, "band", None), flag)
    with one_line_warnings(command):
        if is_recording(args.data):
            rec = load_recording_args(args, args.data)
            data = estimate_frf(rec, band_hz=(lo, hi))

            check_usable(args.data, data)
            estimate_notes(args, data.estimator, data.estimator.get("measurement", []))
            return data
        options = {}
        if getattr(args, "map", None):
            options["channel_map"] = args.map
        if getattr(args, "freq_axis", None):
            options["freq_axis"] = args.freq_axis
        data = load_frf(args.data, **options)
    check_usable(args.data, data)
    for ch, s in data.std.items():  # every data command weights by the std: a zero is unusable
        if np.any(s == 0):
            k = int(np.argmax(s == 0))
            raise FormatError(args.data, f"{ch}_std is 0 in data row {k + 1} ({data.freq_hz[k]:.6g} Hz): a point "
                                         f"without noise cannot be weighted; drop the std columns or fix the row")
    if lo is None and hi is None:
        return data
    try:
        banded = data.band(lo, hi)
    except SatmdError as exc:
        raise SatmdError(f"{flag} {args.band}: {exc} in {safe_text(args.data)}") from None
    if len(banded) < MIN_POINTS:
        raise SatmdError(f"{flag} {args.band}: leaves {len(banded)} frequency point(s) of {safe_text(args.data)}; "
                         f"the fitting commands need at least {MIN_POINTS}")
    return banded


MIN_POINTS = 2  # one frequency point cannot pin a resonance, whatever the channels


def check_usable(path, data):
    """Refuse FRFs no command can fit, naming the file: too few points, a channel that is zero everywhere."""
    if len(data) < MIN_POINTS:
        raise FormatError(path, f"{len(data)} frequency point(s): the fitting commands need at least {MIN_POINTS}")
    from ..io.frfdata import MAX_ABS_VALUE

    for ch, v in data.channels.items():
        mag = np.abs(v)
        if not np.any(mag):
            raise FormatError(path, f"channel {ch} is zero at every frequency: nothing was measured")
        k = int(np.argmax(mag))
        if mag[k] > MAX_ABS_VALUE or mag[k] < 1e-100:
            raise FormatError(path, f"channel {ch} peaks at |{ch}| = {mag[k]:.3g} ({data.freq_hz[k]:.6g} Hz): not an "
                                    f"FRF in SI units (the fitting commands take 1e-100..1e100; a wrong unit?)")
    for ch, s in data.std.items():
        if np.max(s) > MAX_ABS_VALUE:
            raise FormatError(path, f"{ch}_std reaches {np.max(s):.3g}: not a noise level in SI units")

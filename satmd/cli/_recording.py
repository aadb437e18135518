"""The options a time recording's file cannot answer: its excitation, its period, its sample rate."""
from __future__ import annotations

import argparse


def add_recording_options(parser: argparse.ArgumentParser):
    """--excitation, --period-s and --fs: what a time recording's file cannot say."""
    parser.add_argument("--excitation", default="auto", choices=("auto", "random", "periodic", "impact", "sweep"),
                        help="recordings: what excited the rig (default: detected from the force)")
    parser.add_argument("--period-s", type=_positive, default=None, metavar="S",
                        help="recordings: the period of a periodic force in seconds (default: detected)")
    parser.add_argument("--fs", type=_positive, default=None, metavar="HZ",
                        help="recordings in .mat/.npz without a sample-rate variable: the sample rate in Hz")


def load_recording_args(args, path):
    """A time recording with --map and --fs applied and its excitation read (--excitation, --period-s)."""
    from ..io import load_recording
    from ..signal.excitation import received

    from ..errors import SatmdError

    try:
        rec = load_recording(path, channel_map=getattr(args, "map", None), fs_hz=getattr(args, "fs", None))
        return received(rec, getattr(args, "excitation", "auto") or "auto", getattr(args, "period_s", None))
    except SatmdError as err:
        text = as_typed(str(err))
        raise SatmdError(text if str(path) in text else f"{path}: {text}") from None


#: the library's names for what the command line calls its options
TYPED = {"(period_s)": "(--period-s)", "(fs_hz)": "(--fs)", "a channel map ": "--map ",
         "period_s / ": "--period-s / ", "period_s = ": "--period-s ", "a sample rate applies to": "--fs applies to"}


def as_typed(message: str) -> str:
    """A library message with the options named as the user types them."""
    import re

    for name, flag in TYPED.items():
        message = message.replace(name, flag)
    message = re.sub(r"(^|: )map\b", r"\1--map", message)
    return re.sub(r"(^|: )excitation '(\w+)' given", r"\1--excitation \2 given", message)


def _positive(text):
    """A finite number > 0 (argparse type)."""
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number > 0")
    return value

"""satmd simulate: write model FRFs (optionally noisy) as a SPEC §7 file, or a time recording (--time)."""
from __future__ import annotations

from ..errors import SatmdError
from ..io import CHANNELS, WRITERS, save_frf
from ..io.atomic import all_or_none
from ..io.recording import RECORDING_WRITERS
from ..physics import PAPER_GRID_HZ
from ..simulation.frf import simulate
from ._common import (
    MAX_SAMPLES,
    SEED,
    add_rig_options,
    check_element_range,
    check_outputs,
    OptionGroup,
    option_defaults,
    plot_suffixes,
    real,
    refuse_unused,
    parse_band,
    parse_effect,
    parse_freq,
    parse_kv,
    parse_names,
    parse_number,
    rig_from_args,
)


def register(sub):
    p = sub.add_parser("simulate", help="write model FRFs to a file (with effects and noise)",
                       description="Simulate the SATMD's FRFs and write them as a satmd-frf v1 CSV.")
    add_rig_options(p)
    p.add_argument("--effect", action="append", default=[], metavar="NAME:key=value,...",
                   help="missing-physics effect, e.g. extra_mode:f_hz=66,zeta=0.01,mass_ratio=0.01 or "
                        "parameter_offset:k1:value=2e5 (repeatable)")
    p.add_argument("--noise", default=None, metavar="REL[:FLOOR]",
                   help="Gaussian noise with std = REL|A| + FLOOR max|A| on Re and Im; adds std columns")
    p.add_argument("--seed", type=SEED, default=None, help="random seed for the noise")
    freq = p.add_argument("--freq", default=None, metavar="LO:HI:N", help="frequency grid (default 40:130:60)")
    channels = p.add_argument("--channels", default=None, help="channels to write, from a1,a2,u1,u2,q (default a1,a2)")
    p.add_argument("-o", "--out", required=True, metavar="OUT.csv",
                   help="output file (FRFs: .csv .uff .mat .npz; with --time: .csv .uff .wav .mat .npz)")
    t = OptionGroup(p.add_argument_group("time recordings (--time)"))
    t.add_argument("--time", action="store_true",
                   help="write a time recording (force, acc1, acc2) instead of FRFs: band-limited random force "
                        "through the linear model; --noise REL is then sensor noise relative to each channel's RMS")
    t.add_argument("--duration", type=real(0, lo_open=True), default=None, metavar="S",
                   help="recording length in s (default 60)")
    t.add_argument("--fs", type=real(0, lo_open=True), default=None, metavar="HZ",
                   help="sample rate in Hz (default 1000)")
    t.add_argument("--force-band", default=None, metavar="LO:HI",
                   help="excitation band in Hz (default 20:200)")
    t.add_argument("--force-rms", type=real(0, 1e12, lo_open=True), default=None, metavar="N",
                   help="RMS force in N (default 1)")
    t.add_argument("--excitation", default=None, choices=("random", "sweep", "multisine"),
                   help="random: band-limited non-periodic noise, rig at rest at t = 0 (default, as on a rig); "
                        "sweep: one log sine sweep; multisine: odd random-phase multisine with detection lines, "
                        "--realisations x --periods, each realisation from rest (first period: transient)")
    t.add_argument("--nonlinear", action="append", default=None, metavar="NAME:key=value,...",
                   help="SPEC 8b nonlinear element, e.g. cubic_absorber_spring:k3=2e9 (repeatable); "
                        "simulated by the time-domain integrator")
    t.add_argument("--level", type=real(0, 1e12, lo_open=True), default=None, metavar="N",
                   help="drive level: RMS force in N (same as --force-rms)")
    t.add_argument("--periods", type=int, default=None, metavar="P", help="multisine periods per realisation (default 3)")
    t.add_argument("--realisations", type=int, default=None, metavar="M",
                   help="multisine realisations, each with new phases (default 4)")
    t.add_argument("--force-noise", type=real(0, MAX_NOISE), default=None, metavar="REL",
                   help="force-sensor noise relative to the force RMS (default: half of --noise)")
    t.add_argument("--burn-in", type=real(0), default=None, metavar="S",
                   help="seconds of excitation before the record starts (default 0: starts at rest)")
    t.add_argument("--ideal", action="store_true",
                   help="an idealised recording: no noise unless --noise, the force cut sharply at the band edges "
                        "(default: lab conditions, 2 %% noise on each accelerometer and 1 %% on the force, the "
                        "shaker's force rolled off above the band and high-passed below it)")
    p.add_argument("--plot", default=None, metavar="OUT.png", help="also plot the FRFs")
    # options of one mode given in the other are refused, not ignored
    p.set_defaults(func=run, time_only=option_defaults(t.actions), frf_only=option_defaults([freq, channels]))


MAX_NOISE = 1e3  # noise a thousand times the signal: beyond, the file holds nothing but noise
TIME_DEFAULTS = {"duration": 60.0, "fs": 1000.0, "force_band": "20:200", "force_rms": 1.0, "excitation": "random",
                 "burn_in": 0.0}


def parse_noise(text):
    if text is None:
        return None
    rel, _, floor = text.partition(":")
    noise = (parse_number(rel, "--noise REL"), parse_number(floor, "--noise FLOOR") if floor else 0.0)
    if noise[0] < 0 or noise[1] < 0:
        raise SatmdError(f"--noise {text!r}: REL and FLOOR must be >= 0")
    if noise[0] > MAX_NOISE or noise[1] > MAX_NOISE:
        raise SatmdError(f"--noise {text!r}: REL and FLOOR must be <= {MAX_NOISE:g} (noise {MAX_NOISE:g} times the "
                         "signal leaves nothing to fit)")
    return noise


def run(args):
    if args.time:
        refuse_unused(args, args.frf_only, "only without --time (a recording's grid follows from --fs, --duration)")
    else:
        refuse_unused(args, args.time_only, "only with --time")
    rig = rig_from_args(args)
    effects = [parse_effect(e) for e in args.effect]
    if args.time:
        return run_time(args, rig, effects)
    freq = parse_freq(args.freq) if args.freq is not None else PAPER_GRID_HZ
    channels = parse_names(args.channels if args.channels is not None else "a1,a2", CHANNELS, "--channels")
    twice = sorted({c for c in channels if channels.count(c) > 1})
    if twice:
        raise SatmdError(f"--channels {args.channels!r}: {', '.join(twice)} given twice")
    check_outputs([("-o", args.out, tuple(sorted(WRITERS))), ("--plot", args.plot, args.plot and plot_suffixes())])
    data = simulate(freq, rig, effects, channels, noise=parse_noise(args.noise), seed=args.seed)
    with all_or_none():
        save_frf(data, args.out)
        if args.plot:
            from ..plots import plot_frfdata

            plot_frfdata(data, args.plot, title=f"simulated: {', '.join(e.name for e in effects) or 'nominal model'}")
    print(f"wrote {args.out} ({len(data)} points, channels {', '.join(channels)})")


def run_time(args, rig, effects):
    """--time: a simulated recording (satmd.simulation.simulate_recording)."""
    from ..io import save_recording
    from ..simulation import simulate_recording

    if args.plot:
        raise SatmdError("--plot does not apply with --time (plot the estimate: satmd estimate-frf REC --plot FIG.png)")
    for key, value in TIME_DEFAULTS.items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    noise = parse_noise(args.noise)
    if noise and noise[1]:
        raise SatmdError("--noise with --time takes REL only (sensor noise relative to each channel's RMS)")
    lo, hi = parse_band(args.force_band, "--force-band")
    if lo is None or hi is None:
        raise SatmdError(f"--force-band {args.force_band!r}: expected LO:HI in Hz")
    if not 0 < lo < hi < args.fs / 2:  # the simulator's condition, in the options' names
        raise SatmdError(f"--force-band {args.force_band} must lie inside (0, --fs/2 = {args.fs / 2:g}) Hz: "
                         "raise --fs or narrow --force-band")
    n = args.duration * args.fs
    if n > MAX_SAMPLES:
        raise SatmdError(f"--duration {args.duration:g} s at --fs {args.fs:g} Hz is {n:.3g} samples per channel; "
                         f"at most {MAX_SAMPLES} (e.g. --duration {MAX_SAMPLES // args.fs:g})")
    from ..io.limits import check_memory, memory_budget
    from ..simulation.timesim import recording_memory

    check_memory(f"--fs {args.fs:g} Hz for --duration {args.duration:g} s",
                 recording_memory(args.duration, args.fs), "lower --fs or --duration")
    if args.burn_in:  # simulated ahead of the record, as many samples a second: its own limit, under its own name
        # samples left beside the record's: the simulator's limit, and memory at 400 bytes a sample (recording_memory)
        room = min(MAX_SAMPLES - n, (memory_budget() - recording_memory(args.duration, args.fs)) / 400.0)
        if args.burn_in * args.fs > room:
            raise SatmdError(f"--burn-in {args.burn_in:g} s: {args.burn_in * args.fs:.3g} samples ahead of the "
                             f"record at --fs {args.fs:g} Hz; at most {max(room, 0) / args.fs:.3g} s beside "
                             f"--duration {args.duration:g} s (a few seconds let the rig's response settle)")
    check_outputs([("-o", args.out, tuple(sorted(RECORDING_WRITERS)))])
    if args.nonlinear or args.excitation == "multisine" or args.level is not None:
        return run_nonlinear(args, rig, effects, noise, (lo, hi))
    rec = simulate_recording(args.duration, args.fs, rig, effects, band_hz=(lo, hi), force_rms=args.force_rms,
                             noise=noise[0] if noise else None, seed=args.seed, excitation=args.excitation,
                             force_noise=args.force_noise, burn_in_s=args.burn_in, ideal=args.ideal)
    save_recording(rec, args.out)
    print(f"wrote {args.out} ({rec.n_samples} samples at {rec.fs_hz:g} Hz = {rec.duration_s:g} s, "
          f"channels {', '.join(rec.channels)})")


def run_nonlinear(args, rig, effects, noise, band):
    """--time with --nonlinear, --level or --excitation multisine: the time-domain integrator."""
    from ..io import save_recording
    from ..physics import nonlinear_element
    from ..simulation.nonlinear import simulate_nonlinear_recording

    if args.level is not None and args.force_rms not in (None, 1.0):
        raise SatmdError("give the drive level once: --level or --force-rms")
    if args.burn_in:
        raise SatmdError("--burn-in does not apply with --nonlinear or a multisine (each record starts at rest)")
    level = args.level if args.level is not None else args.force_rms
    elements = []
    for text in args.nonlinear or ():
        name, _, kv = text.partition(":")
        try:
            elements.append(nonlinear_element(name, **(parse_kv(kv, f"--nonlinear {name}") if kv else {})))
        except (TypeError, ValueError) as exc:
            raise SatmdError(f"--nonlinear {text!r}: {exc}") from None
        check_element_range(f"--nonlinear {text}", elements[-1])
    for flag, value in (("--periods", args.periods), ("--realisations", args.realisations)):
        if value is not None and value < 1:
            raise SatmdError(f"{flag} {value}: must be >= 1")
    if args.excitation == "multisine":  # a period of at least 16 samples (satmd.simulation.nonlinear)
        periods, realisations = args.periods or 3, args.realisations or 4
        if args.duration * args.fs / (periods * realisations) < 16:
            raise SatmdError(f"--realisations {realisations} x --periods {periods} do not fit in --duration "
                             f"{args.duration:g} s at --fs {args.fs:g} Hz (each period needs 16 samples or more); "
                             f"at most {int(args.duration * args.fs // 16)} periods in all")
    try:
        rec = simulate_nonlinear_recording(rig, elements, level, args.duration, args.fs, band,
                                           noise=noise[0] if noise else 0.0, force_noise=args.force_noise,
                                           seed=args.seed, excitation=args.excitation, periods=args.periods or 3,
                                           realisations=args.realisations or 4, effects=effects)
    except SatmdError as exc:  # the integrator overflowed: name what the user can change
        if not elements or "NaN or infinite" not in str(exc):
            raise
        raise SatmdError(f"--nonlinear {' --nonlinear '.join(args.nonlinear)} at --level {level:g} N: the simulated "
                         "response is not finite (the element is too strong at this drive level); lower --level "
                         "or weaken the element") from None
    save_recording(rec, args.out)
    print(f"wrote {args.out} ({rec.n_samples} samples at {rec.fs_hz:g} Hz = {rec.duration_s:g} s, level "
          f"{level:g} N RMS, {', '.join(e.name for e in elements) or 'linear'}, {args.excitation} force)")

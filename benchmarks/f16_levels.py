"""Benchmark: what `satmd.discover` says of the F-16 ground vibration test at four levels (issue 35).

The F-16 nonlinear benchmark (J.P. Noël and M. Schoukens, "F-16 aircraft benchmark based on ground
vibration test data", 2017 Workshop on Nonlinear System Identification Benchmarks, Brussels;
nonlinearbenchmark.org): full random-phase multisines 2–15 Hz at levels 1, 3, 5 and 7, force at the
shaker, acceleration on the wing and on the payload next to the nonlinear interface
(``force=Force,a1=Acceleration[2],a2=Acceleration[3]``). The four recordings go through
`satmd.discover` as they are (the multisine is detected from the force); the report's
``nonlinear_unexplained`` finding gives, per resonance that moves, its frequency and damping ratio
per level with 95 % intervals and the trends (SPEC §9).

Writes benchmarks/results/f16_levels.json (``--out``) and prints one line. Needs ../shared/data/real/f16
(``--data``); without it, writes nothing and exits 0. `readme_markdown` renders the README region
``f16_levels``.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
from satmd.io.shared import shared_dir  # noqa: E402
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from _machine import describe, load_after, machine  # noqa: E402

DATA = (shared_dir() or ROOT.parent / "shared") / "data" / "real" / "f16"
OUT = ROOT / "benchmarks" / "results" / "f16_levels.json"
LEVELS = (1, 3, 5, 7)
CHANNELS = "force=Force,a1=Acceleration[2],a2=Acceleration[3]"
CITATION = ("J.P. Noël and M. Schoukens, F-16 aircraft benchmark based on ground vibration test data, "
            "2017 Workshop on Nonlinear System Identification Benchmarks, Brussels")


def run(data: Path) -> dict:
    """The discovery of the four levels, JSON-ready."""
    import satmd
    from satmd.io import load_recording
    from satmd.signal import detect_excitation

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the files' Voltage is not used
        recs = [load_recording(data / f"F16Data_FullMSine_Level{i}.mat", channel_map=CHANNELS) for i in LEVELS]
    t0 = time.perf_counter()
    rep = satmd.discover(recs)
    seconds = time.perf_counter() - t0
    nl = rep.nonlinear
    exc = detect_excitation(recs[0])
    return {
        "data": "F-16 ground vibration test, full multisine levels " + ", ".join(map(str, LEVELS)),
        "citation": CITATION,
        "channels": CHANNELS,
        "excitation": {"kind": exc.kind, "period_s": exc.period_s, "periods": exc.periods,
                       "excited_lines": len(exc.lines)},
        "force_rms": [float(x) for x in nl.levels],
        "model_adequate": bool(rep.model_adequate),
        "nonlinear_detected": bool(nl.detected),
        "findings": [f["name"] for f in nl.findings],
        "effects": list(rep.effect_names),
        "tests": [{"name": t.name, "p_value": float(t.p_value)} for t in nl.tests],
        "modes": next((f["modes"] for f in nl.findings if f.get("modes") is not None), []),
        "explanation": nl.findings[0]["explanation"] if nl.findings else "",
        "discover_seconds": seconds,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=DATA)
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    if not all((args.data / f"F16Data_FullMSine_Level{i}.mat").is_file() for i in LEVELS):
        print(f"f16_levels: the F-16 files are not in {args.data}: nothing measured")
        return 0
    info = machine(device="cpu", threads=1)
    result = run(args.data)
    info.update(load_after())
    result["machine"] = info
    args.out.write_text(json.dumps(result, indent=1))
    moving = ", ".join(f"{m['f_hz'][0]:.2f} Hz {m['trend']}/{m['damping_trend']}" for m in result["modes"])
    print(f"f16_levels: adequate {result['model_adequate']}, findings {result['findings']}, moving: {moving}; "
          f"discover {result['discover_seconds']:.1f} s {describe(info)} -> {args.out}")
    return 0


def readme_markdown(result: dict) -> str:
    """README region ``f16_levels``: per resonance that moves, f and ζ per level (± the 95 % half-width)."""
    levels = result["force_rms"]
    head = "| resonance | " + " | ".join(f"{x:.1f} N RMS: f [Hz], ζ [%]" for x in levels) + " | trend | damping |"
    rows = [head, "|" + "---|" * (len(levels) + 3)]
    for m in result["modes"]:
        cells = []
        for f, fc, z, zc in zip(m["f_hz"], m["f_ci95"], m["zeta"], m["zeta_ci95"]):
            cells.append(f"{f:.3f} ± {(fc[1] - fc[0]) / 2:.3f}, {100 * z:.2f} ± {50 * (zc[1] - zc[0]):.2f}")
        lo, hi = levels.index(min(levels)), levels.index(max(levels))
        df = 100 * (m["f_hz"][hi] / m["f_hz"][lo] - 1)
        dz = m["zeta"][hi] / m["zeta"][lo]
        rows.append(f"| {m['f_hz'][lo]:.2f} Hz | " + " | ".join(cells)
                    + f" | {m['trend']} ({df:+.1f} %) | {m['damping_trend']} (×{dz:.2f}) |")
    rows.append("")
    rows.append(f"(`python benchmarks/f16_levels.py`: `discover` on the four recordings, "
                f"{result['discover_seconds']:.1f} s; model adequate: {str(result['model_adequate']).lower()}; "
                f"findings: {', '.join(result['findings']) or 'none'}; linear effects: "
                f"{', '.join(result['effects']) or 'none'}.)")
    return "\n".join(rows)


if __name__ == "__main__":
    sys.exit(main())

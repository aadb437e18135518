"""Why sine sweeps place and name a joint less often than multisines (issue 47): the measurements behind the account
`satmd.structure.transient_spectra` gives.

On tests of the independent simulator (`benchmarks/_indep_gvt.py`) swept as in `structures_gvt_sweeps.py`
(40 → 5 Hz in 40 s, 40 s of quiet after it), levels 1, 3, 5, 7:

1. **noise**: each test located from its sweeps (`locate_joint` on `transient_spectra`) with the simulator's noise
   and without any. The same verdicts say that the noise of one record a level is not what holds sweeps back.
2. **as `locate_joint` weighs it** (cubic tests, noise-free): each level's change from the lowest level's FRF,
   ``E = A − H F``, against the true law's term at the true place through `locate_joint`'s fitted transfer (the
   lowest level's modes, every mode's input real, each channel's residual terms) and its stroke (every line up to
   0.8 of Nyquist): the share of E left unexplained (`satmd.structure.locate.unexplained`).
3. **through the exact transfer** (the same tests): the simulator's own modes from the joint to every sensor, its
   anti-alias low-pass included, one real coefficient: the share left unexplained with H the lowest level's FRF
   (as 2), with the lowest level's own joint response subtracted (a sweep's levels are one sweep scaled, so
   ``E_l = T (G_l − r_l G_1)`` exactly, r_l the level ratio), and each with the low-pass taken off the stroke the
   law is evaluated on (its phase on the harmonics is the sensors', not the stroke's).

    python benchmarks/structures_sweeps_why.py [--seeds 3,5] [--out PATH]

Writes benchmarks/results/structures_sweeps_why.json and prints one line of figures.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from scipy import signal

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
import _indep_gvt as sim  # noqa: E402
from _machine import machine  # noqa: E402
from structures_gvt import plan  # noqa: E402

from satmd.io import Recording  # noqa: E402
from satmd.structure import locate_joint, transient_spectra  # noqa: E402
from satmd.structure.locate import unexplained  # noqa: E402
from satmd.structure.spectra import motion  # noqa: E402

OUT = ROOT / "benchmarks" / "results" / "structures_sweeps_why.json"
FITTED = (1, 3, 5, 7)


def swept(test, noise_scale: float) -> list:
    """The test's swept levels 1, 3, 5, 7 as Recordings, its noise scaled (0: none)."""
    test.noise = {**test.noise, "acc": test.noise["acc"] * noise_scale, "force": test.noise["force"] * noise_scale}
    recs = sim.simulate(test, excitation="sweep")
    return [Recording(sim.FS, {k: v for k, v in recs[lv - 1].items() if k != "time_s"}, meta={"source": f"L{lv}"})
            for lv in FITTED]


def low_pass(f_hz) -> np.ndarray:
    """The simulator's anti-alias filter at ``f_hz`` (as `_indep_gvt.simulate` builds it)."""
    sos = signal.ellip(8, 0.05, 90.0, 0.8 * sim.FS / 2, fs=sim.FS * sim.OVER, output="sos")
    return signal.sosfreqz(sos, worN=np.asarray(f_hz, float), fs=sim.FS * sim.OVER)[1]


def stroke(s, a: str, b: str, deconvolved: bool) -> np.ndarray:
    """a's displacement relative to b's over the padded record, from every line of the band's lowest up to 0.8 of
    Nyquist (`PeriodicSpectra.motion`), the low-pass divided out where ``deconvolved``."""
    def one(channel):
        if channel == "ground":
            return np.zeros(s.period_samples)
        lines = np.arange(int(s.lines.min()), int(0.8 * (s.period_samples // 2)) + 1)
        x = s.whole[channel][lines]
        if deconvolved:
            x = x / low_pass(lines * s.fs_hz / s.period_samples)
        return motion(x, lines, s.fs_hz, s.period_samples)[0]
    return one(a) - one(b)


def exact_transfer(spectra, test) -> dict:
    """Share of the levels' change left unexplained by the true cubic through the simulator's exact transfer, one
    real coefficient: with H the lowest level's FRF, the lowest level's own joint response subtracted or not, the
    low-pass on the stroke or taken off."""
    ref = spectra[0]
    w = 2 * np.pi * ref.freq_hz
    om = 2 * np.pi * test.freq_hz
    den = om[None, :] ** 2 - w[:, None] ** 2 + 2j * test.zeta * om[None, :] * w[:, None]
    modal = test.phi_s[None, :, :] * (-test.psi)[None, None, :] / den[:, None, :]
    T = -w[:, None] ** 2 * modal.sum(-1) * low_pass(ref.freq_hz)[:, None]  # (K, channels): acceleration per newton
    names = list(ref.responses)
    F = np.array([s.force for s in spectra])
    out = {}
    for deconvolved in (False, True):
        G = np.array([s.at_lines(stroke(s, *test.between, deconvolved) ** 3) for s in spectra])
        for subtracted in (False, True):
            ys, xs = [], []
            for i, c in enumerate(names):
                A = np.array([s.responses[c] for s in spectra])
                wt = 1.0 / np.mean(np.abs(A), axis=1, keepdims=True)
                ratio = F / F[0]
                ys.append(((A - ratio * A[0]) * wt)[1:].ravel())
                g = G - ratio * G[0] if subtracted else G
                xs.append((T[:, i] * g * wt)[1:].ravel())
            y, x = np.concatenate(ys), np.concatenate(xs)
            r = y - (np.vdot(x, y).real / np.vdot(x, x).real) * x
            key = ("own_response_subtracted" if subtracted else "as_located") + ("_low_pass_off" if deconvolved else "")
            out[key] = round(float(np.vdot(r, r).real / np.vdot(y, y).real), 4)
    return out


def case(structure: str, law: str, seed: int) -> dict:
    row = {"structure": structure, "law": law, "seed": seed}
    for scale in (1.0, 0.0):
        test = sim.make_test(seed, structure, law)
        row["between"] = list(test.between)
        spectra = [transient_spectra(r) for r in swept(test, scale)]
        t0 = time.perf_counter()
        loc = locate_joint(spectra)
        key = "noisy" if scale else "noise_free"
        row[key] = {"found_between": list(loc.between), "placed": sorted(loc.between) == sorted(test.between),
                    "law": loc.law, "laws": loc.laws[:3], "locate_s": round(time.perf_counter() - t0, 1)}
        if scale == 0.0 and law == "cubic":
            row["unexplained_as_located"] = {name: round(unexplained(spectra, tuple(test.between), name), 4)
                                             for name in ("cubic", "sparse")}
            row["unexplained_exact_transfer"] = exact_transfer(spectra, test)
    return row


def line(result: dict) -> str:
    parts = []
    for r in result["rows"]:
        n, q = r["noisy"], r["noise_free"]
        text = (f"{r['structure']} {r['law']} {r['seed']}: noisy {'placed' if n['placed'] else 'misplaced'} "
                f"({n['law']}), noise-free {'placed' if q['placed'] else 'misplaced'} ({q['law']})")
        if "unexplained_as_located" in r:
            e, x = r["unexplained_as_located"], r["unexplained_exact_transfer"]
            text += (f"; true law unexplained {e['cubic']:.3f} as located, exact transfer {x['as_located']:.3f} "
                     f"(own response subtracted {x['own_response_subtracted']:.3f}; low-pass off "
                     f"{x['as_located_low_pass_off']:.3f}, both {x['own_response_subtracted_low_pass_off']:.3f})")
        parts.append(text)
    return "structures_sweeps_why: " + " | ".join(parts)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=lambda t: [int(x) for x in t.split(",")], default=[3, 5])
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = [case(structure, law, seed) for structure, law, seed in plan(0, 0, args.seeds) if law is not None]
    result = {"machine": machine(), "rows": rows, "benchmark_seconds": round(time.perf_counter() - t0, 1)}
    args.out.write_text(json.dumps(result, indent=1))
    print(line(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())

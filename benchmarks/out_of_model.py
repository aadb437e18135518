"""Out-of-model benchmark (issue 24): files the SATMD model cannot describe, run through `satmd discover --json`.

Every family is made here with numpy alone, without satmd's forward model: the
SATMD rig itself (for the wrong-unit and wrong-convention families) is solved
from SPEC §2 by a plain 3×3 linear solve written below, so a bug in
`satmd.physics` cannot hide here. Each case is written as a `satmd-frf v1` CSV
(by this script, not by satmd's writer), alternately with and without std
columns, and run through the command line as a user would:
`python -m satmd.cli discover FILE --json`. Families:

- ``one_dof``: a 1-DOF oscillator (f0 120–600 Hz) measured as accelerance (a1 only);
- ``two_dof``: a mechanical host + absorber (no piezo) with values far from the rig's;
- ``three_dof``: a grounded 3-mass chain (modes 20–600 Hz), driving point and the second mass;
- ``beam``: a multi-mode beam (3–6 modes, 20–1000 Hz), one or two response points;
- ``plate``: a simply supported plate, modal sum over (m, n) modes up to 1.5 kHz, two points;
- ``white_noise`` (std given) and ``white_noise_nostd``: complex Gaussian noise, no structure;
- ``units_g``, ``units_mm``, ``displacement``, ``velocity``: the SATMD rig in wrong units;
- ``conjugate``: the SATMD rig written with the e^{-iωt} convention;
- ``db_phase``: magnitude in dB and phase in degrees in the _re/_im columns;
- ``missing_channel``: a2 present but the sensor gave nothing (noise only, or zeros with noise) or a copy of a1;
- ``real_beam``: the third-party beam accelerances ../shared/data/real/meas_point_{1,2,3}.txt, read with
  ``--freq-axis 0:1`` (skipped when absent).

A family passes when `model_adequate` is false and no physics effect is listed
(`effects` empty). Writes benchmarks/results/out_of_model.json (a partial run,
``--families`` or ``--scale`` < 1, goes to /tmp unless ``--out`` is given) and
prints one line per family.

Usage: python benchmarks/out_of_model.py [--families one_dof,beam,...] [--seed 0] [--keep DIR] [--out PATH]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _machine import provenance  # noqa: E402

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
from satmd.io.shared import shared_dir  # noqa: E402
SHARED = shared_dir() or ROOT.parent / "shared"
REAL = SHARED / "data" / "real"
RESULT = ROOT / "benchmarks" / "results" / "out_of_model.json"

RIG = dict(m1=0.85, k1=194e3, c1=10.0, cp=4.0, e=0.65, Cp=27e-6)
RANGES = {"m2": (0.3, 0.8), "kp": (5e4, 2e5), "R": (5.0, 100.0), "L": (0.02, 0.5)}
GRIDS = ((40.0, 130.0, 60), (30.0, 160.0, 200))


def satmd_rig_a(f, m2, kp, R, L):
    """A1, A2 of SPEC §2 by a direct 3×3 solve per frequency (independent of satmd.physics)."""
    r = RIG
    w = 2 * np.pi * f
    a1, a2 = np.empty(f.size, complex), np.empty(f.size, complex)
    for i, om in enumerate(w):
        Z = np.array([[r["k1"] + kp - r["m1"] * om**2 + 1j * om * (r["c1"] + r["cp"]), -kp - 1j * om * r["cp"],
                       r["e"] / r["Cp"]],
                      [-kp - 1j * om * r["cp"], kp - m2 * om**2 + 1j * om * r["cp"], -r["e"] / r["Cp"]],
                      [r["e"] / r["Cp"], -r["e"] / r["Cp"], 1 / r["Cp"] - L * om**2 + 1j * om * R]])
        u = np.linalg.solve(Z, np.array([1.0, 0.0, 0.0]))
        a1[i], a2[i] = -om**2 * u[0], -om**2 * u[1]
    return a1, a2


def _noisy(rng, x, rel=0.01, floor_frac=0.002):
    std = rel * np.abs(x) + floor_frac * np.abs(x).max()
    return x + std * (rng.standard_normal(x.size) + 1j * rng.standard_normal(x.size)), std


def _grid(rng):
    lo, hi, n = GRIDS[rng.integers(len(GRIDS))]
    return np.linspace(lo, hi, n)


def _pack(f, chans, std_given, rng, rel=0.01):
    out, stds = {}, {}
    for c, x in chans.items():
        out[c], stds[c] = _noisy(rng, x, rel)
    return {"freq_hz": f, "channels": out, "std": stds if std_given else {}}


def _mdof_accelerance(f, M, K, C, drive, points):
    """Accelerances at `points` for a unit force at `drive` of M u'' + C u' + K u = F (direct solve)."""
    w = 2 * np.pi * f
    F = np.zeros(M.shape[0])
    F[drive] = 1.0
    out = np.empty((len(points), f.size), complex)
    for i, om in enumerate(w):
        u = np.linalg.solve(K - om**2 * M + 1j * om * C, F)
        out[:, i] = -om**2 * u[list(points)]
    return out


def one_dof(rng, std_given):
    f0, zeta, m = rng.uniform(120, 600), rng.uniform(0.005, 0.05), rng.uniform(0.2, 5.0)
    f = np.linspace(rng.uniform(0.3, 0.6) * f0, rng.uniform(1.5, 2.5) * f0, int(rng.choice([100, 200, 400])))
    w, w0 = 2 * np.pi * f, 2 * np.pi * f0
    a = -w**2 / (m * (w0**2 - w**2 + 2j * zeta * w0 * w))
    return _pack(f, {"a1": a}, std_given, rng)


def two_dof(rng, std_given):
    """Host + absorber, no piezo, values far from the rig's (heavier, stiffer, other frequencies)."""
    m1 = rng.uniform(5, 50)
    f1 = rng.uniform(150, 400)
    k1 = m1 * (2 * np.pi * f1) ** 2
    m2 = m1 * rng.uniform(0.02, 0.1)
    k2 = m2 * (2 * np.pi * f1 * rng.uniform(0.85, 1.0)) ** 2
    c1, c2 = 2 * 0.01 * np.sqrt(k1 * m1), 2 * rng.uniform(0.02, 0.1) * np.sqrt(k2 * m2)
    f = np.linspace(0.5 * f1, 1.6 * f1, 200)
    M, K = np.diag([m1, m2]), np.array([[k1 + k2, -k2], [-k2, k2]])
    C = np.array([[c1 + c2, -c2], [-c2, c2]])
    a = _mdof_accelerance(f, M, K, C, 0, (0, 1))
    return _pack(f, {"a1": a[0], "a2": a[1]}, std_given, rng)


def three_dof(rng, std_given):
    """A grounded chain ground–k1–m1–k2–m2–k3–m3, Rayleigh damping; force on m1, sensors on m1 and m2."""
    m = rng.uniform(0.5, 20.0, 3)
    k = rng.uniform(0.3, 3.0, 3) * m.mean() * (2 * np.pi * rng.uniform(40, 250)) ** 2
    M = np.diag(m)
    K = np.array([[k[0] + k[1], -k[1], 0], [-k[1], k[1] + k[2], -k[2]], [0, -k[2], k[2]]])
    wn = np.sqrt(np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    zeta = rng.uniform(0.005, 0.03)
    alpha, beta = zeta * wn[0], zeta / wn[-1]  # Rayleigh: about zeta at the outer modes
    C = alpha * M + beta * K
    fn = wn / (2 * np.pi)
    f = np.linspace(max(2.0, 0.5 * fn[0]), 1.4 * fn[-1], int(rng.choice([300, 600])))
    a = _mdof_accelerance(f, M, K, C, 0, (0, 1))
    return _pack(f, {"a1": a[0], "a2": a[1]}, std_given, rng)


def beam(rng, std_given):
    n = int(rng.integers(3, 7))
    fr = np.sort(rng.uniform(30, 900, n))
    zeta = rng.uniform(0.002, 0.03, n)
    phi1, phi2 = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    mass = rng.uniform(0.5, 5.0)
    f = np.linspace(rng.uniform(5, 20), 1000.0, int(rng.choice([500, 1000])))
    w = 2 * np.pi * f

    def acc(pa, pb):
        return sum(-w**2 * pa[r] * pb[r] / (mass * ((2 * np.pi * fr[r])**2 - w**2 + 2j * zeta[r] * 2 * np.pi * fr[r] * w))
                   for r in range(n))
    chans = {"a1": acc(phi1, phi1)}
    if rng.random() < 0.5:
        chans["a2"] = acc(phi1, phi2)
    return _pack(f, chans, std_given, rng)


def plate(rng, std_given):
    """Simply supported rectangular plate: f_mn = f11 (m²/a² + n²/b²)/(1/a² + 1/b²), shapes sin·sin, modal
    mass M/4; drive point and a second response point at random; every mode below 1.5 kHz summed."""
    a, b = 1.0, rng.uniform(0.5, 0.9)
    f11, M, zeta = rng.uniform(15, 60), rng.uniform(1.0, 10.0), rng.uniform(0.003, 0.02)
    (x0, y0), (x1, y1) = rng.uniform(0.1, 0.9, 2) * (a, b), rng.uniform(0.1, 0.9, 2) * (a, b)
    f = np.linspace(rng.uniform(5, 20), rng.choice([500.0, 1000.0]), int(rng.choice([400, 800])))
    w = 2 * np.pi * f
    a1 = np.zeros(f.size, complex)
    a2 = np.zeros(f.size, complex)
    for mm in range(1, 30):
        for nn in range(1, 30):
            fmn = f11 * (mm**2 / a**2 + nn**2 / b**2) / (1 / a**2 + 1 / b**2)
            if fmn > 1500:
                continue
            def shape(x, y, mm=mm, nn=nn):
                return np.sin(mm * np.pi * x / a) * np.sin(nn * np.pi * y / b)
            wr = 2 * np.pi * fmn
            h = -w**2 / ((M / 4) * (wr**2 - w**2 + 2j * zeta * wr * w))
            a1 += shape(x0, y0) ** 2 * h
            a2 += shape(x0, y0) * shape(x1, y1) * h
    return _pack(f, {"a1": a1, "a2": a2}, std_given, rng)


def _rig_case(rng):
    f = _grid(rng)
    p = {k: rng.uniform(*v) for k, v in RANGES.items()}
    return f, satmd_rig_a(f, **p)


def white_noise(rng, std_given):
    f = _grid(rng)
    scale = 10 ** rng.uniform(-2, 1)
    chans = {c: scale * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size)) for c in ("a1", "a2")}
    std = {c: np.full(f.size, scale) for c in chans} if std_given else {}
    return {"freq_hz": f, "channels": chans, "std": std}


def units(rng, std_given, kind):
    f, (a1, a2) = _rig_case(rng)
    w = 2 * np.pi * f
    conv = {"g": lambda a: a / 9.80665, "mm": lambda a: a * 1e3, "displacement": lambda a: a / -(w**2),
            "velocity": lambda a: a / (1j * w), "conjugate": np.conj}[kind]
    return _pack(f, {"a1": conv(a1), "a2": conv(a2)}, std_given, rng)


def db_phase(rng, std_given):
    f, (a1, a2) = _rig_case(rng)
    d = _pack(f, {"a1": a1, "a2": a2}, True, rng)
    stds = d["std"]
    d["channels"] = {c: 20 * np.log10(np.abs(x)) + 1j * np.degrees(np.angle(x)) for c, x in d["channels"].items()}
    # a std column in dB (the relative noise as dB): what a logger that writes dB would give
    d["std"] = {c: 20 / np.log(10) * stds[c] / np.abs(d0) for c, d0 in zip(stds, (a1, a2))} if std_given else {}
    return d


def missing_channel(rng, std_given, variant):
    """a2 written but not measured: the sensor's noise alone, zeros with the logger's noise, or a copy of a1."""
    f, (a1, a2) = _rig_case(rng)
    d = _pack(f, {"a1": a1, "a2": a2}, std_given, rng)
    if variant in ("noise", "zeros"):
        s = (0.002 if variant == "noise" else 1e-6) * np.abs(a1).max()
        d["channels"]["a2"] = s * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size))
        if d["std"]:
            d["std"]["a2"] = np.full(f.size, s)
    else:
        d["channels"]["a2"] = d["channels"]["a1"].copy()
        if d["std"]:
            d["std"]["a2"] = d["std"]["a1"].copy()
    return d


_MISSING = ("noise", "zeros", "copy")

FAMILIES = {
    "one_dof": (one_dof, 6), "two_dof": (two_dof, 5), "three_dof": (three_dof, 6), "beam": (beam, 6),
    "plate": (plate, 6),
    "white_noise": (lambda r, s: white_noise(r, True), 4), "white_noise_nostd": (lambda r, s: white_noise(r, False), 4),
    "units_g": (lambda r, s: units(r, s, "g"), 4), "units_mm": (lambda r, s: units(r, s, "mm"), 4),
    "displacement": (lambda r, s: units(r, s, "displacement"), 4),
    "velocity": (lambda r, s: units(r, s, "velocity"), 4),
    "conjugate": (lambda r, s: units(r, s, "conjugate"), 4), "db_phase": (db_phase, 4),
    "missing_channel": (None, 6),
}


def families(seed: int = 0, scale: float = 1.0, only=None):
    """(family, case name, {"freq_hz", "channels", "std"}) for every generated case; std columns alternate
    (even cases with, odd without; the white-noise families fix it); ``scale`` multiplies the counts."""
    for k, (name, (make, n)) in enumerate(FAMILIES.items()):
        if only and name not in only:
            continue
        for i in range(max(1, round(n * scale))):
            rng = np.random.default_rng([seed, k, i])
            std_given = i % 2 == 0
            if name == "missing_channel":
                yield name, f"{name}_{i:02d}", missing_channel(rng, std_given, _MISSING[i % 3])
            else:
                yield name, f"{name}_{i:02d}", make(rng, std_given)


def write_csv(path: Path, case: dict) -> None:
    """`satmd-frf v1` (SPEC §7), written here with plain numpy (not satmd's writer)."""
    f, chans, std = case["freq_hz"], case["channels"], case["std"]
    names = [c for c in ("a1", "a2", "u1", "u2", "q") if c in chans]
    cols, header = [f], ["freq_hz"]
    for c in names:
        cols += [chans[c].real, chans[c].imag]
        header += [f"{c}_re", f"{c}_im"]
    for c in names:
        if c in std:
            cols.append(np.asarray(std[c], float))
            header.append(f"{c}_std")
    body = np.column_stack(cols)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("# satmd-frf v1\n# out-of-model benchmark case (benchmarks/out_of_model.py)\n")
        fh.write(",".join(header) + "\n")
        np.savetxt(fh, body, delimiter=",", fmt="%.17g")


def run_cli(path: Path, extra=()) -> dict:
    """`satmd discover PATH --json` in a fresh process, one BLAS thread (a shared 2-core machine)."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "satmd.cli", "discover", str(path), *extra, "--json"],
                         capture_output=True, text=True, env=env, cwd=ROOT)
    dt = time.perf_counter() - t0
    row = {"exit": out.returncode, "seconds": dt}
    try:
        d = json.loads(out.stdout)
    except ValueError:
        row.update(model_adequate=None, effects=[], reasons=[], messages=[],
                   error=(out.stderr.strip().splitlines() or ["no output"])[-1][:300])
        return row
    reasons = d.get("adequacy_reasons", [])
    row.update(model_adequate=d.get("model_adequate"), effects=[e["name"] for e in d.get("effects", [])],
               reasons=[r["kind"] for r in reasons], messages=[r["message"] for r in reasons],
               significant_mismatch=d.get("significant_mismatch"), noise=d.get("noise"),
               rel_error_before=d.get("fit_before", {}).get("rel_error"))
    return row


def summarise(rows: list) -> dict:
    per: dict = {}
    for r in rows:
        f = per.setdefault(r["family"], {"n": 0, "inadequate": 0, "with_effects": 0, "std_given": 0, "reasons": {},
                                         "median_seconds": 0.0})
        f["n"] += 1
        f["inadequate"] += r["model_adequate"] is False
        f["with_effects"] += bool(r["effects"])
        f["std_given"] += bool(r["std_given"])
        for k in r["reasons"][:1]:
            f["reasons"][k] = f["reasons"].get(k, 0) + 1
    for fam, f in per.items():
        f["inadequate_rate"] = f["inadequate"] / f["n"]
        f["median_seconds"] = float(np.median([r["seconds"] for r in rows if r["family"] == fam]))
    n = len(rows)
    bad = sum(r["model_adequate"] is False for r in rows)
    withe = sum(bool(r["effects"]) for r in rows)
    return {"n": n, "inadequate": bad, "inadequate_rate": bad / max(n, 1), "with_effects": withe,
            "std_given": sum(bool(r["std_given"]) for r in rows),
            "median_seconds": float(np.median([r["seconds"] for r in rows])) if rows else float("nan"),
            "total_seconds": float(sum(r["seconds"] for r in rows)), "families": per,
            "targets": {"inadequate_ge_95pct": bad / max(n, 1) >= 0.95, "no_physics": withe == 0, "n_ge_50": n >= 50}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n".join(__doc__.splitlines()[2:]))
    ap.add_argument("--families", default="", help="comma-separated subset (default: all, real_beam included)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--scale", type=float, default=1.0, help="multiply the cases per family")
    ap.add_argument("--keep", type=Path, default=None, help="write the generated CSV files here (kept)")
    ap.add_argument("--out", type=Path, default=None, help="result JSON (default: results/out_of_model.json for a "
                                                           "full run, /tmp/out_of_model_partial.json otherwise)")
    args = ap.parse_args(argv)
    only = set(filter(None, args.families.split(",")))
    unknown = only - set(FAMILIES) - {"real_beam"}
    if unknown:
        ap.error(f"unknown families: {', '.join(sorted(unknown))} (known: {', '.join(FAMILIES)}, real_beam)")
    full = not only and args.scale == 1.0 and args.seed == 0
    out = args.out or (RESULT if full else Path(tempfile.gettempdir()) / "out_of_model_partial.json")
    t0 = time.perf_counter()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        for fam, name, case in families(args.seed, args.scale, only):
            path = folder / f"{name}.csv"
            write_csv(path, case)
            row = {"family": fam, "name": name, "std_given": bool(case["std"]), "channels": sorted(case["channels"]),
                   "n_points": int(case["freq_hz"].size), **run_cli(path)}
            rows.append(row)
            print(f"{name:22s} adequate={row['model_adequate']!s:5s} effects={row['effects']} "
                  f"reasons={row['reasons']} {row['seconds']:.1f} s", flush=True)
        if not only or "real_beam" in only:
            for i in (1, 2, 3):
                p = REAL / f"meas_point_{i}.txt"
                if not p.is_file():
                    print(f"real_beam: {p} not found, skipped", flush=True)
                    continue
                row = {"family": "real_beam", "name": p.name, "std_given": False, "channels": ["a1"],
                       "n_points": None, **run_cli(p, ("--freq-axis", "0:1"))}
                rows.append(row)
                print(f"{p.name:22s} adequate={row['model_adequate']!s:5s} effects={row['effects']} "
                      f"reasons={row['reasons']} {row['seconds']:.1f} s", flush=True)
    result = {"benchmark": "out_of_model", "seed": args.seed, "scale": args.scale,
              "machine": {**provenance(), "cpus": os.cpu_count(), "python": platform.python_version(),
                          "load_average_1min": os.getloadavg()[0]},
              "command": "python -m satmd.cli discover FILE --json (one process per file, one BLAS thread)",
              **summarise(rows), "wall_seconds": time.perf_counter() - t0, "cases": rows,
              "note": "families made by benchmarks/out_of_model.py (numpy only, no satmd forward model), written as "
                      "satmd-frf v1 CSV by this script; real_beam: ../shared/data/real/meas_point_*.txt"}
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2, default=float) + "\n", encoding="utf-8")
    for fam, f in result["families"].items():
        print(f"{fam:18s} n={f['n']:2d} inadequate={f['inadequate']:2d} with physics={f['with_effects']}")
    print(f"out of model: {result['inadequate']}/{result['n']} model_adequate false "
          f"({100 * result['inadequate_rate']:.0f} %), {result['with_effects']} with a physics effect, median "
          f"{result['median_seconds']:.1f} s per file; wrote {out}")
    return 0


def readme_markdown(result: dict) -> str:
    """The README region ``out_of_model``: one row per family."""
    rows = ["| family | files (with std) | `model_adequate` false | with a physics effect | reason named first (files) |",
            "|---|---|---|---|---|"]
    for fam, f in result["families"].items():
        why = ", ".join(f"`{k}` {v}" for k, v in sorted(f["reasons"].items(), key=lambda kv: -kv[1])) or "—"
        rows.append(f"| {fam.replace('_', ' ')} | {f['n']} ({f['std_given']}) | {f['inadequate']} | "
                    f"{f['with_effects']} | {why} |")
    rows.append(f"| **all** | {result['n']} ({result['std_given']}) | {result['inadequate']} "
                f"({100 * result['inadequate_rate']:.0f} %) | {result['with_effects']} | median "
                f"{result['median_seconds']:.1f} s per `satmd discover --json` process |")
    return "\n".join(rows)


if __name__ == "__main__":
    sys.exit(main())

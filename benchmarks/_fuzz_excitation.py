"""Hostile inputs on the excitation paths of issue 34 (periodic, impact, sweep, lab .mat layouts).

Each case is a file made here with numpy alone (a linear two-mode system by FFT, noise on every
channel) and a command on it; the judge is `benchmarks/fuzz.py`'s: a one-line refusal naming what is
wrong, or an answer; never a traceback or a hang.
"""
from __future__ import annotations

import io

import numpy as np

FS = 1000.0


def _response(force, rng, noise=0.01):
    """acc1, acc2 of a two-mode linear system (35 and 90 Hz) for ``force``, from rest, by zero-padded FFT."""
    n = force.size
    size = 1 << int(np.ceil(np.log2(n + int(4 * FS))))
    f = np.fft.rfftfreq(size, 1 / FS)
    w = 2j * np.pi * f
    modes = ((35.0, 0.02, 1.0), (90.0, 0.03, -0.6))
    h1 = sum(r * w ** 2 / ((2 * np.pi * fn) ** 2 + 2 * z * 2 * np.pi * fn * w + w ** 2) for fn, z, r in modes)
    h2 = sum(abs(r) * w ** 2 / ((2 * np.pi * fn) ** 2 + 2 * z * 2 * np.pi * fn * w + w ** 2) for fn, z, r in modes)
    F = np.fft.rfft(force, size)
    out = [np.fft.irfft(h * F, size)[:n] for h in (h1, h2)]
    return [x + noise * np.std(x) * rng.standard_normal(n) for x in [force, *out]]


def _csv(channels) -> bytes:
    t = np.arange(channels[0].size) / FS
    rows = np.column_stack([t, *channels])
    buf = io.StringIO()
    buf.write("time_s,force,acc1,acc2\n")
    np.savetxt(buf, rows, delimiter=",", fmt="%.9g")
    return buf.getvalue().encode()


def _mat(**variables) -> bytes:
    from scipy.io import savemat

    buf = io.BytesIO()
    savemat(buf, variables)
    return buf.getvalue()


def _multisine(period, periods, rng, lo=10.0, hi=200.0):
    k = np.arange(period // 2 + 1)
    f = k * FS / period
    spec = np.where((f >= lo) & (f <= hi), np.exp(2j * np.pi * rng.random(k.size)), 0)
    one = np.fft.irfft(spec, period)
    return np.tile(one / np.std(one), periods)


def _hits(times, n, width=5, heights=None):
    x = np.zeros(n)
    pulse = 50 * np.sin(np.pi * np.arange(width) / width)
    for j, t in enumerate(times):
        i = int(t * FS)
        x[i:i + width] += (1 if heights is None else heights[j]) * pulse[: max(0, min(width, n - i))]
    return x


def files(seed: int = 38) -> dict:
    """name -> bytes of every hostile recording."""
    rng = np.random.default_rng(seed)
    out = {}
    ms = _multisine(1000, 8, rng)
    glitch = ms.copy()
    glitch[4300:4330] += 6.0
    out["glitch.csv"] = _csv(_response(glitch, rng))
    out["partial_period.csv"] = _csv(_response(_multisine(1000, 8, rng)[:7450], rng))
    t = np.arange(8000) / FS
    out["drifting_period.csv"] = _csv(_response(np.sin(2 * np.pi * 40 * t * (1 + 0.01 * t)), rng))
    out["two_periods.csv"] = _csv(_response(_multisine(2000, 2, rng), rng))
    n = int(16 * FS)
    out["double_hit.csv"] = _csv(_response(_hits([0.5, 0.52, 4.0, 8.0, 12.0], n), rng))
    f = _response(_hits([0.5, 4.0, 8.0, 12.0], n), rng)
    f[0] = np.minimum(f[0], 0.3 * f[0].max())
    out["clipped_hits.csv"] = _csv(f)  # every hit clipped
    out["hit_at_end.csv"] = _csv(_response(_hits([0.5, 5.0, 10.0, 15.97], n), rng))
    out["one_hit_at_end.csv"] = _csv(_response(_hits([15.99], n), rng))
    from scipy.signal import chirp

    t = np.arange(int(20 * FS)) / FS
    out["sweep_misses_band.csv"] = _csv(_response(chirp(t, 300, t[-1], 450, method="logarithmic"), rng))
    out["sweep_down.csv"] = _csv(_response(chirp(t, 250, t[-1], 8, method="logarithmic"), rng))
    force, a1, a2 = _response(_multisine(1000, 6, rng), rng)
    out["lab.mat"] = _mat(Force=force[None], Acceleration=np.stack([a1, a2, a1]), Fs=np.array([[FS]]))
    out["columns.mat"] = _mat(F=force[:, None], A=np.column_stack([a1, a2]), sample_rate=FS)
    out["nofs.mat"] = _mat(force=force, acc1=a1, acc2=a2)
    out["cube.mat"] = _mat(Force=force[None], Acceleration=np.stack([a1, a2])[None], Fs=FS)  # 1×2×N: axes of one dropped
    out["realizations.mat"] = _mat(Force=np.stack([force, force]), Acceleration=np.stack([np.stack([a1, a2])] * 2), Fs=FS)
    out["textfs.mat"] = _mat(force=force, acc1=a1, acc2=a2, fs="1000")
    out["time.mat"] = _mat(force=force, acc1=a1, acc2=a2, t=np.arange(force.size) / FS)
    return out


def cases(case) -> list[dict]:
    """The fuzz cases (``case`` is `_fuzz_cases.case`)."""
    blobs = files()
    out = []

    def add(expect, names, name, *options, command="discover"):
        argv = [command, "{work}/" + name, *options] + (["-o", "{work}/o.csv"] if command == "estimate-frf" else [])
        out.append(case("excitations", "cli", expect, names, argv=argv, files={name: blobs[name]}))

    for name in ("glitch.csv", "partial_period.csv", "drifting_period.csv", "double_hit.csv", "hit_at_end.csv",
                 "sweep_misses_band.csv", "sweep_down.csv"):
        for command in ("discover", "estimate-frf"):
            add("answer", [], name, command=command)
    for command in ("discover", "estimate-frf"):
        add("either", ["two_periods.csv"], "two_periods.csv", command=command)
        add("either", ["clipped_hits.csv"], "clipped_hits.csv", command=command)
        add("either", ["one_hit_at_end.csv"], "one_hit_at_end.csv", command=command)
        add("refuse", ["--period-s"], "glitch.csv", "--period-s", "0.7", command=command)
        add("refuse", ["--period-s"], "glitch.csv", "--period-s", "1.0004", command=command)
        add("either", ["--excitation"], "glitch.csv", "--excitation", "impact", command=command)
        add("refuse", ["--excitation"], "drifting_period.csv", "--excitation", "periodic", command=command)
        add("either", ["--excitation"], "double_hit.csv", "--excitation", "sweep", command=command)
        add("answer", [], "lab.mat", command=command)  # a force and one matrix of accelerations: read as written
        add("answer", [], "lab.mat", "--map", "force=Force,a1=Acceleration[1],a2=Acceleration[2]", command=command)
        add("refuse", ["--map"], "lab.mat", "--map", "force=Force,a1=Acceleration[4]", command=command)
        add("refuse", ["--map"], "lab.mat", "--map", "force=Missing,a1=Acceleration[1]", command=command)
        add("refuse", ["--map"], "lab.mat", "--map", "force=Force,a1=Acceleration[x]", command=command)
        add("refuse", ["--map"], "lab.mat", "--map", "force=Force,force=Force", command=command)
        add("answer", [], "columns.mat", "--map", "force=F,a1=A[1],a2=A[2]", command=command)
        add("refuse", ["--fs"], "nofs.mat", command=command)
        add("answer", [], "nofs.mat", "--fs", "1000", command=command)
        add("refuse", ["--fs"], "nofs.mat", "--fs", "-3", command=command)
        add("answer", [], "cube.mat", "--map", "force=Force,a1=Acceleration[1]", command=command)  # read as 2×N
        add("refuse", ["one index per axis"], "realizations.mat", "--map", "force=Force[1],a1=Acceleration[1]",
            command=command)  # realization × channel × time: which realization is not guessed
        add("answer", [], "realizations.mat", "--map", "force=Force[1],a1=Acceleration[1,1],a2=Acceleration[1,2]",
            command=command)
        add("refuse", ["textfs.mat"], "textfs.mat", command=command)
        add("answer", [], "time.mat", command=command)
        add("refuse", ["--fs"], "glitch.csv", "--fs", "1000", command=command)
    return out

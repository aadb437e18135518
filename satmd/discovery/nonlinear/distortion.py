"""The distortion tests of one recording and the FRFs of several on one grid (`satmd.discovery.nonlinear`, step 1).

`NonlinearReport` is the ``nonlinear`` block of SPEC §9; `distortion_test` and `multisine_test` judge one
recording (random force: distortion regressors in local windows; multisine: its detection lines);
`common_frfs` estimates several recordings on one grid.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...conventions import ACCEL_CHANNELS
from ...signal.periodic import multisine_arrays
from .stats import (
    NonlinearTest,
    distortion_regressors,
    integrate,
    linearity_test,
    separate_linearity_test,
)

UNEXPLAINED_NL = "nonlinear_unexplained"
EXPERIMENT_LEVEL = "record a second level (about 20 dB apart, same band): the level dependence names the element"
EXPERIMENT_MULTISINE = ("a random-phase odd multisine with detection lines (several realisations, ≥ 2 periods): "
                        "separates noise from distortion and odd from even nonlinearity")


@dataclass(frozen=True)
class NonlinearReport:
    """The ``nonlinear`` block of SPEC §9 with its evidence.

    Attributes
    ----------
    detected : whether any test rejects linearity at its level
    tests : list of `NonlinearTest`
    findings : list of `NonlinearFinding` (read by the JSON keys too): name, parameters, ci95, equivalent,
        equivalent_linear, explanation (and
        ``character`` or ``modes`` for a ``nonlinear_unexplained`` finding, SPEC §9)
    experiments : what to record next to settle what is open
    levels : one level figure per recording (force RMS), in the order given
    set_aside : linear effects a one-recording fit named while distortion is present (not physics)
    model : a structure's `satmd.structure.StructureModel` (its linear part and joint), when one was fitted
    deferred : the named finding with its time-domain strength, left to be made (`findings.with_strength`)
    """

    detected: bool
    tests: list
    findings: list
    experiments: list = field(default_factory=list)
    levels: list = field(default_factory=list)
    set_aside: list = field(default_factory=list)
    model: object = field(default=None, repr=False, compare=False)
    deferred: Callable | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict:
        """The SPEC §9 ``nonlinear`` block (plus ``experiments``)."""
        keys = ("name", "between", "location", "law", "parameters", "ci95", "equivalent", "equivalent_linear", "character",
                "modes", "fit", "explanation")
        out = {"detected": bool(self.detected), "tests": [t.to_dict() for t in self.tests],
               "findings": [{k: f[k] for k in keys if k in f} for f in self.findings],  # typed or plain dicts
               "experiments": list(self.experiments)}
        if self.set_aside:
            out["set_aside"] = list(self.set_aside)
        return out

    def report(self) -> str:
        """Plain-language text."""
        head = "nonlinearity DETECTED" if self.detected else "no nonlinearity detected (consistent with a linear rig)"
        if not self.detected and self.tests and all(t.not_run for t in self.tests):
            head = "linearity not tested: no test could run on these data"
        lines = [f"[[Nonlinearity]] {head}"]
        lines += [f"    test {line}" for line in _test_lines(self.tests)]
        for f in self.findings:
            lines.append(f"  - {f['name']}: {f['explanation']}")
            if f.get("equivalent"):
                named = [e if isinstance(e, str) else f"{e['law']} (ΔBIC {e['delta_bic']:.1f})" for e in f["equivalent"]]
                lines.append(f"     equally good: {', '.join(named)} (the levels cannot tell them apart)")
        if self.set_aside:
            lines.append("    linear effects a fit would name are set aside while distortion is present: "
                         + ", ".join(self.set_aside))
        lines += [f"    next experiment: {e}" for e in self.experiments]
        return "\n".join(lines)

    def __str__(self):
        return self.report()


def _test_lines(tests) -> list:
    """Each test's line, the recordings' tests that could not run for one reason said once
    (``distortion_lines#1–#4: not run (...)``: four levels' identical lines told a reader nothing more)."""
    lines, k = [], 0
    while k < len(tests):
        t, j = tests[k], k + 1
        if t.not_run and "#" in t.name:  # one test a recording: name#k
            base = t.name.split("#")[0]
            while j < len(tests) and tests[j].not_run == t.not_run and tests[j].name.split("#")[0] == base:
                j += 1
        if j - k > 1:
            lines.append(f"{t.name}–#{tests[j - 1].name.split('#')[-1]}: not run ({t.not_run})")
        else:
            lines.append(t.report())
        k = j
    return lines


# --- detection on one recording ----------------------------------------------------------------------------
def distortion_test(recording, band_hz=None, alpha: float = 1e-3, band=None) -> NonlinearTest:
    """Distortion test of one random-force recording (force and accelerations, or force and any output ``y``).

    Parameters
    ----------
    recording : Recording with ``force`` and ``acc1``/``acc2`` (SATMD) or one other output channel
    band_hz : (lo, hi) Hz (default: the band the force excites)
    alpha : level
    band : former name of ``band_hz`` (deprecated)

    Returns
    -------
    NonlinearTest
    """
    from ...errors import DataError, renamed_keyword
    from ...signal.excitation import excitation_of
    from ...signal.lpm import excited_band

    kind = excitation_of(recording).kind
    if kind in ("impact", "sweep"):  # the local regressors need a broadband force at every moment
        raise DataError(f"the distortion test needs a random or periodic force; a{'n' if kind == 'impact' else ''} "
                        f"{kind} record cannot be tested for distortion (record two levels apart to see level "
                        "dependence, or a periodic multisine for its detection lines)")
    band_hz = renamed_keyword(band, band_hz, "distortion_test")
    fs = recording.fs_hz
    x = recording["force"]
    if band_hz is None:
        lo, hi, _ = excited_band(x, fs)
        band_hz = (lo, hi)
    accs = [c for c in ("acc1", "acc2") if c in recording.channels]
    if accs:
        responses = {ch: recording[c] for c, ch in zip(("acc1", "acc2"), ACCEL_CHANNELS) if c in recording.channels}
        predicted = linear_prediction(recording, band_hz)
        a1, a2 = predicted.get(ACCEL_CHANNELS[0]), predicted.get(ACCEL_CHANNELS[1])
        signals: dict[str, np.ndarray] = {}
        shapes: dict[str, tuple[str, ...]] = {}
        if a1 is not None:
            signals["u1"], shapes["u1"] = integrate(a1, fs, 2, band_hz), ("cube",)
        if a1 is not None and a2 is not None:
            signals["d"], shapes["d"] = integrate(a2 - a1, fs, 2, band_hz), ("cube",)
            signals["v"], shapes["v"] = integrate(a2 - a1, fs, 1, band_hz), ("cube", "absv", "sign")
    else:
        others = [c for c in recording.channels if c != "force"]
        responses = {c: recording[c] for c in others}
        y = recording[others[0]]
        signals = {"y": y - np.mean(y), "dy": np.gradient(y) * fs}
        shapes = {"y": ("square", "cube"), "dy": ("cube", "absv")}
    regs = distortion_regressors(signals, shapes)
    if accs:
        return separate_linearity_test(x, responses, fs, regs, band_hz=band_hz, alpha=alpha)
    return linearity_test(x, responses, fs, regs, band_hz=band_hz, alpha=alpha)


def multisine_test(recording, alpha: float = 1e-3) -> NonlinearTest:
    """Detection-line test of a multisine recording, every output channel (Bonferroni over them).

    Parameters
    ----------
    recording : Recording with multisine meta (see `is_multisine`)
    alpha : level

    Returns
    -------
    NonlinearTest
        ``distortion_lines``; ``details`` per channel with the odd and even ratios.
    """
    from .periodic import detection_lines_test, forced_lines, without_linear_response

    u, outs, lines = multisine_arrays(recording)
    hi = lines.max() * recording.fs_hz / u.shape[-1]
    forced = np.union1d(lines, forced_lines(u, lines=lines))  # a line with force on it is no detection line
    outs = {c: without_linear_response(u, y, lines) for c, y in outs.items()}
    tests = {c: detection_lines_test(u, y, forced, recording.fs_hz, band_hz=(0.0, 1.5 * hi), alpha=alpha / len(outs))
             for c, y in outs.items()}
    worst = min(tests.values(), key=lambda t: t.p_value)
    p = min(1.0, worst.p_value * len(tests))
    details: dict = {c: t.details for c, t in tests.items()} | {"explained": {}}
    if all(t.not_run for t in tests.values()):  # e.g. a chirp over the whole band leaves no line free of force
        details["reason"] = "; ".join(sorted({f"{t.not_run}" for t in tests.values()}))
    return NonlinearTest("distortion_lines", p, worst.bands_hz, alpha, details)


def linear_prediction(recording, band_hz) -> dict:
    """The accelerations the best linear approximation predicts from the force alone (LPM FRF x force spectrum).

    Regressors built from these, not from the measured responses, hold no response noise: the
    distortion test's residual (which is that noise under the null) is then independent of them.
    """
    from ...signal.lpm import lpm

    est = lpm(recording, band_hz=band_hz)
    n, fs = recording.n_samples, recording.fs_hz
    x = recording["force"]
    X = np.fft.rfft(x - x.mean())
    f = np.fft.rfftfreq(n, 1.0 / fs)
    keep = (f >= est.freq_hz[0]) & (f <= est.freq_hz[-1])
    out = {}
    for ch, h in est.frf.items():
        H = np.zeros(f.size, complex)
        H[keep] = np.interp(f[keep], est.freq_hz, h.real) + 1j * np.interp(f[keep], est.freq_hz, h.imag)
        out[ch] = np.fft.irfft(H * X, n)
    return out


def strongest_regressor(test: NonlinearTest) -> str | None:
    """The regressor group that explains most of the distortion (a hint, not a name)."""
    regs = test.details.get("regressors") or []
    return regs[0] if regs else None


def concentrated_bands(test: NonlinearTest, share: float = 0.25, smooth: int = 7) -> list:
    """Where a test's per-point score is significant *and* within ``share`` of its peak (smoothed): the locus."""
    score = test.details.get("scores")
    freq = test.details.get("freq_hz")
    if score is None or not test.bands_hz:
        return test.bands_hz
    assert freq is not None  # stored with the scores
    s = np.convolve(score, np.ones(smooth) / smooth, mode="same")
    on = s >= share * s.max()
    sig = np.zeros(freq.size, np.bool_)
    for a, b in test.bands_hz:
        sig |= (freq >= a) & (freq <= b)
    on &= sig
    bands, start = [], None
    for i, v in enumerate(np.append(on, False)):
        if v and start is None:
            start = i
        elif not v and start is not None:
            bands.append([float(freq[start]), float(freq[i - 1])])
            start = None
    return bands or test.bands_hz

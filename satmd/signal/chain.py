"""What the measurement chain does to an FRF estimate, said in words (SPEC §9 ``measurement``).

Every check here is about the *chain* (sensors, excitation, estimator), never
about the structure: a finding names the artifact, how large it is next to the
noise, and the setting that removes it. Discovery lists these apart from
physics, so an artifact of the chain never appears as an effect.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from ..conventions import TINY


@dataclass(frozen=True)
class MeasurementFinding:
    """One artifact of the measurement chain.

    Attributes
    ----------
    name : short identifier (``resolution_bias``, ``force_noise_bias``, ``clipping``, ...)
    explanation : what it is and how large, in words
    remedy : the setting or change that removes it
    corrected : True when satmd already removed it from the estimate, or models it in every fit
    values : the numbers a fit needs to model it (e.g. an exponential window's ``decay_s``); not reported
    """

    name: str
    explanation: str
    remedy: str
    corrected: bool = False
    values: dict = field(default_factory=dict, compare=False)

    def to_dict(self) -> dict:
        return {k: v for k, v in asdict(self).items() if k != "values"}


def half_power_widths(freq_hz: np.ndarray, h: np.ndarray, min_height: float = 0.2) -> list[tuple[float, float]]:
    """(peak frequency, half-power width) of each resonance peak of |h| taller than ``min_height`` × max."""
    mag = np.abs(h)
    out = []
    top = mag.max()
    for i in range(1, mag.size - 1):
        if mag[i] < min_height * top or mag[i] < mag[i - 1] or mag[i] < mag[i + 1]:
            continue
        half = mag[i] / np.sqrt(2.0)
        lo = i
        while lo > 0 and mag[lo] > half:
            lo -= 1
        hi = i
        while hi < mag.size - 1 and mag[hi] > half:
            hi += 1
        if mag[lo] > half or mag[hi] > half:
            continue  # the peak runs off the band: no width to measure
        f_lo = np.interp(half, [mag[lo], mag[lo + 1]], [freq_hz[lo], freq_hz[lo + 1]])
        f_hi = np.interp(half, [mag[hi], mag[hi - 1]], [freq_hz[hi], freq_hz[hi - 1]])
        out.append((float(freq_hz[i]), float(f_hi - f_lo)))
    return out


def sharpest_resonance(freq_hz, channels: dict):
    """(frequency, half-power width) of the narrowest resonance over the channels, or None."""
    peaks = [p for h in channels.values() for p in half_power_widths(freq_hz, h)]
    return min(peaks, key=lambda p: p[1]) if peaks else None


def welch_findings(freq_hz, channels: dict, std: dict, resolution_hz: float, segments: int,
                   estimator: str) -> list[MeasurementFinding]:
    """Resolution bias and too few averages of a Welch (H1/H2, Hann) estimate."""
    found = []
    sharp = sharpest_resonance(freq_hz, channels)
    if sharp is not None:
        f0, width = sharp
        bias = 4.0 / 3.0 * (resolution_hz / width) ** 2  # Bendat & Piersol, B_e = 2Δf for Hann
        i = int(np.argmin(np.abs(freq_hz - f0)))
        rel_std = min(std[c][i] / max(abs(channels[c][i]), TINY) for c in channels)
        if bias > 0.5 * rel_std:
            need = 2 ** int(np.ceil(np.log2(resolution_hz / (width * np.sqrt(0.75 * 0.1 * rel_std)))))
            found.append(MeasurementFinding(
                "resolution_bias", corrected=True, explanation=
                f"the {estimator} estimate's resolution ({resolution_hz:.3g} Hz) smears the resonance at "
                f"{f0:.1f} Hz (half-power width {width:.2f} Hz): its peak is about {100 * bias:.2g} % low, "
                f"{bias / max(rel_std, TINY):.1f}× the noise there. satmd compares the model through the same "
                f"window (its power kernel, to second order), so the smearing is not taken for physics",
                remedy=f"use the local polynomial estimator (the default), or nperseg at least {need}× longer"))
    if segments < 16:
        found.append(MeasurementFinding(
            "too_few_averages",
            f"only {segments} Welch averages: coherence and std are rough and H1 is biased where coherence is low",
            "record longer, or use the local polynomial estimator (the default)"))
    return found


def lpm_findings(freq_hz, channels: dict, std: dict, settings: dict, force_noise_bias: np.ndarray,
                 requested_band=None, bias_bound=None, sweep: bool = False) -> list[MeasurementFinding]:
    """Short record for the resonances, force-noise bias (corrected, or not told), unexcited band (LPM).

    ``bias_bound``: per point, the relative force-noise bias that may remain (`satmd.signal.lpm.LPMEstimate`).
    ``sweep``: the force is a sweep, whose windows the local polynomial cannot fit are the structure's (`_lines`).
    """
    found = []
    sharp = sharpest_resonance(freq_hz, channels)
    window = settings["window_hz"]
    if sharp is not None and window > sharp[1] / 4:
        need = settings["record_s"] * window / (sharp[1] / 5)
        found.append(MeasurementFinding(
            "short_record",
            f"each local window spans {window:.3g} Hz, more than a quarter of the narrowest resonance's "
            f"half-power width ({sharp[1]:.2f} Hz at {sharp[0]:.1f} Hz): the local polynomial may bend the peak",
            f"record at least {need:.0f} s"))
    bias = float(np.max(force_noise_bias)) if np.size(force_noise_bias) else 0.0
    if bias > 0:
        rel = min(float(np.median(std[c] / np.maximum(np.abs(channels[c]), TINY))) for c in channels)
        if bias > 0.1 * rel:
            found.append(MeasurementFinding(
                "force_noise_bias",
                f"noise on the force sensor pulls the FRF towards zero by up to {100 * bias:.2g} % "
                f"({bias / max(rel, TINY):.1f}× the typical noise); estimated from the force's noise floor "
                f"outside the excited band and removed",
                "a cleaner force signal (higher excitation level or a quieter load cell)", corrected=True))
    found += _unseen_floor(channels, std, settings, bias_bound)
    found += _lines(settings.get("lines_removed_hz") or {}, settings.get("line_windows_hz") or [],
                    settings["window_hz"], sweep)
    lo, hi = settings["band_hz"]
    req_lo, req_hi = requested_band or (None, None)
    cut = [f"{a:g}–{b:g} Hz" for a, b in ((req_lo, lo), (hi, req_hi))
           if a is not None and b is not None and b - a > max(2.0, 0.02 * (hi - lo))]
    if cut:
        found.append(MeasurementFinding(
            "unexcited_band",
            f"the force excites {lo:.1f}–{hi:.1f} Hz only; {' and '.join(cut)} of the requested band carry no "
            f"force and were left out",
            "widen the excitation band of the shaker signal"))
    return found


def _lines(removed: dict, dropped: list, window_hz: float, sweep: bool = False) -> list[MeasurementFinding]:
    """Lines in the responses that the force does not explain: removed from the record, or windows dropped.

    Under a sweep, windows whose residual stands out are the structure's own unless they sit at the mains: its
    response rings on at a resonance after the force has moved past it (on a simulated chain swept 15 → 2 Hz in
    60 s, linear and without any interference, three windows beside its 7.1 Hz mode), and a joint's harmonics of
    the force's frequency lie where the force is not; neither is the sensor chain's."""
    freqs = sorted({round(f, 2) for fs in removed.values() for f in fs} | {round(f, 2) for f in dropped})
    if not freqs:
        return []
    tol = max(window_hz, 0.5)
    mains = [m for m in (50.0, 60.0) if all(min(abs(f - k * m) for k in range(1, int(f / m) + 2)) <= tol
                                               for f in freqs)]
    where = ", ".join(f"{f:.2f}" for f in freqs[:12]) + (" ..." if len(freqs) > 12 else "")
    if sweep and not mains:
        return [MeasurementFinding(
            "sweep_windows_left_out",
            f"{len(freqs)} estimate window(s) at {where} Hz carry response the force in them does not explain and "
            "were left out: under a sweep, the structure ringing on at a resonance after the force moved past it, or "
            "a nonlinearity's harmonics of the force's frequency, not the sensor chain",
            "sweep slower through the resonances, or let the record ring out after the sweep (its whole transient is "
            "then estimated without windows), or use a periodic excitation", corrected=True)]
    did = []
    if removed:
        did.append(f"{sum(len(v) for v in removed.values())} sinusoid(s) fitted and subtracted from "
                   f"{', '.join(sorted(removed))}")
    if dropped:
        did.append(f"{len(dropped)} estimate window(s) still carrying a line left out")
    what = f"lines at multiples of {mains[0]:g} Hz (mains hum)" if mains else "narrow lines"
    return [MeasurementFinding(
        "mains_hum" if mains else "narrowband_interference",
        f"the responses carry {what} that the force does not explain, at {where} Hz: {'; '.join(did)}. They are "
        f"the sensor chain's, not the structure's",
        "check grounding and shielding of the accelerometer cables (ground loop), or use differential inputs"
        if mains else "look for electrical pick-up or a rotating machine nearby", corrected=True)]


def _unseen_floor(channels, std, settings, bias_bound) -> list[MeasurementFinding]:
    """No force-noise floor could be told from the force: nothing corrected; say how large the bias may be."""
    status = settings.get("force_noise_status")
    if status in (None, "estimated"):
        return []
    why = {"no_region": "the force is excited up to (nearly) the Nyquist frequency, so no band above it shows "
                        "the force sensor's noise alone",
           "not_below_excitation": "the flat stretch above the excited band is not 30 dB under the excitation, so "
                                   "it may be force, not noise"}.get(status)
    if why is None:
        slope = settings.get("force_noise_slope_db_per_octave")
        span = settings.get("force_noise_span_hz") or [float("nan")] * 2
        why = (f"above the excited band the force spectrum keeps falling ({slope:.1f} dB/octave up to "
               f"{span[1]:.0f} Hz) and never levels off: a roll-off is excitation, not noise")
    if bias_bound is not None and np.size(bias_bound) and settings.get("force_noise_bound") is not None:
        rel = np.concatenate([std[c] / np.maximum(np.abs(channels[c]), TINY) for c in channels])
        worst = float(np.max(np.asarray(bias_bound)))
        ratio = float(np.max(np.tile(bias_bound, len(channels)) / np.maximum(rel, TINY)))
        size = (f"the bias it may cause (H pulled towards zero by the noise-to-force power ratio) is at most "
                f"{100 * worst:.2g} %, {ratio:.2g}× the noise at its worst point")
    else:
        size = "its bias on the FRF cannot be bounded from this record"
    return [MeasurementFinding(
        "force_noise_floor_unseen",
        f"no force-noise floor can be told from the force spectrum: {why}. No force-noise correction was made; "
        f"{size}",
        "record at a higher sample rate (so the force's noise floor shows above the shaker's roll-off), or "
        "measure the load cell's noise with the shaker off", corrected=False)]


def sweep_findings(excitation, freq_hz, channels: dict) -> list[MeasurementFinding]:
    """A single sweep faster than the sharpest resonance can follow (ISO 7626-2: rate < 0.9 f² ζ² Hz/s).

    With half-power width B = 2ζf the limit is 0.225 B² Hz/s; a logarithmic
    sweep's rate at f is f ln2 times its octaves per second.
    """
    if excitation.kind != "sweep" or not excitation.sweep:
        return []
    sharp = sharpest_resonance(freq_hz, channels)
    if sharp is None:
        return []
    f_r, width = sharp
    s = excitation.sweep
    rate = (abs(s["rate_hz_per_s"]) if "rate_hz_per_s" in s
            else abs(s.get("rate_octaves_per_s", 0.0)) * f_r * np.log(2.0))
    limit = 0.225 * width ** 2
    if rate <= limit:
        return []
    return [MeasurementFinding(
        "fast_sweep",
        f"the sweep passes the {f_r:.4g} Hz resonance (half-power width {width:.3g} Hz) at {rate:.3g} Hz/s, "
        f"{rate / limit:.1f}x faster than it can follow (ISO 7626-2: {limit:.3g} Hz/s): the estimate is smeared "
        f"and shifted there",
        f"sweep slower than {limit:.3g} Hz/s through the resonances, or repeat the sweep periodically so that "
        f"the steady periods are averaged")]


def clipping_findings(recording) -> list[MeasurementFinding]:
    """A channel that sits on its extremes for several samples was clipped."""
    from ..io.recording import clipped_channels

    return [MeasurementFinding(
        "clipping",
        f"channel {name} sits at its extreme value for {count} samples: it was clipped, which spreads "
        f"harmonics over the band",
        f"lower the excitation level or raise the input range of {name}")
        for name, count in clipped_channels(recording).items()]

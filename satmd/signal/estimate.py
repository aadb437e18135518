"""FRFs from time recordings: the local polynomial method (default, `satmd.signal.lpm`) or Welch H1/H2.

`estimate_frf` picks the estimator, keeps to the band the force excites, and
records in ``FRFData.estimator`` how the FRFs were made and what the
measurement chain did (`satmd.signal.chain`); Welch machinery lives in
`satmd.signal.welch`, transmissibilities in `satmd.signal.transmissibility`.
"""
from __future__ import annotations

import warnings

from numbers import Real

import numpy as np

from ..conventions import ESTIMATE_REL_FLOOR, RECORDING_CHANNELS
from ..errors import DataWarning, DataError, renamed_keyword
from ..validation import LOAD_HINT, Interval, Whole, check_data, validate_params
from ..io.frfdata import FRFData
from ..io.recdata import check_rate
from ..io.recording import Recording
from .transmissibility import Transmissibility, model_transmissibility, save_transmissibility, transmissibility
from .welch import (
    STD_FLOOR,
    Spectra,
    check_estimator,
    frf_from_spectra,
    kernel_rms_hz,
    usable_bins,
    default_nperseg,
    get_window,
    spectra,
)

__all__ = ["estimate_frf", "describe_estimate", "default_nperseg", "get_window", "spectra", "Spectra",
           "Transmissibility", "model_transmissibility", "transmissibility", "save_transmissibility"]


@validate_params({"nperseg": [None, Interval(Whole, 8)], "overlap": [None, Interval(Real, 0, 1, "hi")],
                  "width_hz": [None, Interval(Real, 0, open="lo")], "period_s": [None, Interval(Real, 0, open="lo")]})
def estimate_frf(recording: Recording, nperseg: int | None = None, window=None, overlap: float | None = None,
                 estimator: str | None = None, band_hz=None, width_hz: float | None = None,
                 excitation: str = "auto", period_s: float | None = None, band=None) -> FRFData:
    """FRFs a1 = acc1/force and a2 = acc2/force with std, coherence and measurement-chain findings.

    Parameters
    ----------
    recording : Recording
        With a ``force`` channel and ``acc1`` and/or ``acc2``.
    nperseg, window, overlap :
        Welch settings (samples per segment, any `scipy.signal.get_window`
        name, overlap fraction); giving any of them selects Welch H1.
    estimator : {"lpm", "H1", "H2"}, optional
        ``lpm``: the local polynomial method on the full record (no window,
        full resolution, leakage and transient removed, std from the local
        residual; `satmd.signal.lpm`). ``H1`` / ``H2``: Welch averaging (noise on
        the responses / on the force). Default: the estimator the excitation
        calls for: the mean over steady periods at the excited lines for a
        periodic force (`satmd.signal.periodic`), H1 over hits for impacts
        (`satmd.signal.impact`), the LPM for random forces and sweeps.
    band_hz : (lo, hi), optional
        Band to keep in Hz, either may be None (``band=``, its former name, still works and warns). The LPM also keeps to the band
        the force excites, and says so.
    width_hz : float, optional
        LPM window width in Hz (default: 0.3 Hz, or a fifth of the sharpest
        resonance's half-power width when that is narrower).
    excitation : {"auto", "random", "periodic", "impact", "sweep"}
        What excited the rig; ``auto`` detects it from the force
        (`satmd.signal.excitation`). The estimate's ``estimator["excitation"]`` says
        what was found or given.
    period_s : float, optional
        The period of a periodic force in seconds (default: detected).

    band : (lo, hi), optional
        The former name of ``band_hz`` (deprecated: it warns).
    Returns
    -------
    FRFData
        With ``std``, ``coherence`` and ``estimator`` (method, settings,
        ``noise_dof``, and ``measurement`` findings, see `satmd.signal.chain`).
    """
    from .excitation import excitation_of, received

    check_data(recording, "recording", (Recording,), "estimate_frf", hint=LOAD_HINT)
    band_hz = renamed_keyword(band, band_hz, "estimate_frf")
    source, responses = _check_force(recording)
    welch_given = any(v is not None for v in (nperseg, window, overlap))
    at_door = received(recording, excitation, period_s)
    exc = excitation_of(at_door)
    if estimator is None and not welch_given and width_hz is None and _periodic_realisations(at_door):
        return _estimate_realisations(at_door, band_hz)
    designed = exc.kind in ("periodic", "impact")
    if exc.kind == "sweep":  # whole transients in the record: no leakage term, however fast the sweep
        from .sweepfrf import at_rest_at_the_end

        designed = at_rest_at_the_end(recording, responses)
    if estimator is None and not welch_given and width_hz is None and designed:
        _check_constant(recording, source, responses)
        return _estimate_designed(recording, exc, band_hz)
    if exc.kind == "sweep" and exc.sweep and not designed:  # cut off mid-sweep: its ends carry the cut's transient
        lo_s, hi_s = sorted((exc.sweep["f_start_hz"], exc.sweep["f_end_hz"]))
        band_hz = (max(1.05 * lo_s, band_hz[0] if band_hz and band_hz[0] is not None else 0.0),
                   min(0.95 * hi_s, band_hz[1] if band_hz and band_hz[1] is not None else np.inf))
    method = ("H1" if welch_given else "lpm") if estimator is None else str(estimator)
    if method.lower() == "lpm":
        if welch_given:
            raise DataError("nperseg, window and overlap are Welch settings: they do not apply to the lpm estimator")
        data = _estimate_lpm(recording, band_hz, width_hz, sweep=exc.kind == "sweep")
    else:
        data = _estimate_welch(recording, nperseg, "hann" if window is None else window,
                               0.5 if overlap is None else overlap, method, band_hz)
    from dataclasses import replace

    from .chain import sweep_findings

    extra = [f.to_dict() for f in sweep_findings(exc, data.freq_hz, data.channels)]
    info = dict(data.estimator, excitation=exc.to_dict(),
                measurement=list(data.estimator.get("measurement", [])) + extra)
    return replace(data, estimator=info)


def describe_estimate(data) -> str:
    """One line on how FRFs were estimated from a recording (empty for other FRFs); ``data``: FRFData or its
    ``estimator`` dict."""
    e = data if isinstance(data, dict) else data.estimator
    if not e:
        return ""
    if e["method"] == "sweep":
        lo, hi = e["band_hz"]
        return (f"the whole record's spectra of a sweep at rest at both ends, G fitted locally, {e['points']} "
                f"independent points {lo:.4g}–{hi:.4g} Hz, noise from {e['noise_dof']:.0f} degrees of freedom")
    if e["method"] in ("periodic", "impact"):
        lo, hi = e["band_hz"]
        how = e.get("excitation", {})
        what = (f"the mean over {how.get('periods_used')} steady periods of {how.get('period_s'):g} s "
                f"({how.get('source')} periodic force), at the {e['points']} excited lines"
                if e["method"] == "periodic" else
                f"H1 over {how.get('hits')} hits ({how.get('source')} impacts), {e['points']} lines")
        return f"{what} {lo:.4g}–{hi:.4g} Hz, noise from {e['noise_dof']:.0f} degrees of freedom"
    if e["method"] == "realisations":
        lo, hi = e["band_hz"]
        return (f"the best linear approximation over {e['realisations']} realisations ({e['steady_periods']} steady "
                f"periods each), at the {e['points']} lines excited in every one {lo:.4g}–{hi:.4g} Hz, noise and "
                f"nonlinear distortion from their spread, {e['noise_dof']:.0f} degrees of freedom")
    if e["method"] == "lpm":
        lo, hi = e["band_hz"]
        return (f"local polynomial method on the full {e['record_s']:g} s record, {e['points']} independent points "
                f"{lo:.1f}–{hi:.1f} Hz (the band the force excites), windows of {e['window_hz']:.3g} Hz, "
                f"noise from {e['noise_dof']:.0f} degrees of freedom")
    return (f"Welch {e['method'][6:]}, {e['window']} window, nperseg={e['nperseg']} ({e['resolution_hz']:.3g} Hz), "
            f"{e['segments']} averages")


def _check_force(recording: Recording):
    source = recording.meta.get("source", "recording")
    if "force" not in recording.channels:
        raise DataError(f"{source}: no force channel (output-only recording): FRFs need the force; "
                        f"transmissibilities A2/A1 do not (satmd.signal.transmissibility)")
    responses = [r for r in RECORDING_CHANNELS if r in recording.channels]
    if not responses:
        raise DataError(f"{source}: no acc1 or acc2 channel (has {', '.join(recording.channels)})")
    check_rate(source, recording.fs_hz)
    return source, responses


def _check_constant(recording: Recording, source, responses):
    """A constant force or response: nothing was excited or measured (said before any spectrum is taken)."""
    for name in ("force", *responses):
        if np.ptp(recording[name]) == 0:
            raise DataError(f"{source}: channel {name} is constant ({recording[name][0]:g} throughout): "
                            f"{'nothing excited the rig' if name == 'force' else 'the sensor recorded nothing'}")


def _estimate_lpm(recording: Recording, band_hz, width_hz, sweep: bool = False) -> FRFData:
    from .chain import clipping_findings, lpm_findings
    from .lpm import lpm

    source, responses = _check_force(recording)
    if recording.n_samples < 256:
        raise DataError(f"{source}: {recording.n_samples} samples is too short for a local-polynomial FRF "
                        f"estimate (need at least 256)")
    _check_constant(recording, source, responses)
    est = lpm(recording, band_hz=band_hz, width_hz=width_hz)
    s = est.settings
    findings = clipping_findings(recording) + lpm_findings(est.freq_hz, est.frf, est.std, s,
                                                           est.force_noise_bias, band_hz, est.force_noise_bias_bound,
                                                           sweep)
    floor = 1e-10 * max(np.max(np.abs(h)) for h in est.frf.values())
    std = {c: np.maximum(v, floor) for c, v in est.std.items()}
    info = {"method": "lpm", "reference": "Pintelon et al. 2010, local polynomial method",
            "record_s": round(s["record_s"], 6), "band_hz": [round(b, 6) for b in s["band_hz"]],
            "window_hz": round(s["window_hz"], 6), "bins_per_window": s["bins_per_window"],
            "degree": s["degree"], "points": int(est.freq_hz.size), "noise_dof": round(s["noise_dof"], 1),
            "force_noise_floor_detected": s["force_noise_floor"] is not None,
            "max_force_noise_bias": float(np.max(est.force_noise_bias)),
            "force_noise_status": s["force_noise_status"],
            "max_force_noise_bias_bound": float(np.max(est.force_noise_bias_bound)),
            "measurement": [f.to_dict() for f in findings]}
    meta = {"source": str(source), "estimator": "lpm", "resolution_hz": f"{s['window_hz']:.6g}",
            "band_hz": f"{s['band_hz'][0]:.6g}:{s['band_hz'][1]:.6g}", "noise_dof": f"{s['noise_dof']:.0f}",
            "noise": "local-polynomial residual, noise spectra smoothed over "
                     f"{s['smooth_windows']} windows"}
    return FRFData(est.freq_hz, est.frf, std, meta, coherence=est.coherence, estimator=info,
                   correlation=est.correlation, bias_bound=est.force_noise_bias_bound)


def _estimate_designed(recording: Recording, exc, band_hz) -> FRFData:
    """FRFs of a periodic or an impact excitation (`satmd.signal.periodic`, `satmd.signal.impact`)."""
    from .chain import clipping_findings
    from .impact import impact_frf, whole_record_frf
    from .periodic import excitation_findings, periodic_frf
    from .sweepfrf import at_rest_at_the_end

    source, responses = _check_force(recording)
    if exc.kind == "periodic":
        f, frf, std, coh, dof = periodic_frf(recording, exc, responses, band_hz)
        extra = []
        ref = "Pintelon & Schoukens 2012, periodic excitation: mean over steady periods"
        noise = f"spread over {len(exc.steady)} steady periods"
    elif (exc.kind == "impact" and not exc.dropped and "cut_mid_ring" not in recording.meta
          and at_rest_at_the_end(recording, responses)):
        f, frf, std, coh, dof, extra = whole_record_frf(recording, exc, responses, band_hz)
        ref = "hits as one transient: the whole record's spectra, force windowed to its pulses, G fitted locally"
        noise = "local residual, smoothed over neighbouring windows"
    elif exc.kind == "impact":
        f, frf, std, coh, dof, extra = impact_frf(recording, exc, responses, band_hz)
        ref = "H1 over hits, force window (ISO 7626-5)"
        noise = f"scatter over {len(exc.hits)} hits" if len(exc.hits) > 1 else "the quiet tail of the one hit"
    else:
        from .lpm import excited_band
        from .sweepfrf import sweep_frf

        lo, hi, _ = excited_band(recording["force"], recording.fs_hz)
        lo = lo if not band_hz or band_hz[0] is None else max(lo, band_hz[0])
        hi = hi if not band_hz or band_hz[1] is None else min(hi, band_hz[1])
        if hi <= lo:
            raise DataError(f"band {band_hz[0]}:{band_hz[1]} Hz holds nothing of the sweep's {lo:.4g}–{hi:.4g} Hz")
        f, frf, std, coh, dof = sweep_frf(recording, responses, (lo, hi))
        extra = []
        ref = "whole-record spectra of a sweep at rest at both ends, G fitted locally (no leakage term)"
        noise = "local residual, smoothed over neighbouring windows"
    findings = [x for x in clipping_findings(recording) if exc.kind != "impact"] + excitation_findings(exc) + extra
    floor = 1e-10 * max(np.max(np.abs(h)) for h in frf.values())
    std = {c: np.maximum(v, floor) for c, v in std.items()}
    info = {"method": exc.kind, "reference": ref, "record_s": round(recording.duration_s, 6),
            "band_hz": [round(float(f[0]), 6), round(float(f[-1]), 6)], "points": int(f.size),
            "noise_dof": round(float(dof), 1), "excitation": exc.to_dict(),
            "measurement": [x.to_dict() for x in findings]}
    decay = [x.values["decay_s"] for x in findings if "decay_s" in x.values]
    if decay:  # an exponential window: the estimate is H(iω + 1/τ), and fits compare the model there
        info["window_decay_s"] = float(decay[0])
    meta = {"source": str(source), "estimator": exc.kind, "band_hz": f"{f[0]:.6g}:{f[-1]:.6g}",
            "noise_dof": f"{dof:.0f}", "noise": noise}
    # beyond its noise, an estimate carries its model's and the chain's small systematic error: an effect whose
    # whole signature stays within it is reported as measurement, not physics (`satmd.discovery.budget`)
    return FRFData(f, frf, std, meta, coherence=coh, estimator=info, bias_bound=np.full(f.size, ESTIMATE_REL_FLOOR))


def _periodic_realisations(recording) -> bool:
    """A lab's realisations, each periodic with one layout (`excitation.with_realisations`)."""
    from .periodic import is_multisine

    return "realisation_samples" in recording.meta and is_multisine(recording) and \
        int(recording.meta.get("realisations", 1)) > 1


def _estimate_realisations(recording: Recording, band_hz) -> FRFData:
    """The best linear approximation over a lab's random-phase realisations (`periodic.multisine_frf`), its std
    from their spread: noise and the nonlinear distortion that changes with the phases (Pintelon & Schoukens)."""
    from .chain import clipping_findings
    from .periodic import in_band, multisine_frf

    source, responses = _check_force(recording)
    _check_constant(recording, source, responses)
    bla = multisine_frf(recording)
    f = bla.freq_hz
    keep = in_band(f, band_hz)
    if keep.sum() < 4:
        raise DataError(f"band {band_hz[0]}:{band_hz[1]} Hz holds {int(keep.sum())} of the excited lines "
                        f"({f[0]:.4g}–{f[-1]:.4g} Hz)")
    f = f[keep]
    m, p = int(bla.meta["realisations"]), int(bla.meta["periods"])
    frf = {c: v[keep] for c, v in bla.channels.items()}
    floor = 1e-10 * max(np.max(np.abs(h)) for h in frf.values())
    std = {c: np.maximum(v[keep], floor) for c, v in bla.std.items()}
    info = {"method": "realisations", "reference": "Pintelon & Schoukens 2012 ch. 3-4: the best linear "
            "approximation over random-phase realisations", "record_s": round(recording.duration_s, 6),
            "band_hz": [round(float(f[0]), 6), round(float(f[-1]), 6)], "points": int(f.size),
            "noise_dof": float(2 * (m - 1)), "realisations": m, "steady_periods": p,
            "measurement": [x.to_dict() for x in clipping_findings(recording)]}
    meta = {"source": str(source), "estimator": "realisations", "band_hz": f"{f[0]:.6g}:{f[-1]:.6g}",
            "noise_dof": f"{2 * (m - 1)}", "noise": f"spread over {m} realisations (noise and nonlinear distortion)"}
    return FRFData(f, frf, std, meta, coherence={c: v[keep] for c, v in bla.coherence.items()}, estimator=info,
                   bias_bound=np.full(f.size, ESTIMATE_REL_FLOOR))


def _estimate_welch(recording: Recording, nperseg, window, overlap, estimator, band_hz) -> FRFData:
    from .chain import clipping_findings, welch_findings
    from .lpm import excited_band

    est = check_estimator(estimator)
    source, responses = _check_force(recording)
    s = spectra(recording, "force", responses, nperseg, window, overlap)  # too short: said here first
    _check_constant(recording, source, responses)
    # bins the force never excited are noise over noise: keep to the excited band, as the LPM does
    lo, hi, _ = excited_band(recording["force"], recording.fs_hz)
    requested = band_hz
    band_hz = (lo if not band_hz or band_hz[0] is None else max(lo, band_hz[0]),
            hi if not band_hz or band_hz[1] is None else min(hi, band_hz[1]))
    if band_hz[1] <= band_hz[0]:
        raise DataError(f"band {requested[0]}:{requested[1]} Hz holds no frequency bin the force excites "
                        f"({lo:.1f}–{hi:.1f} Hz)")
    results = {r: frf_from_spectra(s, r, est) for r in responses}
    keep = usable_bins(source, s, [a for res in results.values() for a in res], band_hz)
    f = s.freq_hz[keep]
    channels, std, coh = {}, {}, {}
    for r, (h, g, sd) in results.items():
        ch = RECORDING_CHANNELS[r]
        channels[ch] = h[keep]
        coh[ch] = g[keep]
        std[ch] = np.maximum(sd[keep], STD_FLOOR * np.max(np.abs(h[keep])))
    if s.segments < 8:
        warnings.warn(f"{source}: only {s.segments} averages: coherence and std are rough; use a shorter nperseg",
                      DataWarning, stacklevel=2)
    resolution = recording.fs_hz / int(s.meta["nperseg"])
    findings = clipping_findings(recording) + welch_findings(f, channels, std, resolution, s.segments, est)
    meta = {"source": str(source), "estimator": est, **s.meta, "n_eff": f"{s.n_eff:.4g}",
            "noise": "coherence-based std (Bendat & Piersol)"}
    info = {"method": f"welch-{est}", "window": s.meta["window"], "nperseg": int(s.meta["nperseg"]),
            "kernel_rms_hz": kernel_rms_hz(get_window(window, int(s.meta["nperseg"])), recording.fs_hz),
            "overlap": float(s.meta["overlap"]), "segments": s.segments, "resolution_hz": resolution,
            "points": int(f.size), "noise_dof": round(2 * max(s.n_eff - 1.0, 0.5), 1),
            "measurement": [x.to_dict() for x in findings]}
    return FRFData(f, channels, std, meta, coherence=coh, estimator=info)

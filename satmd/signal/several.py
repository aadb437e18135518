"""Several recordings of one structure: on one frequency grid, repeats of one test pooled into one FRF.

- `common_frfs`: each recording's FRF on one grid (one band, one LPM window width), so that levels
  can be compared line by line (`on_common_grid` keeps the frequencies they share);
- `repeated_hits`: impact files of one test (hits of about one height) joined into one recording,
  whose FRF is H1 over every hit;
- `pooled`: the inverse-variance mean of FRFs on one grid; three or more periodic realisations give
  the best linear approximation, with the spread over realisations in its std.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..conventions import TINY
from .periodic import is_multisine, multisine_frf


def is_forced_recording(x) -> bool:
    """A time recording with a force channel (not FRFData)."""
    return hasattr(x, "fs_hz") and hasattr(x, "channels") and "force" in getattr(x, "channels", {})


def pooled(datas):
    """Inverse-variance mean of FRFData on one grid (std of the mean).

    Periodic realisations (``estimator.method`` periodic, three or more) give
    the best linear approximation: its std is the larger of the noise's and the
    spread over realisations (noise and the stochastic nonlinear distortion,
    Pintelon & Schoukens ch. 3), and ``estimator.nonlinear_variance_share``
    says how much of that spread the noise does not explain.
    """
    first = datas[0]
    k = len(datas)
    realisations = k >= 3 and all(d.estimator.get("method") == "periodic" for d in datas)
    chans, std, share = {}, {}, []
    for c in first.channels:
        w = np.stack([1.0 / np.maximum(d.std[c], TINY) ** 2 for d in datas])
        H = np.stack([d.channels[c] for d in datas])
        chans[c] = np.sum(w * H, axis=0) / w.sum(axis=0)
        std[c] = 1.0 / np.sqrt(w.sum(axis=0))
        if realisations:  # the spread over realisations: per part, of the mean
            spread = np.sqrt(np.sum(np.abs(H - H.mean(axis=0)) ** 2, axis=0) / (k - 1) / k / 2.0)
            share.append(float(np.median(np.maximum(spread ** 2 - std[c] ** 2, 0.0) / np.maximum(spread ** 2, TINY))))
            std[c] = np.maximum(std[c], spread)
    est = dict(first.estimator)
    if "noise_dof" in est and est["noise_dof"]:
        est["noise_dof"] = 2.0 * (k - 1) if realisations else float(est["noise_dof"]) * k
    est["pooled_records"] = k
    if realisations:
        est["realisations"] = k
        est["nonlinear_variance_share"] = round(max(share), 4)
    return replace(first, channels=chans, std=std, correlation={}, estimator=est)

#: Impact files whose median hit heights lie within this factor are repeats of one test, not levels.
IMPACT_LEVEL_FACTOR = 3.0


def repeated_hits(items):
    """Impact recordings of one test joined end to end (one Recording), or None when they are not that.

    Every item must be an impact recording at one sample rate with the same
    channels, and their median hit heights within `IMPACT_LEVEL_FACTOR`
    (farther apart they are levels, judged as such).
    """
    from .excitation import excitation_of, received
    from ..io.recording import Recording

    if len(items) < 2 or not all(is_forced_recording(x) for x in items):
        return None
    excs = [excitation_of(x) for x in items]
    if any(e.kind != "impact" for e in excs) or len({x.fs_hz for x in items}) > 1:
        return None
    if len({tuple(sorted(x.channels)) for x in items}) > 1:
        return None
    heights = [float(np.median([abs(x["force"][p] - np.median(x["force"])) for _, p in e.hits]))
               for x, e in zip(items, excs)]
    if max(heights) > IMPACT_LEVEL_FACTOR * min(heights):
        return None
    from .sweepfrf import at_rest_at_the_end

    joined = {c: np.concatenate([x[c] for x in items]) for c in items[0].channels}
    meta = {"source": " + ".join(str(x.meta.get("source", "recording")) for x in items)}
    responses = [c for c in ("acc1", "acc2") if c in items[0].channels]
    if not all(at_rest_at_the_end(x, responses, strict=True) for x in items):  # a file cut mid-ring: no whole-record transient
        meta["cut_mid_ring"] = "a file ends before its response has rung down"
    rec = Recording(items[0].fs_hz, joined, dict(items[0].units), meta)
    return received(rec, "impact")


# --- FRFs of several recordings on one grid ---------------------------------------------------------------
def common_frfs(recordings) -> list:
    """LPM FRFs of several recordings on one frequency grid (same band and window width).

    Parameters
    ----------
    recordings : list of Recording (same sample rate and length give the same grid)

    Returns
    -------
    list of FRFData
    """
    from .estimate import estimate_frf
    from .excitation import excitation_of
    from .lpm import excited_band

    if all(is_multisine(r) and (int(r.meta.get("realisations", 1)) > 1
                                or not {"acc1", "acc2"} & set(r.channels)) for r in recordings):
        return each_named(recordings, multisine_frf)  # several realisations in each file, or a generic output
    if all(is_multisine(r) for r in recordings):  # periodic: the estimator of the excitation, at its lines
        return each_named(recordings, estimate_frf)
    bands = each_named(recordings, lambda r: excited_band(r["force"], r.fs_hz)[:2])
    band = (max(b[0] for b in bands), min(b[1] for b in bands))
    band = _within_sweeps(recordings, band)
    first = each_named(recordings[:1], lambda r: estimate_frf(r, band_hz=band))[0]
    swept = any(excitation_of(r).kind == "sweep" for r in recordings)
    # sweeps: the first level's exact window (its rounded width lays the others' on another grid); random
    # forces keep the rounded width their level test was calibrated with (exact windows raised its false
    # alarms on linear structures from 0 to 2 in 104 in benchmarks/structures_levels.py)
    width = _window_of(first) if swept else first.estimator.get("window_hz")
    out = [first, *each_named(recordings[1:], lambda r: estimate_frf(r, band_hz=band, width_hz=width), start=2)]
    return [_with_model_error(d, r, band, width) if d.estimator.get("method") == "lpm" else d
            for d, r in zip(out, recordings)]


def each_named(recordings, call, start: int = 1) -> list:
    """``call(r)`` of each recording; a `DataError` about one of several recordings names its file (its source,
    else its place among them counted from ``start``) where the message does not: "the force is constant" alone
    does not say which level's."""
    from ..errors import DataError

    out = []
    for i, r in enumerate(recordings, start=start):
        try:
            out.append(call(r))
        except DataError as exc:
            source = str(r.meta.get("source") or f"recording {i}")
            if type(exc) is not DataError or source in str(exc):  # a subclass may be caught by its type: as it is
                raise
            raise DataError(f"{source}: {exc}") from None
    return out


def _window_of(data):
    """The LPM window width (Hz) that gives another recording of the same length ``data``'s windows: (bins − 1)
    times the bin width. The rounded ``window_hz`` does not: at 0.216667 Hz on a 60 s record it is 13.00002
    bins, which the LPM rounds to 15, and the two levels then share no frequency."""
    est = data.estimator or {}
    bins, record_s = est.get("bins_per_window"), est.get("record_s")
    if bins and record_s:
        return (int(bins) - 1) / float(record_s)
    return est.get("window_hz") or est.get("settings", {}).get("window_hz")


def _within_sweeps(recordings, band_hz):
    """``band_hz`` cut to the part every sweep covers (5 % inside its ends), as `estimate_frf` cuts each sweep's own:
    every estimate then starts at the same bin and the local windows of all levels fall on one grid (a sweep's
    detected ends move a little with level, and a window grid shifted by one bin shares no frequency)."""
    from .excitation import excitation_of

    lo, hi = band_hz
    for r in recordings:
        exc = excitation_of(r)
        if exc.kind == "sweep" and exc.sweep:
            f0, f1 = sorted((exc.sweep["f_start_hz"], exc.sweep["f_end_hz"]))
            lo, hi = max(lo, 1.05 * f0), min(hi, 0.95 * f1)
    return (lo, hi)


def _with_model_error(data, recording, band_hz, width):
    """Attach the local-polynomial model error (degree 2 vs 3 on the same windows) as ``meta['model_error']``."""
    from .lpm import lpm

    try:
        e2 = lpm(recording, band_hz=band_hz, width_hz=width, degree=2)
        e3 = lpm(recording, band_hz=band_hz, width_hz=width, degree=3)
    except Exception:  # noqa: BLE001 - too few bins for degree 3: no model-error estimate
        return data
    if e2.freq_hz.shape != e3.freq_hz.shape or not np.allclose(e2.freq_hz, e3.freq_hz):
        return data
    # the difference is bias + noise (nested fits: its noise variance is var3 - var2); keep what stands out
    err = {c: np.maximum(np.abs(e2.frf[c] - e3.frf[c])
                         - 3.0 * np.sqrt(2.0 * np.maximum(e3.std[c] ** 2 - e2.std[c] ** 2, 0.0)), 0.0) for c in e2.frf}
    j = np.searchsorted(e2.freq_hz, data.freq_hz)
    ok = bool(np.all(j < e2.freq_hz.size)) and np.allclose(e2.freq_hz[np.clip(j, 0, e2.freq_hz.size - 1)],
                                                           data.freq_hz)
    if not ok:
        return data
    return replace(data, meta=dict(data.meta, model_error={c: v[j] for c, v in err.items()}))


def on_common_grid(datas):
    """Restrict FRFData to the frequencies all of them share (to 1e-9 relative); None if they share < 4."""
    freq = datas[0].freq_hz
    keep = np.ones(freq.size, bool)
    for d in datas[1:]:
        j = np.searchsorted(d.freq_hz, freq)
        j = np.clip(j, 0, d.freq_hz.size - 1)
        ok = np.abs(d.freq_hz[j] - freq) <= 1e-9 * np.maximum(freq, 1.0)
        keep &= ok
    if keep.sum() < 4:
        return None
    f_keep = freq[keep]
    return f_keep, [_take(d, f_keep) for d in datas]


def _take(d, freqs):
    """FRFData rows at the given frequencies."""
    j = np.searchsorted(d.freq_hz, freqs)
    meta = dict(d.meta)
    if isinstance(meta.get("model_error"), dict):
        meta["model_error"] = {c: v[j] for c, v in meta["model_error"].items()}
    return replace(d.take(j), meta=meta)


#: Records whose force RMS differ by more than this factor are levels, not repeats of one test (a ground
#: vibration test steps its level by √2 or more; repeats at one setting agree within a few per cent).
REPEAT_LEVEL_FACTOR = 1.2


def one_test(recordings, **options):
    """One FRF from the files of one test: hits saved one per file, or periodic realisations, or repeats.

    Impact files of one test are joined and give H1 over every hit (`repeated_hits`); other files are
    estimated one by one with the same ``options`` and pooled on their shared lines (`pooled`: three or
    more periodic realisations give the best linear approximation, its std from their spread).

    Parameters
    ----------
    recordings : list of Recording with a ``force`` channel, one sample rate and one set of channels.
    **options : `satmd.signal.estimate_frf`'s keywords, the same for every file.

    Returns
    -------
    FRFData
        With ``estimator["pooled_records"]`` (or the hits over every file) saying what was combined.

    Raises
    ------
    DataError
        Files that are not one test: other channels or sample rates, a file without force, impact files
        at different heights, or records whose force levels differ by more than `REPEAT_LEVEL_FACTOR`
        (levels of one structure are compared by `satmd.discover`, not averaged).
    """
    from ..errors import DataError
    from ..numerics import force_level
    from .estimate import estimate_frf

    items = list(recordings)
    names = [str(r.meta.get("source", f"recording {i + 1}")) for i, r in enumerate(items)]
    for name, r in zip(names, items):
        if not is_forced_recording(r):
            raise DataError(f"{name}: no force channel; one FRF from several files needs the force in each")
    if len(items) == 1:
        return estimate_frf(items[0], **options)
    first = items[0]
    for name, r in zip(names[1:], items[1:]):
        if sorted(r.channels) != sorted(first.channels):
            raise DataError(f"{name}: channels {', '.join(sorted(r.channels))} differ from {names[0]}'s "
                            f"({', '.join(sorted(first.channels))}): not one test")
        if r.fs_hz != first.fs_hz:
            raise DataError(f"{name}: sampled at {r.fs_hz:g} Hz, {names[0]} at {first.fs_hz:g} Hz: not one test")
    joined = repeated_hits(items)
    if joined is not None:
        data = estimate_frf(joined, **options)
        return replace(data, estimator=dict(data.estimator, pooled_records=len(items)))
    levels = [force_level(r["force"]) for r in items]
    if max(levels) > REPEAT_LEVEL_FACTOR * min(levels):
        spread = ", ".join(f"{n} {v:.3g}" for n, v in zip(names, levels))
        raise DataError(f"the files' force levels differ by more than {REPEAT_LEVEL_FACTOR:g}x (RMS: {spread}): "
                        "they are levels, not repeats of one test; one FRF would average different linear "
                        "approximations (judge the levels with `satmd discover FILE...`)")
    datas = [estimate_frf(r, **options) for r in items]
    grid = on_common_grid(datas)
    if grid is None:
        raise DataError("the files' FRFs share fewer than 4 frequencies (other lengths or bands): give records "
                        "of one length and one band")
    return pooled(grid[1])

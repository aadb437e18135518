"""The FRF of every response channel of a recording over its force (`estimate_frfs`): a structure's, with as
many accelerometers as its test had.

Each channel is estimated as `estimate_frf` estimates a rig's acc1 and acc2 (two channels a call, the
excitation detected once a call and the same each time: the same force), so every estimator, its settings and
its measurement-chain findings hold for each; the channels' FRFs share the force's frequency grid.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..errors import DataError
from ..io.channelfrfs import ChannelFRFs
from ..io.recording import Recording


def response_channels(recording: Recording) -> list:
    """Every channel of ``recording`` but its force, in its order."""
    return [c for c in recording.channels if c != "force"]


def estimate_frfs(recording, channels=None, **settings) -> ChannelFRFs:
    """The FRF of each response channel over the force, with its std and coherence.

    Parameters
    ----------
    recording : a Recording with a ``force`` channel and one or more responses, or a list of the files of one
        test (`several.one_test`: hits one per file, periodic realisations, repeats at one level)
    channels : the responses to estimate (default: every channel but the force)
    **settings : `estimate_frf`'s options (estimator, width_hz, excitation, period_s, band_hz, Welch's)

    Returns
    -------
    ChannelFRFs

    Raises
    ------
    DataError
        No force, a channel that is not in the recording, or channels whose estimates fall on different grids.
    """
    from .estimate import estimate_frf
    from .several import one_test

    files = list(recording) if isinstance(recording, (list, tuple)) else [recording]
    recording = files[0]
    source = " + ".join(str(r.meta.get("source", "the recording")) for r in files)
    for r in files[1:]:
        if set(r.channels) != set(recording.channels):
            raise DataError(f"{r.meta.get('source', 'a file')}: channels {', '.join(r.channels)}, not those of "
                            f"{recording.meta.get('source', 'the first file')} ({', '.join(recording.channels)})")
    if "force" not in recording.channels:
        raise DataError(f"{source}: no force channel (channels: {', '.join(recording.channels)}); an FRF is a "
                        "response over the force")
    names = response_channels(recording) if channels is None else list(channels)
    missing = [c for c in names if c not in recording.channels or c == "force"]
    if missing or not names:
        raise DataError(f"{source}: no response channel {', '.join(map(repr, missing)) or 'given'} (responses: "
                        f"{', '.join(response_channels(recording)) or 'none'})")
    rows: dict = {}
    grid, estimator, seen = None, {}, set()
    for pair in (names[i:i + 2] for i in range(0, len(names), 2)):
        rigs = [_as_rig(r, pair) for r in files]
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            data = estimate_frf(rigs[0], **settings) if len(rigs) == 1 else one_test(rigs, **settings)
        for w in caught:  # each pair's estimate warns of the same force: said once
            if str(w.message) not in seen:
                seen.add(str(w.message))
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        if grid is None:
            grid, estimator = data.freq_hz, dict(data.estimator)
        elif data.freq_hz.shape != grid.shape or not np.allclose(data.freq_hz, grid, rtol=1e-12, atol=0):
            raise DataError(f"{source}: {', '.join(pair)} estimated on another frequency grid than "
                            f"{names[0]} ({data.freq_hz.size} points against {grid.size})")
        for k, c in enumerate(pair):
            a = f"a{k + 1}"
            rows[c] = (data.channels[a], data.std.get(a, np.zeros(grid.size)),
                       data.coherence.get(a, np.ones(grid.size)))
    unit = recording.units.get(names[0]) or "m/s^2"
    assert grid is not None  # one pair at least: ``names`` is not empty
    return ChannelFRFs(grid, tuple(names), np.array([rows[c][0] for c in names]),
                       np.array([rows[c][1] for c in names]), np.array([rows[c][2] for c in names]),
                       f"{unit}/{recording.units.get('force', 'N')}", estimator, str(source))


def _as_rig(recording: Recording, pair) -> Recording:
    """``recording``'s force and the channels ``pair`` as a rig's acc1 (and acc2)."""
    channels = {"force": recording.channels["force"]}
    channels.update({f"acc{k + 1}": recording.channels[c] for k, c in enumerate(pair)})
    units = {f"acc{k + 1}": recording.units.get(c) or "m/s^2" for k, c in enumerate(pair)}
    units["force"] = recording.units.get("force", "N")
    return Recording(recording.fs_hz, channels, units, dict(recording.meta))


__all__ = ["estimate_frfs", "response_channels"]

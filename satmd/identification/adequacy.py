"""Can the SATMD model describe these data at all? A verdict with its evidence, before any physics is named.

A fit that reproduces less than half of the data (relative FRF error ≥ 0.5), or
that needs a parameter at an absurd value pinned on its bound, is no fit: no
missing-physics effect of a plausible size changes an FRF by that much, and a
χ² "within the noise" at 100 % relative error only says the noise hides
everything. When the fit fails that way the data are read again as the
usual mistakes would have left them, and a reading that the model fits far
better names the mistake:

- ``sign_convention``: conjugated data (the e^{-iωt} convention; satmd uses e^{+iωt}, SPEC §1);
- ``units``: accelerations in g or mm/s², or displacement or velocity instead of acceleration;
- ``db_phase``: magnitude in dB and phase in the real/imaginary columns;
- ``channel``: one channel a copy of another, or one the model cannot follow while the rest fits;
- ``noise_like``: the data have no smooth structure along frequency at all;
- ``poor_fit`` / ``implausible``: another structure (the model reproduces little; parameters at absurd values).

`assess_fit` gives the verdict of one fit; `satmd.discovery` adds what its search
finds (effects at the edge of their own search range, structure left after the
best augmented fit).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..numerics import lag1_autocorrelation
from .problem import SEARCH_RANGES, Problem
from .statistics import POOR_REL_ERROR, beyond_noise

SCREEN_REL_ERROR = 0.6  # a reading (or a channel subset) is refitted only when a coarse design comes this near
SCREEN_POINTS, SCREEN_DESIGN_LOG2 = 256, 10  # the screen's frequencies and design size (2^10 rigs)
SCALE_SLACK = 10.0  # a reading is fitted only when it brings the data within this factor of the model's size
GOOD_REL_ERROR = 0.1  # an alternative reading must reproduce the data at least this well ...
MUCH_BETTER = 0.2  # ... and cut the relative error to below this share of the data as given
NOISE_LAG1 = 0.3  # data whose lag-1 autocorrelation along frequency stays below this are noise-like
G = 9.80665

# (kind, what the data are, how to fix them, factor on the data that gives accelerance, or None)
_UNITS = (
    ("units", "accelerations in g (per N)", "multiply by 9.80665 to get m/s²/N", lambda w: G),
    ("units", "accelerations in mm/s² (per N)", "divide by 1000 to get m/s²/N", lambda w: 1e-3),
    ("units", "displacements (m/N), not accelerations", "multiply by −ω² to get accelerance", lambda w: -w**2),
    ("units", "velocities (m/s/N), not accelerations", "multiply by iω to get accelerance", lambda w: 1j * w),
)


@dataclass(frozen=True)
class Reason:
    """One piece of evidence about the model's adequacy.

    Parameters
    ----------
    kind : ``poor_fit``, ``implausible``, ``sign_convention``, ``units``, ``db_phase``, ``channel``,
        ``noise_like``, ``effect_at_bound`` or ``structure_left``.
    message : the evidence in one plain sentence, with its numbers.
    evidence : the numbers themselves (JSON-ready).
    """

    kind: str
    message: str
    evidence: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON entry: kind, message, evidence."""
        return {"kind": self.kind, "message": self.message, "evidence": dict(self.evidence)}


# the most specific reason names the mistake: a reading of the data that fits beats "another structure"
_PRIORITY = ("sign_convention", "units", "db_phase", "channel", "noise_like", "effect_at_bound", "implausible",
             "structure_left", "poor_fit")


@dataclass(frozen=True)
class Adequacy:
    """Whether the SATMD model (with any vocabulary effects) can describe the data.

    Parameters
    ----------
    adequate : False when the evidence says the model cannot describe the data.
    reasons : the evidence (empty when adequate).
    """

    adequate: bool
    reasons: tuple = ()

    @property
    def summary(self) -> str:
        """One sentence: what is wrong, from the most specific reason (empty when adequate)."""
        if self.adequate or not self.reasons:
            return ""
        best = min(self.reasons, key=lambda r: _PRIORITY.index(r.kind) if r.kind in _PRIORITY else 99)
        return best.message

    def to_dict(self) -> dict:
        """The SPEC §9 keys: ``model_adequate`` and ``adequacy_reasons``."""
        return {"model_adequate": bool(self.adequate), "adequacy_reasons": [r.to_dict() for r in self.reasons]}

    def report(self) -> str:
        """Plain text: the verdict, then one line per reason."""
        if self.adequate:
            return "model adequate: the SATMD model can describe these data"
        lines = [f"MODEL NOT ADEQUATE: {self.summary}"]
        lines += [f"    - {r.kind}: {r.message}" for r in self.reasons if r.message != self.summary]  # the others
        return "\n".join(lines)

    def __str__(self):
        return self.report()

    def adding(self, reasons) -> "Adequacy":
        """This verdict with more evidence against the model (inadequate when any is given)."""
        reasons = tuple(reasons)
        if not reasons:
            return self
        return Adequacy(False, self.reasons + reasons)


def assess_fit(fit, readings: bool = True, refit=None) -> Adequacy:
    """The adequacy verdict of one fit (see the module docstring).

    Parameters
    ----------
    fit : FitResult
        A fit of the SATMD model (with any effects) by `satmd.identify`.
    readings : when the fit fails, refit the data read as the usual mistakes would leave them,
        to name the mistake (a few extra global fits, only for a failed fit).
    refit : the fitting function (`satmd.identify`, which hands itself in: no import cycle);
        None: no readings.

    Returns
    -------
    Adequacy
    """
    copied = copied_channel(fit.data.select(fit.channels))
    if copied is not None:  # certain whatever the fit: two sensors cannot give the same numbers to 1e-9
        return Adequacy(False, (copied,))
    reasons = []
    rel = rel_error_beyond_noise(fit)
    absurd = implausible_reason(fit, "the fit", ": another structure, or data in other units")
    if absurd:
        reasons.append(absurd)
    if rel >= POOR_REL_ERROR or not np.isfinite(rel):
        reasons.append(Reason("poor_fit", f"the best SATMD fit reproduces little of the data (relative FRF error "
                              f"{rel:.3g}{_beyond(fit, rel)}, χ²_red {fit.chi2_reduced:.3g}): not a SATMD rig as "
                              "measured", {"rel_error": rel, "chi2_reduced": float(fit.chi2_reduced)}))
    if not reasons:
        return Adequacy(True)
    if readings and refit is not None:
        reasons = _explain_failure(fit, float(fit.rel_error), refit) + reasons  # readings compare plain errors
    return Adequacy(False, tuple(reasons))


def rel_error_beyond_noise(fit) -> float:
    """The relative FRF error of ``fit`` on what the data carry above their own noise.

    A noisy measurement of a SATMD rig has a large plain relative error even for the true model. With the
    std the data carry (a file's std columns, an estimate's), powers are counted in units of each point's
    noise, so that a few points of huge scatter (a band edge the force hardly reaches) weigh no more than
    their information, and the noise's expected share, 2 per point and channel, is taken out of the
    residual's and the data's: sqrt(max(χ² − 2n, 0) / (Σ|d/σ|² − 2n)); the smaller of that and the plain
    relative error counts (noise only ever excuses a misfit). Data without a std, or with less signal than
    noise (Σ|d/σ|² < 4n: nothing measured above the noise), keep the plain relative error
    (`FitResult.rel_error`).
    """
    rel = float(fit.rel_error)
    if not getattr(fit, "weighted", False) or not np.isfinite(rel):  # no std: nothing to take out
        return rel
    sigma, res = fit.sigma, fit.residuals()
    n = 2 * sum(np.size(res[c]) for c in fit.channels)
    chi2 = sum(float(np.sum(np.abs(res[c] / sigma[c]) ** 2)) for c in fit.channels)
    power = sum(float(np.sum(np.abs(fit.data[c] / sigma[c]) ** 2)) for c in fit.channels)
    return beyond_noise(rel, chi2, n, power)


def _beyond(fit, rel) -> str:
    """', X on the signal above the noise' when the plain relative error says otherwise."""
    plain = float(fit.rel_error)
    return "" if plain == rel else f" on what the data carry above their noise; {plain:.3g} with the noise"


def implausible_reason(fit, who: str, tail: str = "") -> Reason | None:
    """An ``implausible`` `Reason` naming the parameters of ``fit`` at absurd values ("{who} needs ...{tail}"),
    with their values as evidence; None when every value is plausible."""
    absurd = implausible_values(fit)
    if not absurd:
        return None
    return Reason("implausible", f"{who} needs " + "; ".join(absurd.values()) + tail,
                  {"parameters": {n: float(fit.values[n]) for n in sorted(absurd)}})


def implausible_values(fit) -> dict:
    """Rig parameters far outside their plausible range (a factor 3 beyond the global search's box, or
    pinned on a bound there): {name: 'm2 = 50 on its bound (plausible 0.25–0.9)'}."""
    out = {}
    for n, v in fit.values.items():
        if n in SEARCH_RANGES:
            lo, hi = SEARCH_RANGES[n]
            if not lo / 3 <= v <= hi * 3:
                where = " on its bound" if n in fit.pinned else ""
                out[n] = f"{n} = {v:.4g}{where} (plausible {lo:g}–{hi:g})"
    return out


def copied_channel(data) -> Reason | None:
    """A ``channel`` reason when one channel is a copy of another (to 1e-9 relative): one sensor is missing
    or mislabelled, whatever a fit makes of it; None otherwise."""
    names = list(data.names)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if np.allclose(data[a], data[b], rtol=1e-9, atol=0):
                return Reason("channel", f"channel {b} is a copy of channel {a}: one sensor is missing or "
                                         "mislabelled", {"channels": [a, b]})
    return None


def _refit(identify, fit, data, channels=None):
    p = fit._problem  # noqa: SLF001 - same package: the fitted problem's rig, free names and effects
    chans = tuple(channels or p.channels)
    try:
        return identify(data, p.rig, p.names, chans, p.effects, n_search=1024, n_refine=2, max_nfev=200, warn=False)
    except Exception:  # a reading that cannot be fitted at all is simply no better
        return None


def _explain_failure(fit, rel, identify) -> list:
    """Readings of the data that the model fits far better, and channel / noise evidence."""
    data = fit.data.select(fit.channels)
    out = []
    names = list(data.names)
    # noise has neither smooth parts nor a smooth magnitude (a long delay turns a smooth FRF's phase fast,
    # so its parts alone may look rough while its magnitude stays smooth)
    lag = {c: max(_lag1(data[c].real, data[c].imag), _lag1(np.abs(data[c]))) for c in names}
    if len(data) > 8 and all(v < NOISE_LAG1 for v in lag.values()):
        out.append(Reason("noise_like", "the data are noise-like, with no smooth structure along frequency "
                                        f"(lag-1 autocorrelation {max(lag.values()):.2f}; an FRF gives near 1): "
                                        "no model of a structure can describe them",
                          {"lag1": {c: float(v) for c, v in lag.items()}}))
        return out
    typical = _typical_magnitude(fit, data)
    for kind, label, fix, data_alt in _readings(data):
        size = np.median(np.concatenate([np.abs(data_alt[c]) for c in data_alt.names]))
        if not typical / SCALE_SLACK < size < typical * SCALE_SLACK:
            continue  # read so the data are still nowhere near the model's size: no need to fit
        if _design_rel(fit, data_alt) > SCREEN_REL_ERROR:
            continue  # no point of a coarse design over the plausible rigs comes near: not this reading
        alt = _refit(identify, fit, data_alt)
        if _explains(alt) and alt.rel_error < MUCH_BETTER * rel:
            out.append(Reason(kind, f"the data look like {label}: read so, the SATMD model fits them with relative "
                                    f"error {alt.rel_error:.3g} instead of {rel:.3g} ({fix})",
                              {"rel_error_as_given": rel, "rel_error_as_read": float(alt.rel_error),
                               "reading": label}))
            return out  # the first reading that fits names the mistake
    if len(names) > 1:
        for c in names:
            rest = [n for n in names if n != c]
            if _design_rel(fit, data.select(rest), rest) > SCREEN_REL_ERROR:
                continue
            alt = _refit(identify, fit, data.select(rest), rest)
            if _explains(alt):
                out.append(Reason("channel", f"without channel {c} the SATMD model fits the rest (relative error "
                                             f"{alt.rel_error:.3g} instead of {rel:.3g}): {c} is not what the "
                                             "model calls it (a disconnected, missing or mislabelled sensor)",
                                  {"channel": c, "rel_error_without": float(alt.rel_error)}))
                return out
    return out


def _explains(alt) -> bool:
    """A refit names the mistake only when it reproduces the data well with plausible values: a rig
    still needing an absurd parameter is no better explained without a channel or read otherwise."""
    return alt is not None and alt.rel_error < GOOD_REL_ERROR and not implausible_values(alt)


def _lag1(*parts) -> float:
    """Pooled lag-1 autocorrelation along frequency of real series, each about its mean."""
    return lag1_autocorrelation(np.stack([p - p.mean() for p in parts]))


def _design_rel(fit, data, channels=None) -> float:
    """Smallest relative error over a coarse Sobol design of the plausible rigs (one batched model call):
    a cheap screen before a full refit."""
    from scipy.stats import qmc

    p = fit._problem  # noqa: SLF001 - same package
    try:
        prob = Problem(data, p.rig, p.names, tuple(channels or p.channels), p.effects).thinned(SCREEN_POINTS)
    except Exception:  # data this reading cannot even pose as a problem
        return np.inf
    idx = [i for i, n in enumerate(prob.names) if n in SEARCH_RANGES]
    base = prob.values()
    if not idx:
        thetas = base[None, :]
    else:
        lo = np.log([SEARCH_RANGES[prob.names[i]][0] for i in idx])
        hi = np.log([SEARCH_RANGES[prob.names[i]][1] for i in idx])
        u = qmc.Sobol(len(idx), scramble=True, seed=0).random_base2(SCREEN_DESIGN_LOG2)
        thetas = np.repeat(base[None, :], u.shape[0], axis=0)
        thetas[:, idx] = np.exp(lo + u * (hi - lo))
    power = float(np.sum(np.abs(prob.target / prob.sigma) ** 2))
    return float(np.sqrt(np.nanmin(prob.batch_cost(thetas)) / power)) if power > 0 else np.inf


def _typical_magnitude(fit, data) -> float:
    """Median |FRF| of the model at its given (not fitted) rig on the data grid: the size data should have."""
    from ..physics import frf

    p = fit._problem  # noqa: SLF001 - same package
    r = frf(data.freq_hz, p.rig, p.effects, outputs=data.names)
    return float(np.median(np.concatenate([np.abs(r.channel(c)) for c in data.names])))


def _readings(data):
    """(kind, label, fix, data read so) for each usual mistake that applies to these data."""
    from ..io.frfdata import FRFData

    w = 2 * np.pi * data.freq_hz

    def mapped(fn, std_factor=None):
        chans = {c: fn(data[c]) for c in data.names}
        std = {c: s * std_factor for c, s in data.std.items()} if std_factor is not None else {}
        return FRFData(data.freq_hz, chans, std)

    yield ("sign_convention", "the e^{-iωt} convention (conjugated)", "conjugate them: satmd uses e^{+iωt}",
           mapped(np.conj, 1.0))
    for kind, label, fix, factor in _UNITS:
        k = factor(w)
        yield kind, label, fix, mapped(lambda x, k=k: k * x, np.abs(k))
    re = np.concatenate([data[c].real for c in data.names])
    im = np.concatenate([data[c].imag for c in data.names])
    if np.all(np.abs(re) <= 400) and np.all(np.abs(im) <= 180 + 1e-9) and np.abs(im).max() > 0:
        deg = np.abs(im).max() > 2 * np.pi + 1e-9
        unit = "degrees" if deg else "radians"
        rad = np.pi / 180 if deg else 1.0
        yield ("db_phase", f"magnitude in dB and phase in {unit} (in the _re and _im columns)",
               "convert to complex values: 10^(dB/20)·e^{i·phase}",
               mapped(lambda x: 10 ** (x.real / 20) * np.exp(1j * rad * x.imag)))

"""A structure's modes with their shapes over its sensors (`survey`): what a ground vibration test reports first.

Each mode's shape is read from its residues in every channel's FRF (`fit_modes` fits them with one set of
poles). An accelerance residue is ``A = λ² R`` with ``R`` the receptance residue, and for a lightly damped mode
``2 i ω R_o ≈ φ_o φ_d`` (``φ`` mass-normalised, ``d`` the force's point): the receptance modal constants, one per
channel, are the shape times ``φ_d``. Where a channel is the driving point (its constants positive on every
strong mode, as ``φ_d²`` is; or named), the shapes are mass-normalised (units 1/√kg when the FRFs are in
m/s²/N); elsewhere each is scaled to 1 at its largest sensor. A shape is made real by its best rotation; what
stays imaginary is its complexity (1 − |Σ ψ²| / Σ |ψ|²: 0 for a normal mode, up to 1), which a non-proportional
damping, a close mode or a sensor out of phase raises.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import TINY
from ..errors import DataError
from .fit import ModalFit, fit_modes

STRONG = 0.05  # of a channel's largest residue: a mode it sees (the driving point's sign is read on these)


def modal_constants(residues, poles) -> np.ndarray:
    """Each mode's receptance modal constant (φ_a φ_b for a mass-normalised mode) from accelerance residues
    (channels, modes): the receptance residue is A / λ², and its constant ≈ 2 i ω (A / λ²) for light damping."""
    return (2j * np.abs(poles) * np.asarray(residues) / poles ** 2).real


def driving_point_candidates(channels, residues, poles) -> list:
    """The channels that may be at the force's point: those whose modal constants (`modal_constants`) are positive
    on every mode they see (`STRONG`), as ``φ_d²`` is. With few modes in the band several sensors pass (all in phase
    with the force on each), and none where a mode's sign is off (a delay, a sensor mounted the other way)."""
    if len(poles) == 0:
        return []
    const = modal_constants(residues, poles)
    size = np.abs(np.asarray(residues))
    strong = size > STRONG * np.maximum(size.max(axis=1, keepdims=True), TINY)
    return [c for c, k, s in zip(channels, const, strong) if np.all(k[s] > 0)]


def driving_point_of(channels, residues, poles, weak_too: bool = False):
    """The channel at the force's point, found: the one whose modal constants (`modal_constants`) are positive on
    every mode it sees (`STRONG`), as ``φ_d²`` is; None when no channel, or more than one, has that. ``weak_too``:
    where several pass (sensors near one another, in phase on every strong mode), the one positive on every mode,
    weak ones too, where one alone is."""
    found = driving_point_candidates(channels, residues, poles)
    if len(found) > 1 and weak_too:
        const = modal_constants(residues, poles)
        found = [c for c, k in zip(channels, const) if c in found and np.all(k > 0)]
    return found[0] if len(found) == 1 else None


@dataclass(frozen=True)
class ModalSurvey:
    """The modes of a structure's FRFs and their shapes over its sensors.

    Attributes
    ----------
    fit : the `ModalFit` (frequencies, damping ratios, their 95 % intervals, residues)
    channels : the sensors, in the order of the shapes' columns
    shapes : (modes, channels) real shapes, mass-normalised (``normalised == "mass"``) or 1 at the largest
    complexity : (modes,) 0 for a real (normal) mode, up to 1
    driving_point : the channel at the force's point (named or found), or None
    normalised : ``"mass"`` or ``"largest"``
    other_sign_hz : the modes where a named driving point's constant has the sign no driving point has (a delay
        or a sign convention in the measurement chain, or not the force's point): their mass scale is doubtful
    """

    fit: ModalFit
    channels: tuple
    shapes: np.ndarray
    complexity: np.ndarray
    driving_point: str | None
    normalised: str
    other_sign_hz: tuple = ()

    def to_dict(self) -> dict:
        """The modes (f, ζ, intervals), each with its shape by channel and its complexity."""
        return {"channels": list(self.channels), "driving_point": self.driving_point, "normalised": self.normalised,
                "other_sign_hz": list(self.other_sign_hz),
                "band_hz": list(self.fit.band_hz), "chi2_reduced": self.fit.chi2_reduced,
                "modes": [{**m.to_dict(), "shape": dict(zip(self.channels, map(float, s))), "complexity": float(c)}
                          for m, s, c in zip(self.fit.modes, self.shapes, self.complexity)]}

    def report(self) -> str:
        """A table: each mode's frequency and damping with their intervals, its shape and its complexity."""
        how = (f"mass-normalised through the driving point {self.driving_point}" if self.normalised == "mass" else
               "each 1 at its largest sensor (no sensor alone has positive modal constants on every mode: name the "
               "driving point for a mass scale)")
        f_text = [f"{m.f_hz:.4g} [{m.f_ci95[0]:.4g}, {m.f_ci95[1]:.4g}]" for m in self.fit.modes]
        z_text = [f"{100 * m.zeta:.3g} [{100 * m.zeta_ci95[0]:.2g}, {100 * m.zeta_ci95[1]:.2g}]" for m in self.fit.modes]
        wf, wz = max(map(len, f_text + ["f [Hz]"])), max(map(len, z_text + ["ζ [%]"]))
        odd = (f"; {self.driving_point}'s modal constants have the other sign at "
               f"{', '.join(f'{f:.4g}' for f in self.other_sign_hz)} Hz (a delay or a sign convention in the chain, or "
               "not the force's point): their mass scale is doubtful" if self.other_sign_hz else "")
        lines = [f"{len(self.fit.modes)} modes {self.fit.band_hz[0]:.4g}–{self.fit.band_hz[1]:.4g} Hz over "
                 f"{len(self.channels)} sensors; shapes {how}{odd}",
                 f"{'f [Hz]':<{wf}s}  {'ζ [%]':<{wz}s}  " + " ".join(f"{c:>8s}" for c in self.channels)
                 + "  complexity"]
        for ft, zt, s, c in zip(f_text, z_text, self.shapes, self.complexity):
            lines.append(f"{ft:<{wf}s}  {zt:<{wz}s}  " + " ".join(f"{v:8.3g}" for v in s) + f"  {c:10.2f}")
        return "\n".join(lines)


def survey(freq_hz, frf: dict, std: dict | None = None, band_hz=None, driving_point: str | None = None,
           **fit_options) -> ModalSurvey:
    """The modes of FRFs of several sensors over one force, and their shapes.

    Parameters
    ----------
    freq_hz : (M,) Hz, increasing
    frf : {channel: (M,) complex accelerance}, every channel over the same force
    std : {channel: (M,) std of the real and imaginary parts}, or None
    band_hz : (lo, hi) Hz to fit (default: all of ``freq_hz``)
    driving_point : the channel at the force's point (default: found from the residues' signs, `driving_point_of`;
        where several sensors pass, the one whose constants are positive on every mode, weak ones too)
    **fit_options : `fit_modes`' n_modes, max_order

    Returns
    -------
    ModalSurvey

    Raises
    ------
    DataError
        A driving point that is not a channel. One named whose constants are not all positive is taken at its
        word, and the modes where they are not are said (``other_sign_hz``).
    """
    names = tuple(frf)
    if driving_point is not None and driving_point not in names:
        raise DataError(f"the driving point {driving_point!r} is not a channel ({', '.join(names)})")
    fit = fit_modes(freq_hz, frf, std, band_hz, **fit_options)
    if not fit.modes:
        return ModalSurvey(fit, names, np.zeros((0, len(names))), np.zeros(0), driving_point, "largest")
    poles = np.array([m.pole for m in fit.modes])
    residues = np.array([[m.residues[c] for m in fit.modes] for c in names])  # (channels, modes)
    receptance = 2j * np.abs(poles) * residues / poles ** 2  # ≈ φ_o φ_d, complex where the mode is
    found = driving_point_of(names, residues, poles, weak_too=True)
    odd: tuple = ()
    if driving_point is not None:  # the user's word, with the modes whose sign disagrees said
        odd = tuple(m.f_hz for m, k in zip(fit.modes, receptance[names.index(driving_point)].real) if k <= 0)
    point = driving_point or found
    turn = np.exp(-0.5j * np.angle(np.sum(receptance ** 2, axis=0)))  # the rotation that makes each mode most real
    real = (receptance * turn).real.T  # (modes, channels)
    power = np.maximum(np.sum(np.abs(receptance) ** 2, axis=0), TINY)
    complexity = 1.0 - np.abs(np.sum(receptance ** 2, axis=0)) / power
    if point is not None:
        d = names.index(point)
        real = real * np.sign(real[:, d:d + 1] + TINY)
        shapes = real / np.sqrt(np.maximum(real[:, d:d + 1], TINY))  # φ_o = (φ_o φ_d) / φ_d
        return ModalSurvey(fit, names, shapes, complexity, point, "mass", odd)
    largest = np.take_along_axis(real, np.argmax(np.abs(real), axis=1)[:, None], axis=1)
    return ModalSurvey(fit, names, real / largest, complexity, None, "largest")


__all__ = ["ModalSurvey", "survey", "modal_constants", "driving_point_candidates", "driving_point_of"]

"""`Prediction`: a structure model's simulation of one recording against what was measured (SPEC §11)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

PREDICTION_SCHEMA = "satmd-prediction/1"


@dataclass(frozen=True)
class Prediction:
    """A model's simulation of one recording: NRMSE per channel, nonlinear and linear (SPEC §11).

    ``signals`` holds the measured, linear and nonlinear responses {channel: (3, N)} for figures. A simulation
    with the joint that ran away (the model is not stable at this level: no finite force, or a response a
    million times the measured one, `RAN_AWAY`) has NRMSE inf. ``above_band`` splits the NRMSE by frequency
    (`bands`): the error above the force's band (``band_top_hz``) and the measured response there, per channel,
    each over the channel's RMS: a model that predicts no harmonics misses by the second at least."""

    file: str
    level: float
    extrapolated: bool
    channels: tuple
    nrmse: list
    linear_nrmse: list
    fs_hz: float = 0.0
    signals: dict = field(default_factory=dict, repr=False)
    band_top_hz: float = 0.0
    above_band: dict = field(default_factory=dict)  # {"nrmse": [...], "measured": [...]}
    fitted_band_hz: tuple | None = None  # the band the model's recordings excited (`StructureModel.band_hz`)
    outside_band: float | None = None  # the share of this force's power outside it: there the model extrapolates
    joint_reach: float | None = None  # the joint's largest force here over the largest in the fitted recordings
    realisations: int = 1  # a lab's realisations in one file, each simulated from its own start
    going_on: int = 0  # of them, those simulated going on from the one before (`StructureModel.predict`)

    def to_dict(self) -> dict:
        out = {"file": self.file, "level": round(self.level, 6), "extrapolated": self.extrapolated,
               "channels": list(self.channels), "nrmse": [round(x, 4) for x in self.nrmse],
               "linear_nrmse": [round(x, 4) for x in self.linear_nrmse]}
        if self.above_band:
            out["band_top_hz"] = round(self.band_top_hz, 3)
            out["above_band"] = {k: [round(x, 4) for x in v] for k, v in self.above_band.items()}
        if self.outside_band is not None and self.fitted_band_hz is not None:
            out["fitted_band_hz"] = [round(float(x), 3) for x in self.fitted_band_hz]
            out["force_outside_fitted_band"] = round(self.outside_band, 4)
        if self.joint_reach is not None:
            out["joint_force_over_fitted"] = round(self.joint_reach, 4)
        if self.realisations > 1:
            out["realisations"], out["realisations_going_on"] = self.realisations, self.going_on
        return out

    def plot(self, path, title: str = ""):
        """Measured, linear and nonlinear responses, time and spectrum (`figures.prediction_figure`)."""
        from .figures import prediction_figure

        return prediction_figure(self, path, title)

    def report(self) -> str:
        flag = " (extrapolated: outside the fitted levels)" if self.extrapolated else ""
        rows = ", ".join(f"{c} {n:.3f} (linear {ln:.3f})" for c, n, ln in zip(self.channels, self.nrmse, self.linear_nrmse))
        several = (f" over {self.realisations} realisations ({self.going_on} going on from the one before, the "
                   f"others from their start)" if self.realisations > 1 else "")
        text = f"{self.file}: force {self.level:.4g} N RMS{flag}; NRMSE{several} {rows}"
        if self.outside_band is not None and self.fitted_band_hz is not None and self.outside_band >= SHOWN_OUTSIDE:
            lo, hi = self.fitted_band_hz
            text += (f"; {100 * self.outside_band:.0f} % of the force's power lies outside the band the model was "
                     f"fitted in ({lo:.3g}–{hi:.3g} Hz): there it extrapolates, with no mode it was not shown")
        if self.joint_reach is not None and self.joint_reach > SHOWN_REACH:
            text += (f"; the joint's force reaches {self.joint_reach:.2f} times the largest it had in the fitted "
                     "recordings: its law is extrapolated there")
        if not all(np.isfinite(self.nrmse)):
            text += "; the simulation ran away: the model is not stable at this level"
        there = self.above_band.get("measured", [])
        if there and max(there) >= SHOWN_ABOVE:
            text += (f"; above the force's band ({self.band_top_hz:.4g} Hz) the measured response is "
                     + ", ".join(f"{x:.3f}" for x in there) + " of each channel's RMS, of which the model misses "
                     + ", ".join(f"{x:.3f}" for x in self.above_band["nrmse"]))
        return text


SHOWN_ABOVE = 0.05  # a share of the response above the force's band worth a line of the report
SHOWN_OUTSIDE = 0.05  # a share of the force's power outside the fitted band worth a line of the report
SHOWN_REACH = 1.1  # the joint's force beyond the fitted recordings' largest by this factor is said


def nrmse(simulated, measured) -> float:
    """RMS of the simulation's error over the RMS of the measured output (about its mean)."""
    m = np.asarray(measured, float)
    scale = float(np.sqrt(np.mean((m - m.mean()) ** 2))) or 1.0
    return float(np.sqrt(np.mean((np.asarray(simulated, float) - m) ** 2)) / scale)


RAN_AWAY = 1e6  # an NRMSE beyond it is a simulation that grew without bound within the record, not a prediction


def finite_nrmse(simulated, measured) -> float:
    """`nrmse`, inf where the simulation ran away (not finite, or beyond `RAN_AWAY`)."""
    value = nrmse(simulated, measured)
    return value if np.isfinite(value) and value < RAN_AWAY else float("inf")

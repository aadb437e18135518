"""Frequency-wise neural attribution (paper eq. 26, SPEC §6) and the Table 3 statistics.

For each FRF and each normalised output (r̂, l̂ of eq. 19-20) the gradient
with respect to the network's input features is taken by automatic
differentiation. Choice documented here: the derivative is with respect to the
**raw** spectral features ``X = [Re A1, Re A2, Im A1, Im A2]`` (m/s²/N),
chained through the model's per-feature standardisation, so that the
attribution answers "how much does the prediction move when the measured FRF
moves" and can be compared with the physical derivatives ∂A/∂R, ∂A/∂L in the
same units (`satmd.explain.sensitivity`). ``space="scaled"`` gives the
alternative: gradients with respect to the standardised network inputs (the
raw gradients times each feature's training std), which weights frequencies
by how much the features vary over the training set.

Per frequency f_j the four absolute gradients (Re/Im of both channels) are
summed, ``S(f_j) = Σ |∂ŷ/∂X_c(f_j)|``, and each curve is divided by its
maximum, so every curve peaks at 1.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import DataError
from . import contract

OUTPUTS = ("R", "L")
#: The six blind (R [Ω], L [H]) pairs of the paper (SPEC §5), the cases of Figures 5-8.
BLIND_CASES = ((8.0, 0.032), (10.0, 0.050), (22.0, 0.064), (25.0, 0.100), (35.0, 0.192), (60.0, 0.300))

#: The paper's Table 3 (normalised sensitivity statistics over the six blind cases).
PAPER_TABLE3 = {
    "R": {"mean": 0.305312, "std": 0.184042, "mean_case_std": 0.066548, "max_case_std": 0.236613},
    "L": {"mean": 0.341507, "std": 0.179760, "mean_case_std": 0.074551, "max_case_std": 0.257595},
}
#: Where the paper finds the peaks of the sensitivity curves (Hz).
PAPER_PEAK_BANDS_HZ = ((50.0, 52.0), (103.0, 110.0))
PEAK_BAND_TOLERANCE_HZ = 3.0  # a peak this close to a paper band counts as inside (one grid step is 1.5 Hz)
TABLE3_LABELS = {
    "mean": "Mean normalized sensitivity",
    "std": "Standard deviation of normalized sensitivity",
    "mean_case_std": "Mean across-case standard deviation",
    "max_case_std": "Maximum across-case standard deviation",
}


def per_frequency(values: np.ndarray, n_freq: int) -> np.ndarray:
    """(..., 4F) values over raw features -> (..., F): sum of |value| over Re/Im of both channels."""
    v = np.abs(np.asarray(values, float))
    return v.reshape(v.shape[:-1] + (4, n_freq)).sum(axis=-2)


def normalise_max(curves: np.ndarray) -> np.ndarray:
    """Divide each curve (last axis) by its maximum (curves that are all zero stay zero)."""
    c = np.asarray(curves, float)
    peak = c.max(axis=-1, keepdims=True)
    return np.divide(c, peak, out=np.zeros_like(c), where=peak > 0)


@dataclass(frozen=True)
class Attribution:
    """Neural attribution for n FRFs.

    Attributes
    ----------
    freq_hz : (F,)
    curves : (n, 2, F) normalised S_R(f), S_L(f) (each curve max 1)
    gradients : (n, 2, 4F) raw gradients ∂(r̂, l̂)/∂X (normalised outputs, raw features)
    prediction : (n, 2) R̂, L̂ in physical units
    labels : case names
    space : "raw" or "scaled": the features the curves are differentiated against
    """

    freq_hz: np.ndarray
    curves: np.ndarray
    gradients: np.ndarray
    prediction: np.ndarray
    labels: tuple = field(default=())
    space: str = "raw"

    @property
    def S_R(self) -> np.ndarray:
        return self.curves[:, 0]

    @property
    def S_L(self) -> np.ndarray:
        return self.curves[:, 1]

    def table3(self) -> dict:
        """{"R": stats, "L": stats} with the Table 3 statistics and the peak locations."""
        return {name: table3_stats(self.curves[:, k], self.freq_hz) for k, name in enumerate(OUTPUTS)}


def attribution(model, frfs, labels=None, space: str = "raw") -> Attribution:
    """S_R(f), S_L(f) for each FRF (SPEC §6, eq. 26).

    Parameters
    ----------
    model : a trained `satmd.inverse.InverseModel` (net kind) or an object
        following the same contract (`satmd.explain.contract.ExplainableModel`)
    frfs : FRFData or a list of them, a dataset, complex (n, 2, F) or raw
        features (n, 4F) on the model's grid
    labels : optional case names
    space : "raw" (default: ∂/∂X of the raw features, see the module
        docstring) or "scaled" (∂/∂ of the standardised network inputs)

    Returns
    -------
    Attribution
    """
    if space not in ("raw", "scaled"):
        raise DataError(f"space must be 'raw' or 'scaled', got {space!r}")
    torch = contract.torch_module()
    contract.check_net_model(model)
    raw = contract.raw_features(model, frfs)
    X = torch.tensor(raw, dtype=torch.float64, requires_grad=True)
    out = contract.normalised_outputs_raw(model, X)  # (n, 2)
    grads = []
    for k in range(out.shape[1]):
        (g,) = torch.autograd.grad(out[:, k].sum(), X, retain_graph=k + 1 < out.shape[1])
        grads.append(g.detach().numpy())  # rows are independent: the sum gives each row's gradient
    gradients = np.stack(grads, axis=1)  # (n, 2, 4F)
    n_freq = np.size(model.freq_hz)
    g = gradients if space == "raw" else gradients * np.asarray(model.scaler_.scale, float)
    curves = normalise_max(per_frequency(g, n_freq))
    lo = np.array([model.bounds["R"][0], model.bounds["L"][0]])
    prediction = lo + out.detach().double().numpy() * contract.bounds_span(model)
    labels = tuple(labels) if labels is not None else tuple(f"case {i + 1}" for i in range(len(raw)))
    return Attribution(np.asarray(model.freq_hz, float), curves, gradients, prediction, labels, space)


def table3_stats(curves: np.ndarray, freq_hz: np.ndarray) -> dict:
    """The paper's Table 3 statistics for normalised curves (n_cases, F).

    - ``mean`` / ``std``: mean and standard deviation over frequency of the
      case-averaged curve, re-normalised to maximum 1;
    - ``mean_case_std`` / ``max_case_std``: mean and maximum over frequency of
      the across-case standard deviation (population std, ddof = 0);
    - ``peaks_hz``: the two main peaks of the mean curve (`peak_frequencies`).

    Parameters
    ----------
    curves : (n_cases, F) normalised curves.
    freq_hz : (F,) frequencies [Hz].

    Returns
    -------
    dict
        The statistics above.
    """
    c = np.asarray(curves, float)
    mean_curve = normalise_max(c.mean(axis=0))
    case_std = c.std(axis=0)
    return {
        "mean": float(mean_curve.mean()),
        "std": float(mean_curve.std()),
        "mean_case_std": float(case_std.mean()),
        "max_case_std": float(case_std.max()),
        "peaks_hz": peak_frequencies(mean_curve, freq_hz),
    }


def peak_frequencies(curve: np.ndarray, freq_hz: np.ndarray, n: int = 2, min_separation_hz: float = 15.0) -> list:
    """Frequencies of the highest local maxima of a curve (ends of the grid count as maxima).

    Parameters
    ----------
    curve : (F,) values.
    freq_hz : (F,) frequencies [Hz].
    n : how many maxima.
    min_separation_hz : least distance between two reported maxima.

    Returns
    -------
    list of float
        Highest first.
    """
    y = np.asarray(curve, float)
    f = np.asarray(freq_hz, float)
    padded = np.concatenate([[-np.inf], y, [-np.inf]])
    is_max = (padded[1:-1] > padded[:-2]) & (padded[1:-1] >= padded[2:])
    picked: list[float] = []
    for i in np.argsort(-y):
        if not is_max[i]:
            continue
        if all(abs(f[i] - p) >= min_separation_hz for p in picked):
            picked.append(float(f[i]))
        if len(picked) == n:
            break
    return picked


def in_paper_bands(peaks_hz, tolerance_hz: float = PEAK_BAND_TOLERANCE_HZ) -> list:
    """For each paper band, whether some peak falls inside it (± tolerance, one grid step is 1.5 Hz)."""
    return [any(lo - tolerance_hz <= p <= hi + tolerance_hz for p in peaks_hz) for lo, hi in PAPER_PEAK_BANDS_HZ]

"""Training and test data for the amortized inverse (SPEC §5).

Two presets build labelled synthetic acceleration FRFs with the NumPy forward
model (``satmd.physics.frf``; mechanical parameters fixed at the rig's values):

``paper``
    The paper's 30 reference (R, L) pairs, each surrounded by
    ``samples_per_pair`` samples with R jittered uniformly by ±2 Ω and L by
    ±0.010 H (clipped at 0). The train/validation split is *by reference
    pair*: every sample of a validation pair is in the validation set, so no
    neighbourhood leaks across partitions.
``box``
    R and L drawn independently and uniformly over ``BOX_RANGE`` (the
    "independently varying R and L" the paper names as future work). There
    are no reference pairs: every sample is its own group and the split is a
    random share of samples, so validation points sit among training points
    exactly as new points drawn from the box do.

Noise (eq. 23) never touches the stored FRFs: it is added to network
*inputs* only, by :func:`add_input_noise`, with the noise model of
``satmd simulate --noise REL``: on each of Re and Im, a Gaussian of standard
deviation ``REL |A|``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..errors import SatmdError
from ..physics import PAPER_GRID_HZ, Rig, frf

#: The 30 training reference pairs (R [Ω], L [H]) of SPEC §5.
PAPER_PAIRS = np.array([
    (5, .014), (7, .026), (11, .042), (13, .048), (15, .052), (17, .064), (19, .080), (21, .092),
    (23, .108), (26, .116), (27, .124), (30, .148), (34, .168), (36, .184), (40, .200), (44, .212),
    (46, .220), (50, .236), (54, .260), (56, .272), (62, .312), (68, .336), (70, .348), (75, .372),
    (78, .384), (80, .392), (88, .420), (90, .432), (92, .448), (98, .480),
], dtype=float)

#: The six blind pairs of the paper's Table 2 and the paper's predictions (R, L, R_pred, L_pred).
BLIND_PAIRS = np.array([(8.0, 0.032), (10.0, 0.050), (22.0, 0.064), (25.0, 0.100), (35.0, 0.192), (60.0, 0.300)])
PAPER_TABLE2 = np.array([
    (8.0, 0.032, 8.0709, 0.03154),
    (10.0, 0.050, 10.0535, 0.04956),
    (22.0, 0.064, 21.9515, 0.06358),
    (25.0, 0.100, 25.0939, 0.09981),
    (35.0, 0.192, 35.0788, 0.19126),
    (60.0, 0.300, 60.1483, 0.29881),
])
PAPER_TABLE2_MAE = {"R": 0.0823, "L": 0.000572, "R_rel": 0.0041, "L_rel": 0.0066}

#: Pairs well away from the paper's R-L line (for the off-curve check).
OFF_CURVE_PAIRS = np.array([(10.0, 0.30), (90.0, 0.05), (15.0, 0.40), (75.0, 0.10), (50.0, 0.05), (30.0, 0.45)])

#: Output normalisation bounds (eq. 20).
BOUNDS = {"R": (0.0, 103.0), "L": (0.0, 0.5)}
#: Sampling range of the ``box`` preset.
BOX_RANGE = {"R": (3.0, 100.0), "L": (0.01, 0.49)}
PRESETS = ("paper", "box")

JITTER_R = 2.0
JITTER_L = 0.010


@dataclass(frozen=True)
class InverseDataset:
    """Labelled acceleration FRFs: ``a1``, ``a2`` complex (n, n_freq), labels R, L (n,).

    ``group`` is the reference pair (paper) of each sample, or the sample
    itself (box); ``is_val`` marks the validation partition.
    """

    freq_hz: np.ndarray
    R: np.ndarray
    L: np.ndarray
    a1: np.ndarray
    a2: np.ndarray
    group: np.ndarray
    is_val: np.ndarray
    preset: str = "custom"
    info: dict = field(default_factory=dict)

    def __len__(self):
        return self.R.size

    @property
    def train(self) -> "InverseDataset":
        return self.subset(~self.is_val)

    @property
    def val(self) -> "InverseDataset":
        return self.subset(self.is_val)

    def subset(self, mask) -> "InverseDataset":
        mask = np.asarray(mask)
        return InverseDataset(self.freq_hz, self.R[mask], self.L[mask], self.a1[mask], self.a2[mask],
                              self.group[mask], self.is_val[mask], self.preset, dict(self.info))

    def features(self) -> np.ndarray:
        """Raw network features (n, 4 n_freq): [Re A1, Re A2, Im A1, Im A2] (SPEC §1)."""
        return complex_to_features(np.stack([self.a1, self.a2], axis=-2))

    def labels(self) -> np.ndarray:
        """(n, 2) physical labels [R, L]."""
        return np.stack([self.R, self.L], axis=-1)

    def labels_normalised(self, bounds=BOUNDS) -> np.ndarray:
        return normalise(self.labels(), bounds)

    def frfdata(self, i: int, noise: float = 0.0, seed=None):
        """Sample ``i`` as FRFData (with std columns and noise when ``noise`` > 0)."""
        from ..io import FRFData
        from ..simulation.frf import noise_std

        chans = {"a1": self.a1[i], "a2": self.a2[i]}
        if not noise:
            return FRFData(self.freq_hz, chans, {}, {"R": f"{self.R[i]:.12g}", "L": f"{self.L[i]:.12g}"})
        rng = np.random.default_rng(seed)
        std = {c: noise_std(v, noise) for c, v in chans.items()}
        noisy = {c: v + std[c] * (rng.standard_normal(v.shape) + 1j * rng.standard_normal(v.shape))
                 for c, v in chans.items()}
        return FRFData(self.freq_hz, noisy, std, {"R": f"{self.R[i]:.12g}", "L": f"{self.L[i]:.12g}"})


def complex_to_features(a: np.ndarray) -> np.ndarray:
    """(..., 2, F) complex [A1, A2] -> (..., 4F) real [Re A1, Re A2, Im A1, Im A2].

    The same ordering as ``satmd.physics.torch.features``.
    """
    a = np.asarray(a)
    z = a.reshape(a.shape[:-2] + (-1,))
    return np.concatenate([z.real, z.imag], axis=-1)


def features_to_complex(x: np.ndarray) -> np.ndarray:
    """Inverse of :func:`complex_to_features`: (..., 4F) -> (..., 2, F) complex."""
    x = np.asarray(x)
    half = x.shape[-1] // 2
    z = x[..., :half] + 1j * x[..., half:]
    return z.reshape(x.shape[:-1] + (2, half // 2))


def normalise(values: np.ndarray, bounds=BOUNDS) -> np.ndarray:
    lo = np.array([bounds["R"][0], bounds["L"][0]])
    hi = np.array([bounds["R"][1], bounds["L"][1]])
    return (np.asarray(values, float) - lo) / (hi - lo)


def denormalise(values: np.ndarray, bounds=BOUNDS) -> np.ndarray:
    """Eq. 20: R = R_min + r (R_max - R_min), likewise L."""
    lo = np.array([bounds["R"][0], bounds["L"][0]])
    hi = np.array([bounds["R"][1], bounds["L"][1]])
    return lo + np.asarray(values, float) * (hi - lo)


def simulate_pairs(R, L, freq_hz=PAPER_GRID_HZ, rig: Rig | None = None):
    """Noise-free (a1, a2), each complex (n, n_freq), for the given R, L arrays (one batched call)."""
    rig = Rig() if rig is None else rig
    R = np.asarray(R, float)
    L = np.asarray(L, float)
    r = frf(freq_hz, rig.replace(R=R, L=L), outputs=ACCEL_CHANNELS)
    return r.a1, r.a2


def jitter_pairs(pairs, per_pair: int, rng, jitter_r=JITTER_R, jitter_l=JITTER_L, include_centre=False):
    """Samples around each pair: uniform ±jitter, clipped at 0. Returns R, L, group."""
    pairs = np.asarray(pairs, float).reshape(-1, 2)
    group = np.repeat(np.arange(len(pairs)), per_pair)
    R = pairs[group, 0] + rng.uniform(-jitter_r, jitter_r, group.size)
    L = pairs[group, 1] + rng.uniform(-jitter_l, jitter_l, group.size)
    if include_centre:
        R = np.concatenate([pairs[:, 0], R])
        L = np.concatenate([pairs[:, 1], L])
        group = np.concatenate([np.arange(len(pairs)), group])
    # clipped at 0 (SPEC); a tiny floor keeps the rig valid and L > 0 physical
    return np.clip(R, 0.0, None), np.clip(L, 1e-6, None), group


def make_dataset(
    preset: str = "paper",
    samples_per_pair: int | None = None,
    n_samples: int | None = None,
    val_fraction: float = 0.2,
    seed: int = 0,
    freq_hz=PAPER_GRID_HZ,
    rig: Rig | None = None,
) -> InverseDataset:
    """Synthetic labelled data for a preset (see the module docstring).

    Parameters
    ----------
    preset : "paper" or "box"
    samples_per_pair : samples around each of the 30 reference pairs (paper; the reference used 5;
        None: ``satmd.inverse.params.PRESET_SIZES``)
    n_samples : number of samples (box; None: ``PRESET_SIZES``)
    val_fraction : share of reference pairs (paper) or of samples (box) in the validation set
    seed : everything random (jitter, split) derives from it
    freq_hz : frequency grid
    rig : fixed mechanical parameters (default: the paper's rig)

    Returns
    -------
    InverseDataset
    """
    if preset not in PRESETS:
        raise SatmdError(f"unknown preset {preset!r}; choose from {', '.join(PRESETS)}")
    if not 0.0 <= val_fraction < 1.0:
        raise SatmdError(f"val_fraction must be in [0, 1), got {val_fraction}")
    from .params import PRESET_SIZES

    sizes = PRESET_SIZES[preset]
    samples_per_pair = sizes.get("samples_per_pair") if samples_per_pair is None else samples_per_pair
    n_samples = sizes.get("n_samples") if n_samples is None else n_samples
    rng = np.random.default_rng(seed)
    freq_hz = np.asarray(freq_hz, float)
    val_groups: np.ndarray | list[int]
    if preset == "paper":
        assert samples_per_pair is not None  # PRESET_SIZES["paper"] has it
        if samples_per_pair < 1:
            raise SatmdError(f"samples_per_pair must be >= 1, got {samples_per_pair}")
        R, L, group = jitter_pairs(PAPER_PAIRS, samples_per_pair, rng)
        n_groups = len(PAPER_PAIRS)
        # validation pairs: drawn among the interior pairs (the two ends stay in
        # training so that validation measures interpolation, like the blind pairs)
        n_val = int(round(val_fraction * n_groups))
        val_groups = rng.choice(np.arange(1, n_groups - 1), size=n_val, replace=False) if n_val else []
    else:
        assert n_samples is not None  # PRESET_SIZES["box"] has it
        if n_samples < 2:
            raise SatmdError(f"n_samples must be >= 2, got {n_samples}")
        (r0, r1), (l0, l1) = BOX_RANGE["R"], BOX_RANGE["L"]
        R = rng.uniform(r0, r1, n_samples)
        L = rng.uniform(l0, l1, n_samples)
        group = np.arange(n_samples)
        n_val = int(round(val_fraction * n_samples))
        val_groups = rng.choice(n_samples, size=n_val, replace=False) if n_val else []
    a1, a2 = simulate_pairs(R, L, freq_hz, rig)
    is_val = np.isin(group, np.asarray(val_groups, int))
    info = {"preset": preset, "seed": seed, "val_fraction": val_fraction}
    if preset == "paper":
        info["val_pairs"] = sorted(int(g) for g in np.asarray(val_groups, int))
    if preset == "paper":
        info["samples_per_pair"] = samples_per_pair
    else:
        info["n_samples"] = n_samples
        info["box_range"] = {k: list(v) for k, v in BOX_RANGE.items()}
    return InverseDataset(freq_hz, R, L, a1, a2, group, is_val, preset, info)


def pairs_dataset(pairs, per_pair: int = 0, seed: int = 0, jitter_r=JITTER_R / 2, jitter_l=JITTER_L / 2,
                  freq_hz=PAPER_GRID_HZ, rig: Rig | None = None, preset: str = "test") -> InverseDataset:
    """The given pairs exactly, plus ``per_pair`` jittered neighbours of each (test sets).

    Parameters
    ----------
    pairs : (k, 2) array of (R, L)
    per_pair : jittered neighbours per pair
    seed : jitter seed
    jitter_r, jitter_l : half-widths of the uniform jitter of R [Ω] and L [H]
    freq_hz : frequency grid
    rig : fixed mechanical parameters (default: the paper's rig)
    preset : label stored in the dataset

    Returns
    -------
    InverseDataset
    """
    rng = np.random.default_rng(seed)
    R, L, group = jitter_pairs(pairs, per_pair, rng, jitter_r, jitter_l, include_centre=True)
    a1, a2 = simulate_pairs(R, L, freq_hz, rig)
    return InverseDataset(np.asarray(freq_hz, float), R, L, a1, a2, group, np.zeros(R.size, bool), preset,
                          {"pairs": np.asarray(pairs).tolist(), "per_pair": per_pair, "seed": seed})


def crossfit_folds(ds: InverseDataset, n_folds: int, seed: int = 0) -> np.ndarray:
    """Cross-fitting folds: the fold of each sample (n,), or -1 for samples every fold trains on.

    The validation groups of ``ds`` (``is_val``: reference pairs in the paper
    preset, single samples in the box preset) are dealt at random into
    ``n_folds`` folds of near-equal size; every other sample is in no fold.
    Member ``k`` of a cross-fitted ensemble trains on every sample whose fold
    is not ``k``: each validation group is held out from one member only, so
    every member trains on nearly every pair, and each validation group has
    an out-of-fold prediction.

    Parameters
    ----------
    ds : the training data, with its validation partition
    n_folds : number of folds (>= 1)
    seed : the random assignment derives from it

    Returns
    -------
    ndarray of int
    """
    if n_folds < 1:
        raise SatmdError(f"cross-fitting needs at least 1 fold, got {n_folds}")
    val_groups = np.random.default_rng([int(seed), 29]).permutation(np.unique(ds.group[ds.is_val]))
    fold_of = np.full(len(ds), -1)
    for k, g in enumerate(val_groups.tolist()):
        fold_of[ds.group == g] = k % n_folds
    return fold_of


def add_input_noise(a: np.ndarray, rel: float, rng) -> np.ndarray:
    """Eq. 23 on complex FRFs (..., F): each of Re, Im gets N(0, (rel |A|)²)."""
    if not rel:
        return np.asarray(a)
    a = np.asarray(a)
    std = rel * np.abs(a)
    return a + std * (rng.standard_normal(a.shape) + 1j * rng.standard_normal(a.shape))

"""The output-error fit's intervals (`satmd.structure.output_error.half_widths`) against the textbook answer."""
import numpy as np
import pytest
from scipy.signal import lfilter

from satmd.structure.output_error import half_widths


def test_the_interval_of_a_mean_is_the_textbook_one_for_white_and_ar1_misfits():
    """For the mean of n samples (a Jacobian of ones), 1.96 σ/√n where the misfit is white; where it is AR(1)
    with lag-one correlation ρ, each run its own series, the variance of the mean is σ²/n · (1 + ρ)/(1 − ρ)
    (large n): three times wider at ρ = 0.8. A simulation's misfit is smooth, so this is the usual case."""
    rng = np.random.default_rng(0)
    n = 40000
    white = rng.normal(0.0, 2.0, n)
    assert half_widths(np.ones((n, 1)), white - white.mean(), [n])[0] == pytest.approx(1.96 * 2.0 / np.sqrt(n),
                                                                                          rel=0.03)
    rho = 0.8
    runs = [lfilter([1.0], [1.0, -rho], rng.normal(0.0, 1.0, n // 4)) for _ in range(4)]
    smooth = np.concatenate(runs)
    half = half_widths(np.ones((n, 1)), smooth - smooth.mean(), [r.size for r in runs])[0]
    assert half == pytest.approx(1.96 * smooth.std() / np.sqrt(n) * 3.0, rel=0.05)

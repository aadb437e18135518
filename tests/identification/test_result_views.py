"""FitResult's public views of the fitted problem: what other packages read instead of its private state."""
import numpy as np

from satmd import effect, identify, simulate


def test_public_views_agree_with_the_fit():
    data = simulate(effects=[effect("time_delay", tau_s=2e-4)], noise=(0.01, 0.002), seed=2)
    fit = identify(data)
    assert fit.data is not None and np.array_equal(fit.freq_hz, data.freq_hz)
    pred = fit.prediction()
    z = fit.standardised_residuals()
    for c in fit.channels:
        assert np.array_equal(fit.sigma[c], data.std[c])
        np.testing.assert_array_equal(fit.residuals()[c], pred[c] - data[c])  # model - data
        np.testing.assert_allclose(fit.residuals()[c] / fit.sigma[c], z[c], rtol=1e-12)

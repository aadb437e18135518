import numpy as np
import pytest

from satmd.explain import BLIND_CASES, PAPER_TABLE3, attribution, peak_frequencies, table3_stats
from satmd.explain.attributions import normalise_max, per_frequency

from .conftest import simulate, torch


def test_curves_shape_and_normalisation(standin):
    raw = simulate(*np.array(BLIND_CASES).T)
    att = attribution(standin, raw)
    assert att.curves.shape == (6, 2, 60)
    assert att.gradients.shape == (6, 2, 240)
    np.testing.assert_allclose(att.curves.max(axis=-1), 1.0)
    assert np.all(att.curves >= 0)
    assert att.S_R.shape == att.S_L.shape == (6, 60)
    assert att.prediction.shape == (6, 2)
    scaled = attribution(standin, raw, space="scaled")
    np.testing.assert_allclose(scaled.curves.max(axis=-1), 1.0)
    with pytest.raises(ValueError):
        attribution(standin, raw, space="nope")


def test_gradient_is_the_raw_feature_derivative(standin):
    """The raw gradient equals a central finite difference of the ensemble-mean output."""
    raw = simulate([22.0], [0.064])
    att = attribution(standin, raw)

    def out(x):
        xs = torch.as_tensor(standin.features(x))
        with torch.no_grad():
            return torch.stack([n(xs.double().float()) for n in standin.networks_]).double().mean(0).numpy()[0]

    for j in (3, 70, 150, 233):
        h = 1e-3 * standin.scaler_.scale[j]
        xp, xm = raw.copy(), raw.copy()
        xp[0, j] += h
        xm[0, j] -= h
        fd = (out(xp) - out(xm)) / (2 * h)
        np.testing.assert_allclose(att.gradients[0, :, j], fd, rtol=0.05, atol=1e-3 * np.abs(att.gradients).max())


def test_per_frequency_sums_re_im_of_both_channels():
    n_freq = 3
    v = np.arange(12.0) - 6  # [Re A1 | Re A2 | Im A1 | Im A2], 3 points each
    expected = np.abs(v).reshape(4, 3).sum(axis=0)
    np.testing.assert_allclose(per_frequency(v, n_freq), expected)
    np.testing.assert_allclose(normalise_max(np.array([[1.0, 2.0, 4.0]])), [[0.25, 0.5, 1.0]])


def test_table3_definitions_on_a_constructed_example():
    f = np.array([40.0, 50.0, 60.0, 70.0, 105.0])
    curves = np.array([[0.2, 1.0, 0.2, 0.1, 0.5],
                       [0.4, 1.0, 0.0, 0.1, 0.9]])
    s = table3_stats(curves, f)
    mean_curve = np.array([0.3, 1.0, 0.1, 0.1, 0.7])  # max already 1
    assert s["mean"] == pytest.approx(mean_curve.mean())
    assert s["std"] == pytest.approx(mean_curve.std())
    case_std = np.array([0.1, 0.0, 0.1, 0.0, 0.2])
    assert s["mean_case_std"] == pytest.approx(case_std.mean())
    assert s["max_case_std"] == pytest.approx(0.2)
    assert s["peaks_hz"] == [50.0, 105.0]
    # re-normalisation of the mean curve
    s2 = table3_stats(curves * np.array([[1.0], [1.0]]) * 0.5, f)
    assert s2["mean"] == pytest.approx(s["mean"])
    assert set(PAPER_TABLE3["R"]) == {"mean", "std", "mean_case_std", "max_case_std"}


def test_peak_frequencies_separation():
    f = np.linspace(40, 130, 61)
    y = np.exp(-((f - 51) / 2) ** 2) + 0.6 * np.exp(-((f - 106) / 3) ** 2) + 0.9 * np.exp(-((f - 54) / 2) ** 2)
    peaks = peak_frequencies(y, f)
    assert len(peaks) == 2
    assert 49 <= peaks[0] <= 56 and 103 <= peaks[1] <= 109

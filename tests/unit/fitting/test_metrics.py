"""The reports' SSIM (vecfit/fitting/metrics.py, OpenCV) is scikit-image's
structural_similarity as vecfit reported it before: Gaussian window, sigma 1.5, sample
covariance, data range 1."""
from __future__ import annotations

import numpy as np
import pytest
from skimage.metrics import structural_similarity

from vecfit.fitting.metrics import compare, ssim


@pytest.mark.parametrize("shape", [(64, 48, 3), (11, 40, 3), (37, 11, 3), (200, 300, 3)])
def test_ssim_is_scikit_images(shape):
    rng = np.random.default_rng(sum(shape))
    a = rng.random(shape)
    b = np.clip(a + 0.1 * rng.standard_normal(shape), 0, 1)
    b[: shape[0] // 3] = 0.5  # a flat band: the constants matter there
    expected = structural_similarity(a, b, channel_axis=2, data_range=1.0, gaussian_weights=True,
                                     sigma=1.5, use_sample_covariance=True)
    assert ssim(a, b) == pytest.approx(expected, abs=1e-12)


def test_ssim_of_tiny_images_and_identical_ones():
    rng = np.random.default_rng(3)
    a = rng.random((5, 7, 3))
    assert ssim(a, a) == pytest.approx(1.0, abs=1e-12)  # narrower than the window: averaged whole
    assert abs(ssim(a, rng.random((5, 7, 3)))) < 0.3  # unrelated noise: about 0
    figures = compare(a, a)
    assert figures["mse"] == 0 and figures["psnr"] == float("inf") and figures["ssim"] == pytest.approx(1.0)

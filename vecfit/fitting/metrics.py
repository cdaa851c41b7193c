"""Image quality figures for reports: MSE, PSNR and SSIM (scikit-image), on RGB in [0, 1]."""
from __future__ import annotations

import math

import numpy as np
from skimage.metrics import structural_similarity

from vecfit.io.compositing import composite


def to_rgb(image: np.ndarray, background=(1.0, 1.0, 1.0)) -> np.ndarray:
    """[H, W, 4] straight RGBA (or [H, W, 3]) -> [H, W, 3] RGB composited over background
    (RGB or RGBA, its alpha ignored; None: white)."""
    image = np.asarray(image, dtype=np.float64)
    if image.shape[2] == 3:
        return image
    return composite(image, (1.0, 1.0, 1.0) if background is None else background)


def compare(result: np.ndarray, target: np.ndarray) -> dict:
    """MSE, PSNR (dB) and SSIM of two RGB images in [0, 1] of the same size."""
    mse = float(np.mean((result - target) ** 2))
    psnr = float("inf") if mse == 0 else 10 * math.log10(1.0 / mse)
    ssim = float(structural_similarity(result, target, channel_axis=2, data_range=1.0,
                                      gaussian_weights=True, sigma=1.5,
                                      use_sample_covariance=True))
    return {"mse": mse, "psnr": psnr, "ssim": ssim}


def seen(rgba: np.ndarray, background) -> np.ndarray:
    """The channels the loss compares (loop.Target.compared): RGB over an opaque background,
    else premultiplied RGBA."""
    return composite(rgba, background)

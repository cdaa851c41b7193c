"""A target's blur, estimated, and the render blurred alike for the loss.

A scanned or photographed drawing is blurred: its edges ramp over a few pixels where a
render's ramp over one. Fitted as it is, sharp lines are pulled wide and faint to match
the ramps. Fitted through the blur instead (the render blurred by the target's blur
before the loss compares them), the fit recovers the sharp drawing whose blur the scan
shows, and that sharp drawing is what is written.

The estimate reads the edges: at a step of height H blurred by a Gaussian of sigma s, the
steepest gradient is H / (s sqrt(2 pi)). Over the image's strong edges (gradient maxima
with a step of at least a quarter of the range across 10 px), the median of that ratio
measures the edge's total spread: the blur and the render's own anti-aliasing and the
3x3 Sobel, which add in quadrature to RENDER_SPREAD on a crisp render. A line narrower
than about four times the blur reads as less blurred than it is (its two ramps meet:
7-px lines blurred by 2.5 px read 1.85), so the fit then takes part of the blur for the
drawing; it never reads more.
"""
from __future__ import annotations

import numpy as np

RENDER_SPREAD = 0.76  # the estimate's reading (px) on a crisp render (box anti-aliasing, Sobel)
MIN_STEP = 0.25  # a strong edge's step, in luma across 10 px
MIN_EDGES = 50  # fewer strong edges than this: no estimate (0)
MAX_BLUR = 8.0  # px: the largest blur fitted through
BLUR_FLOOR = 0.4  # px: an estimate below this is a render's own edges (0.0-0.3 measured), not blur


def estimate_blur(rgb: np.ndarray) -> float:
    """The Gaussian blur (sigma, px) of an image [H, W, 3] in [0, 1] beyond a crisp
    render's anti-aliasing: about 0 for a render, 1 for one blurred by sigma 1 (module
    docstring); 0 where the image has too few strong edges to tell."""
    import cv2

    luma = np.ascontiguousarray(np.asarray(rgb, np.float32)[..., :3] @ np.array([0.299, 0.587, 0.114], np.float32))
    gx = cv2.Sobel(luma, cv2.CV_32F, 1, 0, ksize=3) / 8
    gy = cv2.Sobel(luma, cv2.CV_32F, 0, 1, ksize=3) / 8
    steepness = np.hypot(gx, gy)
    peaks = (steepness >= cv2.dilate(steepness, np.ones((3, 3), np.uint8))) & (steepness > 0.02)
    ys, xs = np.nonzero(peaks)
    if len(ys) < MIN_EDGES:
        return 0.0
    nx, ny = gx[ys, xs] / steepness[ys, xs], gy[ys, xs] / steepness[ys, xs]
    h, w = luma.shape

    def along(d: float) -> np.ndarray:
        px = np.clip(xs + d * nx, 0, w - 1).astype(np.float32)[None]
        py = np.clip(ys + d * ny, 0, h - 1).astype(np.float32)[None]
        return cv2.remap(luma, px, py, cv2.INTER_LINEAR)[0]

    step = along(5.0) - along(-5.0)
    strong = step > MIN_STEP
    if strong.sum() < MIN_EDGES:
        return 0.0
    spread = float(np.median(step[strong] / (np.sqrt(2 * np.pi) * steepness[ys, xs][strong])))
    return float(min(np.sqrt(max(spread * spread - RENDER_SPREAD * RENDER_SPREAD, 0.0)), MAX_BLUR))


def gaussian_blur(image, sigma: float):
    """A torch image [H, W, C] blurred by a Gaussian of ``sigma`` px (edges replicated),
    differentiable; the image itself where sigma is 0. The SSIM loss's separable blur
    (losses.py), on the image padded by the window's reach."""
    import torch.nn.functional as F

    from .losses import _blur, _gaussian_window

    if sigma <= 0:
        return image
    reach = max(int(np.ceil(3 * sigma)), 1)
    padded = F.pad(image.permute(2, 0, 1)[None], (reach, reach, reach, reach), mode="replicate")
    return _blur(padded, _gaussian_window(2 * reach + 1, sigma).to(image.device))[0].permute(1, 2, 0)

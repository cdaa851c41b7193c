"""Colour quantisation: k-means in CIELAB, so that clusters follow perceived colour
differences rather than RGB distances (dark tones are not lumped together)."""
from __future__ import annotations

import cv2
import numpy as np

OPAQUE = 0.5  # pixels at least this opaque are traced; the others stay transparent


def prefilter(rgb: np.ndarray, blur: float) -> np.ndarray:
    """A light Gaussian blur (sigma in pixels) that calms noise and texture before
    clustering, so fewer one-pixel speckles come out of it. 0 leaves the image as is."""
    if blur <= 0:
        return rgb
    return cv2.GaussianBlur(rgb, (0, 0), sigmaX=blur, sigmaY=blur, borderType=cv2.BORDER_REFLECT)


# sRGB (D65) to CIE XYZ, and the D65 white: the constants OpenCV's RGB2Lab uses.
SRGB_TO_XYZ = np.array([[0.412453, 0.357580, 0.180423],
                        [0.212671, 0.715160, 0.072169],
                        [0.019334, 0.119193, 0.950227]])
D65_WHITE = np.array([0.950456, 1.0, 1.088754])


def to_lab(rgb: np.ndarray) -> np.ndarray:
    """sRGB float in [0, 1] to CIELAB (L in [0, 100], a and b about [-128, 127]), float32.
    By the formulas, in NumPy: OpenCV's float conversion builds its lookup tables on first
    use (0.09 s of `vecfit trace --no-refine` on an emoji) and interpolates in them
    (0.1 of a unit off on average); the tracer converts only its distinct colours."""
    rgb = np.clip(np.asarray(rgb, np.float64), 0.0, 1.0)
    linear = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    xyz = linear @ (SRGB_TO_XYZ / D65_WHITE[:, None]).T
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16 / 116)
    y = xyz[..., 1]
    lightness = np.where(y > 0.008856, 116 * f[..., 1] - 16, 903.3 * y)
    return np.stack([lightness, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])], -1).astype(np.float32)


def quantize_colors(rgb: np.ndarray, opaque: np.ndarray, colors: int, seed: int,
             sample: int = 20_000, attempts: int = 1) -> np.ndarray:
    """Cluster label of each pixel, int32 [H, W]; -1 where the pixel is not opaque.

    k-means runs on at most `sample` opaque pixels (a seeded random subset, for speed),
    then every opaque pixel takes the nearest centre."""
    labels = np.full(opaque.shape, -1, np.int32)
    colours, which = distinct_colors(rgb[opaque])
    if len(colours) == 0:
        return labels
    colours_lab = to_lab(colours[None])[0]
    lab = colours_lab[which]
    rng = np.random.default_rng(seed)
    data = lab if len(lab) <= sample else lab[rng.choice(len(lab), sample, replace=False)]
    if count_distinct(data) <= colors:
        centres = np.unique(data, axis=0)  # few colours (flat art, tiny images): each is its own cluster
    else:
        cv2.setRNGSeed(seed)  # cv2.kmeans draws its k-means++ seeds from OpenCV's global RNG
        criteria = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.05)
        _, _, centres = cv2.kmeans(np.ascontiguousarray(data), colors, None, criteria, attempts,
                                   cv2.KMEANS_PP_CENTERS)
    # each distinct colour is labelled once (an emoji has a few thousand, a photo's
    # 250,000 pixels about 100,000)
    labels[opaque] = nearest_centre(colours_lab, centres)[which]
    return labels


def palette_classes(rgb: np.ndarray, opaque: np.ndarray, palette_rgb: np.ndarray) -> np.ndarray:
    """Like quantize_colors with fixed centres: each opaque pixel's nearest palette colour
    (index into ``palette_rgb`` [n, 3] in [0, 1]) in CIELAB; -1 where not opaque."""
    labels = np.full(opaque.shape, -1, np.int32)
    colours, which = distinct_colors(rgb[opaque])
    if len(colours):
        labels[opaque] = nearest_centre(to_lab(colours[None])[0], to_lab(palette_rgb[None])[0])[which]
    return labels


def distinct_colors(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of rgb [N, 3] and, for each row, the index of its own: found by
    their 8-bit values where the colours are 8-bit ones (as read from files), else by
    their exact float values."""
    if len(rgb) == 0:
        return rgb.reshape(0, 3), np.zeros(0, np.int64)
    levels = np.rint(rgb * 255)
    if np.array_equal((levels / 255).astype(rgb.dtype), rgb):
        key = (levels[:, 0].astype(np.int64) << 16) | (levels[:, 1].astype(np.int64) << 8) | levels[:, 2].astype(np.int64)
        _, first, which = np.unique(key, return_index=True, return_inverse=True)
    else:
        _, first, which = np.unique(np.ascontiguousarray(rgb).view(np.dtype((np.void, rgb.itemsize * 3))),
                                    return_index=True, return_inverse=True)
    return np.ascontiguousarray(rgb[first]), which.reshape(-1)


def count_distinct(rows: np.ndarray) -> int:
    """How many distinct rows a float array [N, C] has (compared as bytes: -0.0 and 0.0
    differ, which colours converted from [0, 1] do not produce)."""
    rows = np.ascontiguousarray(rows)
    return len(np.unique(rows.view(np.dtype((np.void, rows.itemsize * rows.shape[1])))))


def nearest_centre(points: np.ndarray, centres: np.ndarray, chunk: int = 1 << 16) -> np.ndarray:
    """Index of the nearest centre for each point (ties go to the lower index), in chunks
    to bound the memory of the distance matrix."""
    out = np.empty(len(points), np.int32)
    c2 = (centres ** 2).sum(1)
    for start in range(0, len(points), chunk):
        p = points[start:start + chunk]
        d = c2[None, :] - 2.0 * p @ centres.T
        out[start:start + chunk] = d.argmin(1)
    return out

"""The changed region of an edit: where the edited image differs from the SVG's own
render, or where the user's mask says so."""
from __future__ import annotations

import cv2
import numpy as np

from vecfit.errors import VecfitError
from vecfit.io.images import load_rgba


def changed_region(original: np.ndarray, edited: np.ndarray, threshold: float, min_area: int,
                   grow: int) -> np.ndarray:
    """[H, W] bool: where a channel of the two images (RGB as the loss sees them, [H, W, C]
    in [0, 1]) differs by more than ``threshold``, less regions smaller than ``min_area``
    pixels (a different renderer's anti-aliasing along edges, which is no edit), grown by
    ``grow`` pixels (the edges of an edited shape blend with its neighbours)."""
    diff = np.abs(np.asarray(original, np.float32) - np.asarray(edited, np.float32)).max(axis=2)
    changed = (diff > threshold).astype(np.uint8)
    if min_area > 1 and changed.any():
        n, labels, stats, _ = cv2.connectedComponentsWithStats(changed, connectivity=8)
        small = np.flatnonzero(stats[:, cv2.CC_STAT_AREA] < min_area)
        small = small[small > 0]  # label 0 is the unchanged rest
        changed[np.isin(labels, small)] = 0
    return grown(changed.astype(bool), grow)


def grown(region: np.ndarray, pixels: int) -> np.ndarray:
    """``region`` dilated by a disc of radius ``pixels``."""
    if pixels <= 0 or not region.any():
        return region
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * pixels + 1, 2 * pixels + 1))
    return cv2.dilate(region.astype(np.uint8), disc) > 0


def load_mask(path, size: tuple[int, int]) -> np.ndarray:
    """A user's mask image as [H, W] bool: white (or any light, opaque pixel) marks the
    changed region. ``size`` is (width, height), which it must have."""
    rgba = load_rgba(path)
    h, w = rgba.shape[:2]
    if (w, h) != tuple(size):
        raise VecfitError(f"{path}: the mask is {w}x{h} pixels but the edited image is "
                          f"{size[0]}x{size[1]}")
    light = rgba[..., :3].mean(axis=2) * rgba[..., 3]
    return light > 0.5

"""``trace --remove-background``: the flat background of an opaque image found and made
transparent for the tracer, so that no shape covers it.

The background colour is the border's dominant colour (the modal 4-bit bin of the
pixels along the image's edges, then their median inside that bin: robust to JPEG noise
and to shapes touching the border), or the colour the user gives (``--background``).
The pixels removed are those within BACKGROUND_DELTA_E (CIELAB) of it that are connected
to the image's border: a white counter inside a letter on a white page is background, the
white of an eye inside a face is not. The anti-aliased rim between the background and a
shape stays opaque here; the fit (against the background colour, which the written SVG
leaves out) then places the shape's edge within it, as over transparency.
"""
from __future__ import annotations

import cv2
import numpy as np

from .quantize import to_lab

BACKGROUND_DELTA_E = 6.0  # JPEG noise on a flat colour stays within 2-4 units
BORDER = 2  # pixels of each edge looked at for the dominant colour


def border_colour(rgb: np.ndarray) -> np.ndarray:
    """The dominant colour of the image's border: RGB float [3] in [0, 1], 8-bit exact."""
    b = BORDER
    edge = np.concatenate([rgb[:b].reshape(-1, 3), rgb[-b:].reshape(-1, 3),
                           rgb[:, :b].reshape(-1, 3), rgb[:, -b:].reshape(-1, 3)])
    bins = np.clip((edge * 16).astype(np.int64), 0, 15) @ np.array([256, 16, 1])
    modal = np.bincount(bins).argmax()
    return np.rint(np.median(edge[bins == modal], axis=0) * 255) / 255


def background_mask(rgb: np.ndarray, colour: np.ndarray, delta_e: float = BACKGROUND_DELTA_E) -> np.ndarray:
    """[H, W] bool: the pixels within ``delta_e`` of ``colour`` connected to the border."""
    near = np.linalg.norm(to_lab(rgb) - to_lab(np.asarray(colour, np.float64)[None])[0], axis=-1) < delta_e
    count, labels = cv2.connectedComponents(near.astype(np.uint8), connectivity=8)
    touching = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    keep = np.zeros(count, bool)
    keep[touching] = True
    keep[0] = False  # label 0: the pixels not near the colour
    return keep[labels]


def without_background(image: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """The RGBA image with its background (background_mask) made transparent."""
    out = np.array(image, np.float32, copy=True)
    out[background_mask(out[..., :3], colour), 3] = 0.0
    return out

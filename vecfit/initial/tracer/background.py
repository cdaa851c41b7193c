"""``trace --remove-background``: the flat background of an opaque image found and made
transparent for the tracer, so that no shape covers it.

The background colour is the colour of three or four of the image's corners where they
agree (a logo that bleeds to the canvas's edges along most of the border still leaves its
rounded corners on the page), else the border's dominant colour (the modal 4-bit bin of
the pixels along the image's edges); either way the median of the border pixels of that
colour, robust to JPEG noise. Or the colour the user gives (``--background``).
Every pixel within BACKGROUND_DELTA_E (CIELAB) of it is background, enclosed or not (a
logo's counters and holes show the page too; as a commercial tracer's "ignore white",
a white eye on a white page goes with it). The anti-aliased rim around it is unmixed:
each rim pixel is taken as the nearest shape pixel's colour over the background, with
the coverage that explains it as its alpha, so the tracer places the edges between
pixels as it does on a transparent image. Beyond the canvas counts as background: the
edge pixels of a shape that touches the canvas's edge are rim too, unmixed where they are
a blend (left mixed, they were traced as pixel-sized pieces of their own colours). The
fit then runs on the original image over the background colour, which the written SVG
leaves out.
"""
from __future__ import annotations

import cv2
import numpy as np

from .quantize import to_lab

BACKGROUND_DELTA_E = 6.0  # JPEG noise on a flat colour stays within 2-4 units
BORDER = 2  # pixels of each edge looked at for the dominant colour
EDGE_BLEND = 0.05  # RGB distance within which an edge pixel is a blend of the background and its inner neighbour


def border_colour(rgb: np.ndarray) -> np.ndarray:
    """The background colour the module's docstring describes: RGB float [3] in [0, 1],
    8-bit exact."""
    b = BORDER
    edge = np.concatenate([rgb[:b].reshape(-1, 3), rgb[-b:].reshape(-1, 3),
                           rgb[:, :b].reshape(-1, 3), rgb[:, -b:].reshape(-1, 3)])
    corners = _corners_colour(rgb)
    if corners is not None:
        chosen = background_mask(edge[None], corners)[0]
    else:
        bins = np.clip((edge * 16).astype(np.int64), 0, 15) @ np.array([256, 16, 1])
        chosen = bins == np.bincount(bins).argmax()
    return np.rint(np.median(edge[chosen], axis=0) * 255) / 255


def corners_rival(rgb: np.ndarray, colour: np.ndarray) -> np.ndarray | None:
    """A colour that two or more of the image's corners show (within BACKGROUND_DELTA_E)
    other than ``colour``, the background found: which of them is the page is then a
    guess (a frame bleeding to the canvas on two sides); None where there is none."""
    corners, agree = _corners(rgb)
    other = ~background_mask(corners[None], colour)[0]
    rivals = [k for k in range(4) if other[k] and agree[k] >= 2]
    return corners[rivals[0]] if rivals else None


def _corners_colour(rgb: np.ndarray) -> np.ndarray | None:
    """The colour that three or four of the image's corner pixels share, or None where no
    three agree."""
    corners, agree = _corners(rgb)
    best = int(agree.argmax())
    return corners[best] if agree[best] >= 3 else None


def _corners(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The four corner pixels [4, 3] and, for each, how many of the four (itself included)
    lie within BACKGROUND_DELTA_E of it."""
    corners = np.stack([rgb[0, 0], rgb[0, -1], rgb[-1, 0], rgb[-1, -1]])
    lab = to_lab(corners)
    return corners, (np.linalg.norm(lab[:, None] - lab[None], axis=-1) < BACKGROUND_DELTA_E).sum(1)


def background_mask(rgb: np.ndarray, colour: np.ndarray, delta_e: float = BACKGROUND_DELTA_E) -> np.ndarray:
    """[H, W] bool: the pixels within ``delta_e`` of ``colour``."""
    return np.linalg.norm(to_lab(rgb) - to_lab(np.asarray(colour, np.float64)[None])[0], axis=-1) < delta_e


def without_background(image: np.ndarray, colour: np.ndarray) -> np.ndarray:
    """The RGBA image with its background (background_mask) transparent and the rim
    around it unmixed (the module's docstring)."""
    out = np.array(image, np.float32, copy=True)
    background = background_mask(out[..., :3], colour)
    out[background, 3] = 0.0
    # beyond the canvas counts as background: a shape crossing the canvas's edge leaves
    # blends there with no background pixel beside them (a logo tangent to the edge)
    square = np.ones((3, 3), np.uint8)
    beside = cv2.dilate(background.astype(np.uint8), square) > 0
    beyond = np.pad(background, 1, constant_values=True).astype(np.uint8)
    rim = ~background & (cv2.dilate(beyond, square)[1:-1, 1:-1] > 0)
    inner = ~background & ~rim
    if not rim.any() or not inner.any():
        return out
    # each rim pixel's nearest inner pixel: its colour before mixing with the background
    _, labels = cv2.distanceTransformWithLabels((~inner).astype(np.uint8), cv2.DIST_L2, 3,
                                                labelType=cv2.DIST_LABEL_PIXEL)
    where = np.zeros(int(labels.max()) + 1, np.int64)
    where[labels[inner]] = np.flatnonzero(inner.ravel())
    pure = out[..., :3].reshape(-1, 3)[where[labels[rim]]]
    bg = np.asarray(colour, np.float32)[:3]
    seen, towards = out[rim][:, :3] - bg, pure - bg
    coverage = (seen * towards).sum(1) / np.maximum((towards ** 2).sum(1), 1e-6)
    # at the canvas's edge, away from any background pixel, only a blend is unmixed: a
    # pixel of another colour than its inner neighbour's (a line along the edge) stays
    blend = np.linalg.norm(seen - np.clip(coverage, 0.0, 1.0)[:, None] * towards, axis=1) <= EDGE_BLEND
    keep = ~blend & ~beside[rim]
    coverage = np.where(keep, 1.0, coverage)
    out[rim, :3] = np.where(keep[:, None], out[rim][:, :3], pure)
    out[rim, 3] = np.clip(coverage, 0.0, 1.0) * out[rim, 3]
    return out

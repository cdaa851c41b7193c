"""Flat art or photograph: the share of an image's pixels in flat areas.

Rendered icons, logos, flags, emoji and cartoons are mostly flat colour, anti-aliased
only along their edges; a photograph's pixels nearly all differ from a neighbour. The
fit's opacity rule (vecfit/fitting/opacity.py) and the tracer's compound paths
(vecfit/initial/tracer/groups.py) treat the two differently.
"""
from __future__ import annotations

import cv2
import numpy as np

# A pixel is flat when its 3 x 3 neighbourhood varies by at most FLAT_STEP in every
# channel; an image with less than FLAT_SHARE of its pixels flat is continuous-tone.
# Rendered icons, logos, flags and emoji: 0.84-0.97 flat; skimage's photos 0.04-0.53
# (rocket's sky), kitty and peppers under 0.01.
FLAT_STEP, FLAT_SHARE = 3 / 255, 0.7


def flat_share(rgb: np.ndarray) -> float:
    """The share of an image's pixels in flat areas (see FLAT_STEP)."""
    a = np.ascontiguousarray(rgb, np.float32)
    kernel = np.ones((3, 3), np.uint8)
    spread = cv2.dilate(a, kernel) - cv2.erode(a, kernel)
    return float((spread.reshape(*a.shape[:2], -1).max(2) <= FLAT_STEP).mean())


def is_flat_art(rgb: np.ndarray) -> bool:
    """Whether an image is flat art rather than continuous-tone (FLAT_SHARE)."""
    return flat_share(rgb) >= FLAT_SHARE

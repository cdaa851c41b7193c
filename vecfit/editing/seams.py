"""Seam carving (Avidan and Shamir 2007): vertical seams of least energy removed from an
image one at a time, each found by dynamic programming over the rows (vectorised along
the row). Written here rather than taken from a package: scikit-image dropped its
seam_carve, and the retarget job needs each seam's columns to move the SVG's points,
which the packages on PyPI do not return."""
from __future__ import annotations

import cv2
import numpy as np


def foreground(seen: np.ndarray, background: np.ndarray) -> np.ndarray:
    """[H, W] in [0, 1]: how far each pixel is from the background (largest channel
    difference). Vector art is flat: the inside of a shape has no more gradient energy
    than the empty canvas around it, so without this the seams cut through shapes as
    readily as through the background."""
    return np.abs(np.asarray(seen, np.float32) - np.asarray(background, np.float32)).max(axis=2)


def energy(image: np.ndarray) -> np.ndarray:
    """[H, W] gradient magnitude (|d/dx| + |d/dy|, Sobel, summed over the channels)."""
    a = np.asarray(image, np.float32)
    dx = np.abs(cv2.Sobel(a, cv2.CV_32F, 1, 0, ksize=3, borderType=cv2.BORDER_REPLICATE))
    dy = np.abs(cv2.Sobel(a, cv2.CV_32F, 0, 1, ksize=3, borderType=cv2.BORDER_REPLICATE))
    e = dx + dy
    return e.sum(axis=2) if e.ndim == 3 else e


def vertical_seam(e: np.ndarray) -> np.ndarray:
    """The 8-connected top-to-bottom path of least total energy: its column in each row."""
    h, w = e.shape
    cost = e.astype(np.float64).copy()
    back = np.zeros((h, w), np.int64)
    cols = np.arange(w)
    for y in range(1, h):
        prev = cost[y - 1]
        left = np.concatenate([[np.inf], prev[:-1]])
        right = np.concatenate([prev[1:], [np.inf]])
        choice = np.argmin(np.stack([left, prev, right]), axis=0) - 1  # -1, 0, +1
        back[y] = cols + choice
        cost[y] += prev[back[y]]
    seam = np.empty(h, np.int64)
    seam[-1] = int(np.argmin(cost[-1]))
    for y in range(h - 1, 0, -1):
        seam[y - 1] = back[y, seam[y]]
    return seam


def remove_seam(image: np.ndarray, seam: np.ndarray) -> np.ndarray:
    """``image`` ([H, W] or [H, W, C]) less the pixel ``seam[y]`` of each row y."""
    h, w = image.shape[:2]
    keep = np.ones((h, w), bool)
    keep[np.arange(h), seam] = False
    return image[keep].reshape(h, w - 1, *image.shape[2:])


def carve(image: np.ndarray, count: int, seen=None, salience=None) -> tuple[np.ndarray, list[np.ndarray]]:
    """``image`` less ``count`` vertical seams, each found on what the previous left, and
    the seams (each in the columns of the image it was removed from). ``seen``: the image
    whose energy decides (default ``image``); ``salience`` ([H, W]): added to the energy.
    Both are carved alongside the image."""
    seen = image if seen is None else seen
    salience = np.zeros(image.shape[:2], np.float32) if salience is None else salience
    seams = []
    for _ in range(count):
        seam = vertical_seam(energy(seen) + salience)
        seams.append(seam)
        image, seen, salience = (remove_seam(a, seam) for a in (image, seen, salience))
    return image, seams


def shift(x: np.ndarray, y: np.ndarray, seams: list[np.ndarray]) -> np.ndarray:
    """Where x moves when ``seams`` are removed in turn (points (x, y) in pixels): left by
    one for each seam pixel wholly to its left in its row, by the covered part for the
    seam pixel it lies in."""
    x = np.asarray(x, np.float64).copy()
    for seam in seams:
        rows = np.clip(np.floor(y).astype(np.int64), 0, len(seam) - 1)
        c = seam[rows]
        x -= np.clip(x - c, 0.0, 1.0)
    return x

"""Outputs of an optimisation run besides the SVG: the JSON report and the comparison
picture (target | initial | optimised | error map). Both are written atomically."""
from __future__ import annotations

import json
import math

import cv2
import numpy as np
from PIL import Image

from .files import atomic_write, atomic_write_text
from .png import to_uint8

PANEL_MAX = 512   # longest side of one panel of the comparison picture
GAP = 4           # pixels between panels
ERROR_GAIN = 4.0  # the error map shows |difference| x 4 (a 0.25 difference is full scale)


def _panel(rgb: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    if rgb.shape[1::-1] != size:
        rgb = cv2.resize(rgb.astype(np.float32), size, interpolation=cv2.INTER_AREA)
    return np.clip(rgb, 0, 1)


def error_map(result: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Mean absolute RGB difference, amplified and coloured (inferno: dark is right)."""
    err = np.clip(np.abs(result - target).mean(axis=2) * ERROR_GAIN, 0, 1)
    coloured = cv2.applyColorMap(to_uint8(err), cv2.COLORMAP_INFERNO)
    return coloured[..., ::-1].astype(np.float32) / 255.0


def comparison_image(target: np.ndarray, initial: np.ndarray, optimized: np.ndarray) -> np.ndarray:
    """Four panels side by side, RGB float: target, initial, optimised, error map."""
    return panels_image([target, initial, optimized, error_map(optimized, target)])


def panels_image(images: list[np.ndarray]) -> np.ndarray:
    """RGB float images side by side, each scaled to the first one's panel size (its
    longest side at most PANEL_MAX), GAP white pixels between them."""
    h, w = images[0].shape[:2]
    scale = min(1.0, PANEL_MAX / max(h, w))
    size = (max(1, round(w * scale)), max(1, round(h * scale)))
    pw, ph = size
    out = np.ones((ph, len(images) * pw + (len(images) - 1) * GAP, 3), dtype=np.float32)
    for i, image in enumerate(images):
        out[:, i * (pw + GAP):i * (pw + GAP) + pw] = _panel(image, size)
    return out


def side_by_side(images: list[np.ndarray]) -> np.ndarray:
    """RGB float images of different sizes side by side at one scale (the tallest panel at
    most PANEL_MAX high and the widest at most PANEL_MAX wide), top-aligned on white."""
    scale = min(1.0, PANEL_MAX / max(max(i.shape[0], i.shape[1]) for i in images))
    sizes = [(max(1, round(i.shape[1] * scale)), max(1, round(i.shape[0] * scale))) for i in images]
    out = np.ones((max(h for _, h in sizes), sum(w for w, _ in sizes) + GAP * (len(images) - 1), 3),
                  dtype=np.float32)
    x = 0
    for image, (w, h) in zip(images, sizes):
        out[:h, x:x + w] = _panel(image, (w, h))
        x += w + GAP
    return out


def save_comparison(path, target, initial, optimized) -> None:
    save_panels(path, comparison_image(target, initial, optimized))


def save_panels(path, image: np.ndarray) -> None:
    """An RGB float picture (panels_image) as a PNG, atomically."""
    pixels = to_uint8(image)
    atomic_write(path, lambda tmp: Image.fromarray(pixels, "RGB").save(tmp, format="PNG"))


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.floating, float)):
        v = float(value)
        return v if math.isfinite(v) else None  # JSON has no NaN / Infinity
    if isinstance(value, np.integer):
        return int(value)
    return value


def save_report(path, report: dict) -> None:
    atomic_write_text(path, json.dumps(_jsonable(report), indent=2, allow_nan=False) + "\n")

"""imwrite: diffvg's image writer (gamma-encoded 8-bit PNG), written atomically."""
from __future__ import annotations

import os

import numpy as np
import torch

from PIL import Image

from vecfit.io.files import atomic_write


def imwrite(img, filename, gamma=2.2, normalize=False):
    """Save an H x W x C image (C = 1, 3 or 4; or H x W) in [0, 1]: colour channels raised
    to 1/gamma, as diffvg does. Missing folders are created."""
    folder = os.path.dirname(os.fspath(filename))
    if folder:
        os.makedirs(folder, exist_ok=True)
    a = img.detach().cpu().numpy() if isinstance(img, torch.Tensor) else np.asarray(img)
    a = np.array(a, dtype=np.float64)
    if normalize:
        span = a.max() - a.min()
        if span > 0:
            a = (a - a.min()) / span
    a = np.clip(a, 0.0, 1.0)
    if a.ndim == 2:
        a = a[:, :, None]
    a[:, :, :3] = np.power(a[:, :, :3], 1.0 / gamma)
    channels = a.shape[2]
    if channels in (1, 2):  # grey (and alpha)
        a = np.concatenate([np.repeat(a[:, :, :1], 3, axis=2), a[:, :, 1:]], axis=2)
    if a.shape[2] == 3:
        a = np.concatenate([a, np.ones_like(a[:, :, :1])], axis=2)
    pixels = (a[:, :, :4] * 255 + 0.5).astype(np.uint8)
    if channels in (1, 3):
        pixels = pixels[:, :, :3]
    mode = "RGB" if pixels.shape[2] == 3 else "RGBA"
    fmt = Image.registered_extensions().get(os.path.splitext(os.fspath(filename))[1].lower(), "PNG")
    atomic_write(filename, lambda tmp: Image.fromarray(pixels, mode).save(tmp, format=fmt))

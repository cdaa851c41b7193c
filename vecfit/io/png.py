"""8-bit PNG files written with zlib alone. `vecfit render` writes its picture without
importing Pillow, whose image plugins cost a tenth of a second of start-up. No row filter:
rendered vector art is mostly flat colour, where the filters gain little (tiger's render:
49 KB, against Pillow's 65 KB)."""
from __future__ import annotations

import os
import struct
import sys
import zlib

import numpy as np

from .files import atomic_write_bytes

SIGNATURE = b"\x89PNG\r\n\x1a\n"
COLOUR_TYPES = {1: 0, 2: 4, 3: 2, 4: 6}  # channels -> PNG colour type (grey, grey+alpha, RGB, RGBA)
LEVEL = 5  # zlib's: within a tenth of level 6's size, several times faster on renders


def to_uint8(image) -> np.ndarray:
    """A float image in [0, 1] (NumPy or torch) as uint8, rounded."""
    torch = sys.modules.get("torch")  # (a tensor exists only once torch is imported)
    is_tensor = torch is not None and isinstance(image, torch.Tensor)
    a = image.detach().cpu().numpy() if is_tensor else np.asarray(image)
    if a.dtype.kind != "f":
        a = a.astype(np.float64)
    out = np.clip(a, 0, 1)  # (then in place: a fresh array per step cost more than the arithmetic)
    out *= 255
    out += 0.5
    return out.astype(np.uint8)


def _chunk(tag: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))


def png_bytes(pixels: np.ndarray) -> bytes:
    """The PNG file of uint8 pixels [H, W] or [H, W, C], C = 1-4 (grey, grey + alpha, RGB,
    RGBA), straight alpha."""
    a = np.asarray(pixels)
    if a.ndim == 2:
        a = a[..., None]
    if a.dtype != np.uint8 or a.ndim != 3 or a.shape[2] not in COLOUR_TYPES or 0 in a.shape:
        raise ValueError(f"a PNG holds uint8 pixels [H, W, 1-4], not {a.dtype} {list(np.shape(pixels))}")
    height, width, channels = a.shape
    rows = np.empty((height, 1 + width * channels), np.uint8)
    rows[:, 0] = 0  # filter type: none
    rows[:, 1:] = a.reshape(height, -1)
    header = struct.pack(">IIBBBBB", width, height, 8, COLOUR_TYPES[channels], 0, 0, 0)
    return (SIGNATURE + _chunk(b"IHDR", header) + _chunk(b"IDAT", zlib.compress(rows, LEVEL))
            + _chunk(b"IEND", b""))


def save_png(image, path: str | os.PathLike) -> None:
    """Save an [H, W, 4] straight-RGBA float image as an 8-bit RGBA PNG, atomically."""
    atomic_write_bytes(path, png_bytes(to_uint8(image)))

"""Reading raster images (files, bytes, PIL images, arrays), upright, as float RGBA; and
scaling them to the working size. Writing: vecfit.io.png and vecfit.io.files."""
from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from vecfit.errors import VecfitError
from vecfit.limits import MAX_IMAGE_PIXELS

from .orientation import upright_rgba


def load_rgba(path: str | os.PathLike) -> np.ndarray:
    """An image file as float32 straight RGBA in [0, 1], [H, W, 4], turned upright by its
    EXIF orientation (vecfit.io.orientation); VecfitError naming the file and the reason
    when it cannot be read."""
    return _read_file(Path(path))[0]


def _read_file(path: Path) -> tuple[np.ndarray, dict | None]:
    if not path.exists():
        raise VecfitError(f"{path}: no such file")
    if path.is_dir():
        raise VecfitError(f"{path}: is a folder, not an image")
    too_large = f"{path}: the image is larger than {MAX_IMAGE_PIXELS // 1_000_000} million pixels (the limit)"
    try:
        with _open(path) as im:
            if im.width * im.height > MAX_IMAGE_PIXELS:  # from the header, before decoding
                raise VecfitError(f"{path}: the image is {im.width}x{im.height} pixels; at most "
                                  f"{MAX_IMAGE_PIXELS // 1_000_000} million pixels (the limit)")
            return _upright_rgba(im, str(path))
    except Image.DecompressionBombError:  # Pillow's own limit, met before ours
        raise VecfitError(too_large) from None
    except UnidentifiedImageError:
        raise VecfitError(f"{path}: not an image file (or a format that cannot be read)") from None
    except (OSError, ValueError) as e:
        raise VecfitError(f"{path}: cannot read the image ({e})") from None


def _open(file) -> Image.Image:
    """Image.open without Pillow's nameless warnings of a corrupt EXIF block (JPEG's opener
    reads EXIF for its dpi; the parser is TIFF's): orientation_of says it again, naming the
    image."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=UserWarning, module=r"PIL\.TiffImagePlugin")
        return Image.open(file)


def _upright_rgba(im: Image.Image, name: str) -> tuple[np.ndarray, dict | None]:
    """The image as float32 RGBA, upright, and its "orientation" report entry."""
    rgba, orientation = upright_rgba(im, name)
    return np.asarray(rgba, dtype=np.float32) / 255.0, orientation


def image_rgba(source) -> np.ndarray:
    """An image given as a file path, the bytes of an image file, a PIL image or a NumPy
    array ([H, W], [H, W, 3] or [H, W, 4]; uint8, or floats in [0, 1]) as float32 straight
    RGBA in [0, 1], upright (a file's, bytes' or PIL image's EXIF orientation applied);
    VecfitError saying what is wrong with it."""
    return read_image(source)[0]


def read_image(source) -> tuple[np.ndarray, dict | None]:
    """image_rgba's image and the report's "orientation" entry (vecfit.io.orientation:
    None for an array, or an image without an EXIF orientation)."""
    if isinstance(source, (str, os.PathLike)):
        return _read_file(Path(source))
    if isinstance(source, (bytes, bytearray, memoryview)):
        import io
        try:
            with _open(io.BytesIO(bytes(source))) as im:
                if im.width * im.height > MAX_IMAGE_PIXELS:
                    raise VecfitError(f"the image is {im.width}x{im.height} pixels; at most "
                                      f"{MAX_IMAGE_PIXELS // 1_000_000} million pixels (the limit)")
                return _upright_rgba(im, "the image bytes given")
        except (UnidentifiedImageError, OSError, ValueError, Image.DecompressionBombError) as e:
            raise VecfitError(f"the image bytes cannot be read as an image ({e})") from None
    if isinstance(source, Image.Image):
        return _upright_rgba(source, "the PIL image given")
    return _array_rgba(source), None


def _array_rgba(source) -> np.ndarray:
    """A NumPy array (as image_rgba takes it) as float32 straight RGBA."""
    a = np.asarray(source)
    if a.ndim == 2:
        a = a[..., None].repeat(3, axis=2)
    if a.ndim != 3 or a.shape[2] not in (3, 4) or a.shape[0] * a.shape[1] == 0:
        raise VecfitError(f"an image array must be [H, W], [H, W, 3] or [H, W, 4], not {list(a.shape)}")
    if a.dtype == np.uint8:
        a = a.astype(np.float32) / 255.0
    elif np.issubdtype(a.dtype, np.floating):
        a = a.astype(np.float32)
        if not np.isfinite(a).all() or a.min() < 0 or a.max() > 1:
            raise VecfitError("an image array of floats must hold finite values in [0, 1]")
    else:
        raise VecfitError(f"an image array must be uint8 or floats in [0, 1], not {a.dtype}")
    if a.shape[2] == 3:
        a = np.concatenate([a, np.ones_like(a[..., :1])], axis=2)
    return np.ascontiguousarray(a)


# The shortest side a working image is scaled to (unless the image is shorter itself): the
# jobs' minimum, SSIM's 11 x 11 window. A 700 x 11 target at 512 px would be 8 px high.
MIN_WORKING_SIDE = 11


def working_scale(width: float, height: float, max_size: float, min_side: float = MIN_WORKING_SIDE) -> float:
    """The scale (at most 1) that brings the longest side to max_size (<= 0: no limit),
    but keeps the shortest side at min_side or more: a very wide image keeps its aspect
    ratio and stays longer than max_size."""
    scale = max_size / max(width, height) if max_size > 0 else 1.0
    return min(1.0, max(scale, min_side / min(width, height)))


def downscaled(image: np.ndarray, max_size: int) -> np.ndarray:
    """The image with its longest side at most max_size (area-averaged, premultiplied), its
    shortest at least MIN_WORKING_SIDE (see working_scale)."""
    h, w = image.shape[:2]
    scale = working_scale(w, h, max_size)
    if scale >= 1:
        return image
    import cv2  # here, not at the top: `vecfit render` writes PNGs without it (0.1 s of start-up)

    size = (max(1, round(w * scale)), max(1, round(h * scale)))
    pre = np.concatenate([image[..., :3] * image[..., 3:], image[..., 3:]], axis=2)
    small = cv2.resize(pre, size, interpolation=cv2.INTER_AREA)
    a = small[..., 3:]
    rgb = np.where(a > 0, small[..., :3] / np.maximum(a, 1e-12), 0)
    return np.concatenate([np.clip(rgb, 0, 1), np.clip(a, 0, 1)], axis=2).astype(np.float32)


def downscaled_weight(weight: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """A per-pixel weight [H, W] area-averaged to ``size`` = (height, width)."""
    if weight.shape[:2] == tuple(size):
        return weight
    import cv2

    return cv2.resize(weight.astype(np.float32), (size[1], size[0]),
                      interpolation=cv2.INTER_AREA).astype(np.float32)

"""The PNG writer (vecfit.io.png): what Pillow reads back is the image written, in every
colour type, and bad arrays are refused."""
from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from vecfit.io.png import png_bytes, save_png

RNG = np.random.default_rng(7)


@pytest.mark.parametrize("shape, mode", [((5, 7), "L"), ((5, 7, 1), "L"), ((6, 3, 2), "LA"),
                                         ((4, 9, 3), "RGB"), ((8, 2, 4), "RGBA"), ((1, 1, 4), "RGBA")])
def test_pillow_reads_back_every_colour_type(shape, mode):
    pixels = RNG.integers(0, 256, shape, dtype=np.uint8)
    with Image.open(io.BytesIO(png_bytes(pixels))) as im:
        assert im.mode == mode and im.size == (shape[1], shape[0])
        assert np.array_equal(np.asarray(im).reshape(shape), pixels)


@pytest.mark.parametrize("pixels", [np.zeros((3, 3, 4), np.float32), np.zeros((3, 3, 5), np.uint8),
                                    np.zeros((0, 3, 3), np.uint8), np.zeros(4, np.uint8)])
def test_other_arrays_are_refused(pixels):
    with pytest.raises(ValueError, match="uint8"):
        png_bytes(pixels)


def test_save_png_rounds_floats_and_replaces_the_file_whole(tmp_path):
    image = np.array([[[0.0, 0.5, 1.0, 1.0], [0.2, 0.4, 0.6, 0.25]]], np.float32)
    path = tmp_path / "out.png"
    path.write_bytes(b"old")
    save_png(image, path)
    with Image.open(path) as im:
        assert np.array_equal(np.asarray(im), [[[0, 128, 255, 255], [51, 102, 153, 64]]])
    assert [p.name for p in tmp_path.iterdir()] == ["out.png"]  # no temporary file left

"""vecfit.io's small helpers on known values: background colours, compositing, atomic
writes, flat art or photo, working sizes, and the comparison picture's panels."""
from __future__ import annotations

import os

import numpy as np
import pytest
import torch

from vecfit.errors import VecfitError
from vecfit.io.colors import fitting_background, parse_background
from vecfit.io.compositing import composite, composite_torch
from vecfit.io.files import atomic_write, atomic_write_bytes, atomic_write_text
from vecfit.io.png import to_uint8
from vecfit.io.images import downscaled, downscaled_weight, working_scale
from vecfit.io.report import GAP, error_map, panels_image, side_by_side
from vecfit.io.tone import flat_share, is_flat_art


@pytest.mark.parametrize("text, rgba", [
    (None, None), ("none", None), (" Transparent ", None), ("", None),
    ("white", (1.0, 1.0, 1.0, 1.0)), ("BLACK", (0.0, 0.0, 0.0, 1.0)),
    ("#f00", (1.0, 0.0, 0.0, 1.0)), ("#336699", (0.2, 0.4, 0.6, 1.0)),
    ("#33669980", (0.2, 0.4, 0.6, 128 / 255)), ("#0f08", (0.0, 1.0, 0.0, 136 / 255)),
])
def test_parse_background(text, rgba):
    got = parse_background(text)
    assert got == (None if rgba is None else pytest.approx(rgba))


@pytest.mark.parametrize("text", ["red", "#12345", "#ggg", "336699"])
def test_parse_background_refuses_what_it_cannot_read(text):
    with pytest.raises(VecfitError, match="background must be none, white, black"):
        parse_background(text)


def test_fitting_background_must_be_opaque():
    assert fitting_background("#336699") == pytest.approx((0.2, 0.4, 0.6, 1.0))
    assert fitting_background("none") is None
    with pytest.raises(VecfitError, match="must be opaque"):
        fitting_background("#33669980")


def test_composite_over_a_background_and_premultiplied():
    rgba = np.array([[[1.0, 0.5, 0.0, 0.5], [0.2, 0.2, 0.2, 0.0]]], np.float32)
    over = composite(rgba, (0.0, 0.0, 1.0, 1.0))
    np.testing.assert_allclose(over, [[[0.5, 0.25, 0.5], [0.0, 0.0, 1.0]]])
    np.testing.assert_allclose(composite(rgba, None), [[[0.5, 0.25, 0.0, 0.5], [0, 0, 0, 0]]])
    t = torch.tensor(rgba, requires_grad=True)
    np.testing.assert_allclose(composite_torch(t, (0.0, 0.0, 1.0, 1.0)).detach().numpy(), over)
    np.testing.assert_allclose(composite_torch(t, None).detach().numpy(), composite(rgba, None))
    composite_torch(t, (0.0, 0.0, 1.0, 1.0))[0, 0, 2].backward()
    assert t.grad[0, 0, 3] == pytest.approx(-1.0)  # blue over blue background: d/dalpha = 0 - 1


def test_atomic_writes_replace_whole_files_and_leave_nothing_on_failure(tmp_path):
    path = tmp_path / "sub" / "out.txt"
    atomic_write_text(path, "one\r\ntwo")
    assert path.read_bytes() == b"one\r\ntwo"  # newlines as given, folder made
    atomic_write_bytes(path, b"\x00\x01")
    assert path.read_bytes() == b"\x00\x01"
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's private 0600

    def broken(tmp):
        with open(tmp, "w") as f:
            f.write("half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atomic_write(path, broken)
    assert path.read_bytes() == b"\x00\x01" and sorted(os.listdir(path.parent)) == ["out.txt"]


def test_flat_share_tells_flat_art_from_noise():
    flat = np.zeros((20, 20, 3), np.float32)
    flat[:, 10:] = (1.0, 0.5, 0.0)
    # only the two columns along the edge vary within their 3 x 3 neighbourhood
    assert flat_share(flat) == pytest.approx(18 / 20)
    assert is_flat_art(flat)
    noise = np.random.default_rng(0).random((20, 20, 3)).astype(np.float32)
    assert flat_share(noise) == 0.0 and not is_flat_art(noise)


@pytest.mark.parametrize("w, h, max_size, scale", [
    (1024, 512, 512, 0.5), (300, 200, 512, 1.0), (300, 200, 0, 1.0),
    (700, 11, 512, 1.0),       # the short side would fall under 11 px: kept
    (2000, 20, 500, 11 / 20),  # scaled only as far as 11 px high
])
def test_working_scale(w, h, max_size, scale):
    assert working_scale(w, h, max_size) == pytest.approx(scale)


def test_downscaled_averages_premultiplied():
    image = np.zeros((24, 24, 4), np.float32)
    image[:, :12] = (1.0, 0.0, 0.0, 1.0)   # opaque red on the left
    image[:, 12:] = (0.0, 1.0, 0.0, 0.0)   # transparent "green" on the right
    image[:12, 1:12:2] = (0.0, 1.0, 0.0, 0.0)  # top left: every other column transparent too
    assert downscaled(image, 24) is image
    narrow = image[:, :4]
    assert downscaled(narrow, 2) is narrow  # its short side is under 11 px already
    small = downscaled(image, 12)
    assert small.shape == (12, 12, 4) and small.dtype == np.float32
    np.testing.assert_allclose(small[11, :6], [[1, 0, 0, 1]] * 6, atol=1e-6)
    np.testing.assert_allclose(small[11, 6:], [[0, 0, 0, 0]] * 6, atol=1e-6)
    # half covered by red: red at alpha 0.5 (the hidden green adds nothing)
    np.testing.assert_allclose(small[0, :6], [[1, 0, 0, 0.5]] * 6, atol=1e-6)
    weight = np.arange(16, dtype=np.float32).reshape(4, 4)
    np.testing.assert_allclose(downscaled_weight(weight, (2, 2)), [[2.5, 4.5], [10.5, 12.5]])
    assert downscaled_weight(weight, (4, 4)) is weight


def test_panels_and_error_map():
    a = np.zeros((10, 20, 3), np.float32)
    b = np.ones((5, 10, 3), np.float32)
    out = panels_image([a, b, a])
    assert out.shape == (10, 3 * 20 + 2 * GAP, 3)
    assert out[:, 20:20 + GAP].min() == 1.0 and out[:, 20 + GAP:40 + GAP].min() == 1.0  # b scaled up
    pair = side_by_side([a, b])
    assert pair.shape == (10, 20 + GAP + 10, 3) and pair[5:, 20 + GAP:].min() == 1.0  # top-aligned on white
    right, wrong = error_map(a, a), error_map(b[:, :, :] * 0 + 1, np.zeros((5, 10, 3), np.float32))
    assert right.shape == (10, 20, 3) and right.max() < 0.05  # inferno's dark end
    assert wrong.mean() > 0.5  # full scale: inferno's light end


def test_to_uint8_rounds_clamps_and_leaves_its_input_alone():
    image = np.array([[-0.5, 0.0, 0.5 / 255, 1.5 / 255, 0.2, 1.0, 7.0]], np.float32)
    before = image.copy()
    assert to_uint8(image).tolist() == [[0, 0, 1, 2, 51, 255, 255]]  # (+0.5, then truncated)
    assert (image == before).all()  # (converted in place in a copy, not in the caller's array)
    assert to_uint8(np.array([0, 1, 2])).tolist() == [0, 255, 255]  # integers: as floats
    assert to_uint8(image.astype(np.float64)).tolist() == to_uint8(image).tolist()

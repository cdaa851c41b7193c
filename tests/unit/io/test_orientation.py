"""EXIF orientation: a picture stored turned (as phones store photos) is read upright, from
a file, bytes or a PIL image, JPEG or PNG (eXIf chunk), for all 8 orientations; a broken
EXIF block or orientation leaves it as stored, with a warning naming the file; and a job
(trace) writes the upright size and says in its report what it applied."""
from __future__ import annotations

import io
import json
import re
import warnings

import numpy as np
import pytest
from PIL import Image

import vecfit
from vecfit.io.images import image_rgba, load_rgba, read_image

ORIENTATION_TAG = 0x0112
JPEG_TOLERANCE = 0.03  # mean absolute error of a quality-95 4:4:4 JPEG of flat quadrants
TURNED_TOLERANCE = 0.15  # what a wrong orientation would at least cost (distinct colours)


def upright_picture(width=24, height=16) -> np.ndarray:
    """uint8 RGB [height, width, 3]: four distinct quadrants, so each of the 8 orientations
    (and the swapped sides of 5-8) gives a different picture."""
    a = np.zeros((height, width, 3), np.uint8)
    h, w = height // 2, width // 2
    a[:h, :w] = (220, 30, 30)
    a[:h, w:] = (30, 200, 40)
    a[h:, :w] = (40, 60, 230)
    a[h:, w:] = (240, 220, 40)
    return a


def stored_as(upright: np.ndarray, orientation: int) -> np.ndarray:
    """What a camera stores for ``upright`` under ``orientation``, written from the EXIF
    table's words (where the stored 0th row and 0th column lie in the upright picture),
    independently of the code under test: stored[r, c] = upright[...]."""
    H, W = upright.shape[:2]
    rows, cols = np.indices((W, H) if orientation >= 5 else (H, W))
    index = {
        1: (rows, cols),                   # top, left
        2: (rows, W - 1 - cols),           # top, right
        3: (H - 1 - rows, W - 1 - cols),   # bottom, right
        4: (H - 1 - rows, cols),           # bottom, left
        5: (cols, rows),                   # left, top
        6: (cols, W - 1 - rows),           # right, top
        7: (H - 1 - cols, W - 1 - rows),   # right, bottom
        8: (H - 1 - cols, rows),           # left, bottom
    }[orientation]
    return upright[index]


def encoded(pixels: np.ndarray, fmt: str, exif: bytes | None = None, phone_like: bool = False) -> bytes:
    """The image file's bytes; a JPEG as phones write it (phone_like: EXIF, no JFIF
    segment) makes Pillow parse the EXIF block while opening."""
    buf = io.BytesIO()
    options = {"quality": 95, "subsampling": 0} if fmt == "JPEG" else {}
    Image.fromarray(pixels, "RGB").save(buf, format=fmt, **options, **({} if exif is None else {"exif": exif}))
    data = buf.getvalue()
    if phone_like:
        assert data[2:4] == b"\xff\xe0"  # APP0 (JFIF) right after SOI
        data = data[:2] + data[4 + int.from_bytes(data[4:6], "big"):]
    return data


def exif_with(orientation) -> bytes:
    exif = Image.Exif()
    exif[ORIENTATION_TAG] = orientation
    return exif.tobytes()


def as_float(pixels: np.ndarray) -> np.ndarray:
    return pixels.astype(np.float32) / 255.0


def assert_same_picture(got: np.ndarray, want_uint8: np.ndarray, tolerance: float) -> None:
    assert got.shape[:2] == want_uint8.shape[:2]
    assert np.all(got[..., 3] == 1.0)
    assert float(np.abs(got[..., :3] - as_float(want_uint8)).mean()) < tolerance


def test_the_stored_pictures_differ():
    """The oracle's 8 stored pictures are all different, and far apart at JPEG's
    tolerance: a test reading one orientation as another would fail."""
    up = upright_picture()
    stored = {k: stored_as(up, k) for k in range(1, 9)}
    for a in range(1, 9):
        for b in range(a + 1, 9):
            sa, sb = stored[a], stored[b]
            if sa.shape == sb.shape:
                assert np.abs(as_float(sa) - as_float(sb)).mean() > TURNED_TOLERANCE, (a, b)
    assert stored[6].shape[:2] == (24, 16) and stored[3].shape[:2] == (16, 24)


@pytest.mark.parametrize("fmt", ["JPEG", "PNG"])
@pytest.mark.parametrize("orientation", range(1, 9))
def test_every_orientation_is_read_upright(tmp_path, fmt, orientation):
    up = upright_picture()
    data = encoded(stored_as(up, orientation), fmt, exif_with(orientation))
    if fmt == "PNG":
        assert b"eXIf" in data
    path = tmp_path / f"o{orientation}.{fmt.lower()}"
    path.write_bytes(data)
    tolerance = JPEG_TOLERANCE if fmt == "JPEG" else 1e-6
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a good EXIF block warns of nothing
        got, entry = read_image(path)
    assert_same_picture(got, up, tolerance)
    assert entry["exif"] == orientation and "ignored" not in entry
    assert (entry["applied"] == "none") == (orientation == 1)
    assert_same_picture(load_rgba(path), up, tolerance)


@pytest.mark.parametrize("orientation", [5, 6])
def test_bytes_and_pil_images_are_read_upright(orientation):
    up = upright_picture()
    data = encoded(stored_as(up, orientation), "JPEG", exif_with(orientation), phone_like=True)
    assert_same_picture(image_rgba(data), up, JPEG_TOLERANCE)
    with Image.open(io.BytesIO(data)) as im:
        assert_same_picture(image_rgba(im), up, JPEG_TOLERANCE)
    assert read_image(data)[1] == read_image(Image.open(io.BytesIO(data)))[1] == {
        "exif": orientation, "applied": {5: "transpose (mirror across the top-left diagonal)",
                                         6: "rotate 90 CW"}[orientation]}


def test_an_exif_chunk_after_the_pixels_counts():
    """PNG allows eXIf after IDAT, where Pillow finds it only once the pixels are decoded."""
    up = upright_picture()
    data = encoded(stored_as(up, 6), "PNG", exif_with(6))
    start = data.index(b"eXIf") - 4
    assert start < data.index(b"IDAT")  # Pillow writes it before: move it after
    chunk = data[start:start + 12 + int.from_bytes(data[start:start + 4], "big")]
    rest = data.replace(chunk, b"")
    end = rest.index(b"IEND") - 4
    got, entry = read_image(rest[:end] + chunk + rest[end:])
    assert entry == {"exif": 6, "applied": "rotate 90 CW"}
    assert_same_picture(got, up, 1e-6)


def test_no_orientation_no_entry(tmp_path):
    up = upright_picture()
    path = tmp_path / "plain.png"
    path.write_bytes(encoded(up, "PNG"))
    assert read_image(path)[1] is None and read_image(up)[1] is None
    assert_same_picture(read_image(path)[0], up, 1e-6)


TRUNCATED_IFD = b"Exif\x00\x00II*\x00\x08\x00\x00\x00\x01\x00\x12\x01\x03\x00\x01\x00\x00\x00"
BROKEN = {  # name: (format, EXIF bytes, phone-like JPEG, words the warning gives as the reason)
    "orientation 9": ("JPEG", exif_with(9), True, "orientation is 9, not one of 1-8"),
    "orientation 0": ("PNG", exif_with(0), False, "orientation is 0, not one of 1-8"),
    "not a TIFF block (JPEG)": ("JPEG", b"Exif\x00\x00garbage-not-tiff", False, "cannot be read"),
    "not a TIFF block (PNG)": ("PNG", b"Exif\x00\x00garbage-not-tiff", False, "cannot be read"),
    "truncated (JPEG)": ("JPEG", TRUNCATED_IFD, True, "corrupt"),
    "truncated (PNG)": ("PNG", TRUNCATED_IFD, False, "corrupt"),
}


@pytest.mark.parametrize("case", BROKEN)
def test_broken_exif_is_read_as_stored_with_a_warning(tmp_path, case):
    fmt, exif, phone_like, reason = BROKEN[case]
    stored = stored_as(upright_picture(), 6)  # stored turned: as stored, it stays turned
    path = tmp_path / f"broken.{fmt.lower()}"
    path.write_bytes(encoded(stored, fmt, exif, phone_like))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        got, entry = read_image(path)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1, messages  # ours, naming the file; not Pillow's nameless one
    assert messages[0].startswith(f"{path}: EXIF orientation ignored") and reason in messages[0]
    assert_same_picture(got, stored, JPEG_TOLERANCE if fmt == "JPEG" else 1e-6)
    assert entry["applied"] == "none" and reason in entry["ignored"]


def svg_size(svg: str) -> tuple[str, str]:
    root = re.search(r"<svg\b[^>]*>", svg).group(0)
    return re.search(r'\bwidth="([^"]+)"', root).group(1), re.search(r'\bheight="([^"]+)"', root).group(1)


def test_trace_of_a_phone_photo_is_upright_and_says_so(tmp_path):
    """A 120 x 80 picture stored as 80 x 120 with orientation 6: the SVG, the comparison
    picture and the report are 120 x 80, and the report names the rotation."""
    up = upright_picture(120, 80)
    photo = tmp_path / "phone.jpg"
    photo.write_bytes(encoded(stored_as(up, 6), "JPEG", exif_with(6), phone_like=True))
    assert Image.open(photo).size == (80, 120)
    svg, report = vecfit.trace(photo, output=tmp_path / "out.svg",
                               settings={"trace": {"paths": 8}, "optimize": {"iterations": 0, "threads": 1}})
    assert svg_size(svg) == ("120", "80")
    assert report["size"] == [120, 80]
    assert report["orientation"] == {"exif": 6, "applied": "rotate 90 CW"}
    on_disk = json.loads((tmp_path / "out.report.json").read_text())
    assert on_disk["orientation"] == report["orientation"]
    with Image.open(tmp_path / "out.compare.png") as im:
        target_panel = np.asarray(im.convert("RGB"))[:, :120]  # the first of the panels
    assert target_panel.shape == up.shape
    assert float(np.abs(as_float(target_panel) - as_float(up)).mean()) < JPEG_TOLERANCE

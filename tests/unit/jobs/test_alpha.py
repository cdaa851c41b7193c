"""A target's alpha, kept (issue 39): every format's alpha is read as the same straight
RGBA, and a traced SVG is transparent where the target is, its soft edges fitted: its
render, alpha included, scores >= 35 dB over white and over black."""
from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

import vecfit
from helpers import need
from shared_data import SHARED
from vecfit.fitting.metrics import compare
from vecfit.io.images import read_image
from vecfit.svg.document import SvgDocument
from vecfit.svg.read import scene_of

REALWORLD = SHARED / "realworld" / "cases"


def soft_disc(size=(64, 48)) -> np.ndarray:
    """uint8 RGBA: an orange disc with an anti-aliased rim (1.5 px) and a half-transparent
    blue bar, on a transparent page."""
    w, h = size
    y, x = np.mgrid[0:h, 0:w] + 0.5
    r = np.hypot(x - 24, y - 24)
    disc = np.clip((20 - r) / 1.5 + 0.5, 0, 1)
    bar = ((x > 40) & (x < 58) & (y > 8) & (y < 40)).astype(float) * 0.5
    alpha = disc + bar * (1 - disc)
    rgb = (np.array([230, 120, 30]) * disc[..., None] + np.array([30, 60, 200]) * (bar * (1 - disc))[..., None]) \
        / np.maximum(alpha, 1e-6)[..., None]
    return np.dstack([np.clip(rgb, 0, 255), alpha * 255]).round().astype(np.uint8)


def over(rgba: np.ndarray, colour: float) -> np.ndarray:
    return rgba[..., :3] * rgba[..., 3:] + colour * (1 - rgba[..., 3:])


def drawn(svg: str, w: int, h: int) -> np.ndarray:
    image = vecfit.render(scene_of(SvgDocument.parse(svg), for_writing=False), w, h, samples=4)
    return image.numpy() if hasattr(image, "numpy") else np.asarray(image)


def psnrs(svg: str, target: np.ndarray) -> tuple[float, float]:
    image = drawn(svg, target.shape[1], target.shape[0])
    return tuple(compare(over(image, c), over(target, c))["psnr"] for c in (1.0, 0.0))


def encoded(image: np.ndarray, fmt: str) -> bytes:
    buffer = io.BytesIO()
    pil = Image.fromarray(image, "RGBA")
    if fmt == "palette-png":  # a palette PNG with a transparent index (tRNS)
        pil.quantize(64, method=Image.Quantize.FASTOCTREE).save(buffer, format="PNG")
    elif fmt == "webp":
        pil.save(buffer, format="WEBP", lossless=True, exact=True)
    elif fmt == "premultiplied-tiff":
        # Pillow writes straight alpha (ExtraSamples 2); the colour premultiplied and the
        # tag set to 1 (associated alpha) make a premultiplied TIFF
        a = image[..., 3:].astype(np.float64) / 255
        pre = np.dstack([np.round(image[..., :3] * a), image[..., 3]]).astype(np.uint8)
        Image.fromarray(pre, "RGBA").save(buffer, format="TIFF")
        data = buffer.getvalue()
        tag = b"\x52\x01\x03\x00\x01\x00\x00\x00\x02\x00"
        assert data.count(tag) == 1
        return data.replace(tag, tag[:-2] + b"\x01\x00")
    else:
        pil.save(buffer, format=fmt.upper())
    return buffer.getvalue()


@pytest.mark.parametrize("fmt", ["png", "palette-png", "webp", "tiff", "premultiplied-tiff"])
def test_every_format_reads_as_straight_rgba(fmt):
    source = soft_disc()
    data = encoded(source, fmt)
    image, _ = read_image(data)
    expected = source.astype(np.float64) / 255
    if fmt == "palette-png":  # the palette's colours, its transparent index kept
        expected = np.asarray(Image.open(io.BytesIO(data)).convert("RGBA"), np.float64) / 255
        assert (image[..., 3] == 0).sum() > 0.3 * image[..., 3].size
    # straight: colour where alpha is 0 means nothing, so compare premultiplied
    tolerance = 2.5 / 255 if fmt == "premultiplied-tiff" else 1e-6
    assert np.abs(image[..., 3] - expected[..., 3]).max() < 1e-6
    assert np.abs(image[..., :3] * image[..., 3:] - expected[..., :3] * expected[..., 3:]).max() < tolerance


@pytest.mark.slow
def test_a_soft_edged_translucent_target_is_traced_with_its_alpha(tmp_path):
    source = soft_disc()
    svg, report = vecfit.trace(encoded(source, "png"), settings={"optimize": {"iterations": 250, "threads": 1}})
    target = source.astype(np.float64) / 255
    white, black = psnrs(svg, target)
    assert white >= 35 and black >= 35, (white, black)
    image = drawn(svg, 64, 48)
    assert image[:, :2, 3].max() < 0.02  # transparent where the target is
    # the anti-aliased rim is fitted, not thresholded: its alpha is in between
    rim = (target[..., 3] > 0.1) & (target[..., 3] < 0.9) & (np.arange(64)[None] < 40)
    assert rim.sum() > 50 and np.abs(image[..., 3][rim] - target[..., 3][rim]).mean() < 0.1
    assert ((image[..., 3][rim] > 0.05) & (image[..., 3][rim] < 0.95)).mean() > 0.5


@pytest.mark.slow
@pytest.mark.parametrize("name", ["noto-emoji-000", "noto-emoji-050"])
def test_transparent_realworld_renders_score_35_db_over_white_and_black(name):
    png = need(REALWORLD / f"{name}.png")
    target = np.asarray(Image.open(png).convert("RGBA"), np.float64) / 255
    assert target[..., 3].min() == 0
    # (benchmarks/palette.py, alpha: 40.4 / 42.7 and 42.9 / 40.8 dB over white / black)
    svg, _ = vecfit.trace(png, settings={"optimize": {"threads": 2}})
    white, black = psnrs(svg, target)
    assert white >= 35 and black >= 35, (white, black)

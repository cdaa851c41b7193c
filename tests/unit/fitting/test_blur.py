"""A target's blur estimated, and fitted through (vecfit/fitting/blur.py)."""
from __future__ import annotations

import tempfile
from pathlib import Path

import cv2
import numpy as np
import pytest
import torch
from PIL import Image

import vecfit
from vecfit.errors import VecfitError
from vecfit.fitting.blur import BLUR_FLOOR, estimate_blur, gaussian_blur
from vecfit.fitting.settings import Settings


def drawing(w: int = 128, h: int = 128) -> np.ndarray:
    """Dark lines and a ring, anti-aliased as a renderer draws them, RGB over white."""
    svg = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}"><g fill="none" stroke="#000000" '
           'stroke-width="8" stroke-linecap="round" stroke-linejoin="round"><path d="M14 16L112 24M14 112L44 46"/>'
           '<circle cx="86" cy="82" r="24"/></g></svg>')
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "d.svg").write_text(svg)
        scene = vecfit.load_svg(Path(tmp) / "d.svg")
        return vecfit.render(scene, w, h, samples=4, background=(1, 1, 1, 1)).numpy()[..., :3].astype(np.float32)


def test_a_render_reads_as_sharp_and_a_blurred_copy_as_its_blur():
    crisp = drawing()
    assert estimate_blur(crisp) < BLUR_FLOOR
    for sigma in (1.0, 1.5):
        assert abs(estimate_blur(cv2.GaussianBlur(crisp, (0, 0), sigma)) - sigma) < 0.15 * sigma + 0.1, sigma
    # 7-px lines blurred by 2.5: their two edges' ramps meet, and read as less blur, never more
    assert 1.5 < estimate_blur(cv2.GaussianBlur(crisp, (0, 0), 2.5)) < 2.5
    noisy = cv2.GaussianBlur(crisp, (0, 0), 1.0) + np.random.default_rng(0).normal(0, 0.03, crisp.shape).astype(np.float32)
    assert abs(estimate_blur(np.clip(noisy, 0, 1)) - 1.0) < 0.2
    assert estimate_blur(np.full((64, 64, 3), 0.5, np.float32)) == 0.0  # no edges: nothing to tell


def test_the_blur_is_cv2s_gaussian_and_keeps_the_ink():
    image = torch.from_numpy(drawing(64, 48))
    blurred = gaussian_blur(image, 1.3)
    assert blurred.shape == image.shape and torch.equal(gaussian_blur(image, 0.0), image)
    reference = cv2.GaussianBlur(image.numpy(), (0, 0), 1.3, borderType=cv2.BORDER_REPLICATE)
    assert np.abs(blurred.numpy() - reference).max() < 0.02
    assert abs(float(blurred.mean()) - float(image.mean())) < 1e-3


@pytest.mark.parametrize("bad", ["sharp", -0.5, 9.0, float("nan"), True])
def test_a_bad_target_blur_is_refused(bad):
    with pytest.raises(VecfitError, match="target_blur"):
        Settings.defaults(target_blur=bad)


@pytest.mark.slow
def test_a_blurred_drawing_is_fitted_as_the_sharp_one(tmp_path):
    """A scan's blur (sigma 1.2 px, noise) traced as strokes: fitted through the blur
    estimated from it, the lines come back sharp, closer to the clean drawing than a fit
    that takes the blur for the drawing (target_blur 0)."""
    crisp = drawing()
    scan = cv2.GaussianBlur(crisp, (0, 0), 1.2) + np.random.default_rng(1).normal(0, 0.02, crisp.shape).astype(np.float32)
    Image.fromarray((np.clip(scan, 0, 1) * 255 + 0.5).astype(np.uint8)).save(tmp_path / "scan.png")
    scores = {}
    for blur in ("auto", 0.0):
        svg, report = vecfit.trace(tmp_path / "scan.png", style="strokes", effort="quick", settings={
            "optimize": {"iterations": 40, "threads": 1, "target_blur": blur, "simplify": 0.0}})
        (tmp_path / "out.svg").write_text(svg)
        drawn = vecfit.render(vecfit.load_svg(tmp_path / "out.svg"), 128, 128, samples=4,
                              background=(1, 1, 1, 1)).numpy()[..., :3]
        scores[blur] = 10 * np.log10(1 / np.mean((drawn - crisp) ** 2))
        if blur == "auto":
            assert 1.0 <= report["config"]["optimize"]["target_blur"] <= 1.4
    assert scores["auto"] > scores[0.0] + 1.5, scores

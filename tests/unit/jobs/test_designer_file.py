"""What a designer finds in a traced file (issue 37): opaque colours on flat art, no
outline crossing itself on dense photo traces or emoji, short numbers; the report's
"file" counts are the file's own."""
from __future__ import annotations

import io
import re

import numpy as np
import pytest
from PIL import Image

import vecfit
from vecfit.svg.stats import design_stats

from helpers import need
from shared_data import SHARED


def small_photo(name: str, size: int) -> np.ndarray:
    import skimage.data

    photo = Image.fromarray(getattr(skimage.data, name)()).resize((size, size), Image.LANCZOS)
    return np.asarray(photo, np.float32) / 255


def emoji(name: str, size: int = 256) -> np.ndarray:
    import resvg_py

    png = resvg_py.svg_to_bytes(svg_path=str(need(SHARED / "realworld" / "cases" / f"{name}.svg")),
                                background="white", width=size)
    return np.asarray(Image.open(io.BytesIO(bytes(png))).convert("RGB"), np.float32) / 255


def decimals(svg: str) -> int:
    numbers = re.findall(r"-?\d+\.(\d+)", " ".join(re.findall(r' d="([^"]*)"', svg)))
    return max((len(n) for n in numbers), default=0)


@pytest.mark.slow
def test_dense_photo_trace_has_no_crossed_outline():
    svg, report = vecfit.trace(small_photo("astronaut", 160),
                               settings={"trace": {"paths": 600}, "optimize": {"iterations": 25, "seed": 2}})
    stats = design_stats(svg)
    assert report["file"] == stats  # the report counts the file it wrote
    assert stats["paths"] > 400 and stats["crossed_outlines"] == 0
    assert report["untangled_outlines"] > 0  # the fit did cross some, and they were cut
    assert decimals(svg) <= 2


@pytest.mark.slow
@pytest.mark.parametrize("name", ["noto-emoji-048", "fxemoji-016"])
def test_emoji_trace_is_opaque_simple_and_short(name):
    target = emoji(name)
    paths = design_stats(SHARED / "realworld" / "cases" / f"{name}.svg")["paths"]
    svg, report = vecfit.trace(target, settings={"trace": {"paths": paths}}, effort="quick")
    stats = report["file"]
    assert stats["translucent_paints"] == 0 and "opacity" not in svg
    assert stats["crossed_outlines"] == 0
    assert stats["paths"] <= paths + 1  # and the background rect
    assert decimals(svg) <= 2
    assert report["optimized"]["psnr"] >= 35  # measured 37.1 (noto-emoji-048) and 45+ (fxemoji-016) at 256 px

"""Stroked line art (Tabler icons of ../shared/lineart: stroke-width 2 in a 24 viewBox, round
caps and joins, arcs) renders as resvg's geometry converges: vecfit at 8x8 samples a pixel
(box filter) against resvg's own render at 8x the size, box-averaged to 256 px, is >= 50 dB
(measured 55-59 dB), and it draws as much ink as resvg's 256-px render (within 0.5%).

resvg's 256-px render itself, the benchmark's target, is only ~37-44 dB from that converged
image: its anti-aliasing steps coverage in quarter pixels. That is noise about the exact
coverage, with no bias in the width or place of a line (the ink agrees; a line widened by
2.5% or moved a sixteenth of a pixel scores lower against it, not higher), so a refinement
through vecfit's box-filtered render aims at the designer's geometry, and the designer's
file scores ~39 dB in vecfit's render against resvg's (benchmarks/lineart.py) only
because of resvg's anti-aliasing."""
from __future__ import annotations

import io
import warnings

import numpy as np
import pytest

from shared_data import SHARED

resvg = pytest.importorskip("resvg_py")
LINEART = SHARED / "lineart" / "cases"
ICONS = ["tabler-019", "tabler-037", "tabler-086"]  # arcs, an X, an arrow
SIZE = 256


def _resvg(path, width: int) -> np.ndarray:
    from PIL import Image
    png = bytes(resvg.svg_to_bytes(svg_path=str(path), width=width))
    rgba = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float64) / 255
    return rgba[..., :3] * rgba[..., 3:] + (1 - rgba[..., 3:])


def _psnr(a: np.ndarray, b: np.ndarray) -> float:
    return float(10 * np.log10(1 / np.mean((a - b) ** 2)))


@pytest.mark.slow
@pytest.mark.parametrize("name", ICONS)
def test_tabler_icon_renders_as_resvg_converges(name):
    import vecfit
    path = LINEART / f"{name}.svg"
    if not path.exists():
        pytest.skip(f"no {path} (../shared/lineart)")
    k = 8
    converged = _resvg(path, SIZE * k).reshape(SIZE, k, SIZE, k, 3).mean(axis=(1, 3))
    resvg_1x = _resvg(path, SIZE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(path)
    ours = vecfit.render(scene, SIZE, SIZE, samples=8, background=(1, 1, 1, 1)).numpy()[..., :3].astype(np.float64)
    assert _psnr(ours, converged) >= 50.0
    ink_ours, ink_resvg = (1 - ours).sum(), (1 - resvg_1x).sum()
    assert abs(ink_ours / ink_resvg - 1) < 0.005
    # resvg's 1x anti-aliasing, not vecfit, is what stands between the two at 1x
    assert _psnr(resvg_1x, converged) < _psnr(ours, converged) - 8

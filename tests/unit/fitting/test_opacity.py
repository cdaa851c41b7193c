"""Which colours' opacity a fit may change (vecfit/fitting/opacity.py, optimize.alpha)."""
from __future__ import annotations

import numpy as np
import pytest

import vecfit
from vecfit.fitting.opacity import has_translucent_areas, translucency_wanted
from vecfit.io.tone import flat_share


def disc(w=48, h=40, cx=24.3, cy=19.6, r=11.2, ss=8):
    """Anti-aliased coverage of a disc, ss x ss samples a pixel."""
    o = (np.arange(ss) + 0.5) / ss
    ys = (np.arange(h)[:, None] + o).ravel()
    xs = (np.arange(w)[:, None] + o).ravel()
    inside = ((xs[None, :] - cx) ** 2 + (ys[:, None] - cy) ** 2 < r * r).astype(np.float32)
    return inside.reshape(h, ss, w, ss).mean(axis=(1, 3))


def rgba(cov, rgb=(0.8, 0.2, 0.1), alpha=1.0, background=None):
    h, w = cov.shape
    out = np.zeros((h, w, 4), np.float32)
    if background is not None:
        out[..., :3] = background
        out[..., 3] = 1
    a = cov[..., None] * alpha
    out[..., :3] = out[..., :3] * (1 - a) + np.asarray(rgb, np.float32) * a
    out[..., 3] = out[..., 3] * (1 - a[..., 0]) + a[..., 0]
    return out


def test_an_anti_aliased_rim_is_not_translucency():
    assert not has_translucent_areas(disc())  # opaque disc on a clear canvas
    assert has_translucent_areas(0.5 * disc())  # a half-transparent disc
    shadow = disc() * 0.4
    shadow[disc(r=6) > 0] = 1.0  # an opaque core in a soft halo: the halo is translucent
    assert has_translucent_areas(shadow)


def test_a_shape_ending_in_the_canvas_edge_pixels_is_not_translucency():
    # A bar ending half-way into the last row and the first column, as logos-030's
    # letters do at 256 px: those partial pixels border the clear beyond the canvas.
    bar = np.zeros((40, 48), np.float32)
    bar[10:39, 1:30] = 1.0
    bar[39, 1:30] = bar[10:39, 0] = 0.5
    bar[39, 0] = 0.25
    assert not has_translucent_areas(bar)
    assert has_translucent_areas(0.5 * bar)


def test_flat_art_and_photographs_told_apart():
    flat = rgba(disc(), background=(1, 1, 1))
    assert flat_share(flat[..., :3]) > 0.85
    noise = np.random.default_rng(0).uniform(0, 1, (40, 48, 3)).astype(np.float32)
    assert flat_share(noise) < 0.05
    assert not translucency_wanted(flat, opaque=True)
    assert translucency_wanted(np.concatenate([noise, np.ones_like(noise[..., :1])], 2), opaque=True)
    assert translucency_wanted(rgba(disc(), alpha=0.5), opaque=False)
    assert not translucency_wanted(rgba(disc()), opaque=False)


def _written_opacities(svg: str) -> list[str]:
    import re
    return re.findall(r'(?:fill-opacity|stroke-opacity|opacity)="([^"]*)"', svg)


def _fit(target, svg, alpha):
    return vecfit.refine(target, svg, settings={"optimize": {"iterations": 30, "alpha": alpha, "seed": 1}})


SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="40">'
       '<circle id="c" cx="23" cy="20" r="9" fill="#3050c0"/></svg>')


def test_opaque_target_keeps_colours_opaque():
    target = rgba(disc(), background=(1, 1, 1))
    svg, report = _fit(target, SVG, "auto")
    assert _written_opacities(svg) == []
    svg, report = _fit(target, SVG, "free")  # alpha left free drifts off 1
    assert _written_opacities(svg) != []


def test_a_translucent_target_lets_alpha_change():
    target = rgba(disc(), alpha=0.5)
    svg, report = _fit(target, SVG, "auto")
    (value,) = _written_opacities(svg)
    assert 0.3 < float(value) < 0.95  # fitted towards the target's 0.5
    assert len(value) <= 5  # three decimals at most
    svg, report = _fit(target, SVG, "fixed")
    assert _written_opacities(svg) == []


def test_a_colour_translucent_in_the_input_stays_free():
    """Under auto, a shape the user drew at fill-opacity 0.6 keeps a free alpha, even over
    an opaque target: here the target's disc is fainter still, and the fit follows it."""
    target = rgba(disc(), rgb=(0.19, 0.31, 0.75), alpha=0.3, background=(1, 1, 1))
    faded = SVG.replace('fill="#3050c0"', 'fill="#3050c0" fill-opacity="0.6"')
    svg, report = _fit(target, faded, "auto")
    (value,) = _written_opacities(svg)
    assert float(value) < 0.55


@pytest.mark.parametrize("alpha", ["none", "", "opaque"])
def test_unknown_alpha_mode_refused(alpha):
    with pytest.raises(vecfit.VecfitError, match="alpha must be one of"):
        _fit(rgba(disc(), background=(1, 1, 1)), SVG, alpha)

"""A Scene of NumPy arrays packs by the same code as one of tensors (vecfit.scene.ops) into
the same arrays, and renders without torch (vecfit.renderer.forward.render_numpy) into
the image vecfit.render makes."""
from __future__ import annotations

import numpy as np
import pytest

from vecfit.renderer.forward import render_numpy
from vecfit.renderer.pack import pack_scene
from vecfit.renderer.raster import render
from vecfit.scene.arrays import numpy_arrays, to_numpy
from vecfit.svg.read import read_svg

SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="60" height="40" viewBox="0 0 120 80">'
       '<defs><linearGradient id="g" x1="0" x2="1"><stop offset="0" stop-color="#f00"/>'
       '<stop offset="1" stop-color="#00f" stop-opacity="0.5"/></linearGradient>'
       '<radialGradient id="r" gradientUnits="userSpaceOnUse" cx="90" cy="20" r="15">'
       '<stop offset="0" stop-color="#ff0"/><stop offset="1" stop-color="#0a0"/></radialGradient></defs>'
       '<rect width="120" height="80" fill="#eee"/>'
       '<g opacity="0.6" transform="rotate(10 60 40)"><rect x="10" y="10" width="40" height="30" rx="6" '
       'fill="url(#g)" stroke="#333" stroke-width="3"/><circle cx="35" cy="50" r="12" fill="#0c8"/></g>'
       '<ellipse cx="90" cy="20" rx="18" ry="12" fill="url(#r)" opacity="0.8"/>'
       '<path d="M60 70 C70 40 90 80 110 60 L115 75 Z" fill="#c60" stroke="#036" stroke-width="2" '
       'stroke-linejoin="round" transform="scale(1 0.9)"/>'
       '<path d="M5 75 Q30 60 55 75" fill="none" stroke="#909" stroke-width="4" stroke-dasharray="6 3"/>'
       '</svg>')


def _scenes(tmp_path):
    path = tmp_path / "scene.svg"
    path.write_text(SVG)
    with numpy_arrays():
        plain, _ = read_svg(path)
    tensors, _ = read_svg(path)
    return plain, tensors


def test_numpy_scene_packs_like_tensor_scene(tmp_path):
    plain, tensors = _scenes(tmp_path)
    a, b = pack_scene(plain, 60, 40).arrays(), pack_scene(tensors, 60, 40).arrays()
    assert a.keys() == b.keys()
    for name in a:
        assert isinstance(a[name], np.ndarray), name
        expected = to_numpy(b[name])
        assert a[name].dtype == expected.dtype and a[name].shape == expected.shape, name
        np.testing.assert_allclose(a[name], expected, rtol=1e-6, atol=1e-5, err_msg=name)
    assert len(a["draws"]) == 8 and len(a["paints"]) > 2  # every draw and both gradients packed


@pytest.mark.parametrize("samples", [1, 3])
def test_numpy_scene_renders_like_vecfit_render(tmp_path, samples):
    plain, tensors = _scenes(tmp_path)
    image = render_numpy(plain, samples=samples, seed=4)
    expected = render(tensors, samples=samples, seed=4).numpy()
    assert image.shape == (40, 60, 4)
    np.testing.assert_allclose(image, expected, atol=2e-5)
    assert image[..., 3].min() > 0.99  # the backdrop covers the canvas

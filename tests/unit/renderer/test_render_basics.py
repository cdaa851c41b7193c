"""Known values of the renderer: areas, colours, sizes, determinism."""
from __future__ import annotations

import numpy as np
import pytest
import torch

import vecfit
from helpers import brute_force, slow_unless
from vecfit.renderer.raster import output_size
from vecfit.scene import Circle, LinearGradient, Path, Rect, Scene, Shape, Solid


def square(x0, y0, x1, y1, color, **kw):
    g = Path(points=torch.tensor([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=torch.float32),
             degrees=np.array([1, 1, 1, 1]), subpaths=[(0, 4, True)])
    return Shape(geometry=g, fill=Solid(torch.tensor(color, dtype=torch.float32)), **kw)


def test_pixel_aligned_square_is_exact():
    img = vecfit.render(Scene(width=16, height=16, shapes=[square(4, 4, 12, 10, [1, 0, 0, 1])]))
    alpha = img[..., 3].numpy()
    assert alpha[4:10, 4:12].min() == 1 and alpha.sum() == 48
    assert np.allclose(img[4:10, 4:12, :3].numpy(), [1, 0, 0])


@pytest.mark.parametrize("mode,samples,tol", [("mc", 8, 0.01), ("analytic", 1, 0.01)])
def test_circle_area(mode, samples, tol):
    shape = Shape(geometry=Circle(torch.tensor([20.0, 20.0]), torch.tensor(12.3)),
                  fill=Solid(torch.tensor([0.0, 0.0, 1.0, 1.0])))
    img = vecfit.render(Scene(width=40, height=40, shapes=[shape]), samples=samples, mode=mode)
    assert float(img[..., 3].sum()) == pytest.approx(np.pi * 12.3 ** 2, rel=tol)


def test_half_transparent_over_opaque():
    shapes = [square(0, 0, 8, 8, [1, 0, 0, 1]), square(0, 0, 8, 8, [0, 0, 1, 0.5])]
    img = vecfit.render(Scene(width=8, height=8, shapes=shapes))
    assert np.allclose(img[4, 4].numpy(), [0.5, 0, 0.5, 1], atol=1e-6)


def test_background_and_straight_alpha():
    img = vecfit.render(Scene(width=8, height=8, shapes=[square(0, 0, 8, 8, [0, 0, 1, 0.5])]))
    assert np.allclose(img[2, 2].numpy(), [0, 0, 1, 0.5], atol=1e-6)  # straight, not premultiplied
    img = vecfit.render(Scene(width=8, height=8, shapes=[square(0, 0, 8, 8, [0, 0, 1, 0.5])]),
                        background=(1, 1, 1))
    assert np.allclose(img[2, 2].numpy(), [0.5, 0.5, 1, 1], atol=1e-6)


def test_linear_gradient_user_space():
    grad = LinearGradient(start=torch.tensor([0.0, 0.0]), end=torch.tensor([100.0, 0.0]),
                          offsets=torch.tensor([0.0, 1.0]),
                          colors=torch.tensor([[0.0, 0, 0, 1], [1.0, 1, 1, 1]]), units="userSpaceOnUse")
    shape = Shape(geometry=Rect(torch.tensor([0.0, 0.0]), torch.tensor([100.0, 4.0])), fill=grad)
    img = vecfit.render(Scene(width=100, height=4, shapes=[shape]), samples=1)
    xs = np.arange(100) + 0.5
    assert np.allclose(img[2, :, 0].numpy(), xs / 100, atol=0.01)


def test_group_opacity_is_a_layer():
    """Two overlapping opaque squares in a group of opacity 0.5: the overlap shows only the
    top square at half alpha (a layer), not the two blended."""
    from vecfit.scene import Group
    shapes = [square(0, 0, 6, 8, [1, 0, 0, 1], group=0), square(2, 0, 8, 8, [0, 0, 1, 1], group=0)]
    img = vecfit.render(Scene(width=8, height=8, shapes=shapes,
                              groups=[Group(opacity=torch.tensor(0.5))]))
    assert np.allclose(img[4, 4].numpy(), [0, 0, 1, 0.5], atol=1e-6)
    assert np.allclose(img[4, 0].numpy(), [1, 0, 0, 0.5], atol=1e-6)


def test_independent_of_thread_count_and_deterministic():
    shapes = [Shape(geometry=Circle(torch.tensor([30.0 + 7 * i, 20.0 + 5 * i]), torch.tensor(9.0 + i)),
                    fill=Solid(torch.tensor([i / 5, 0.5, 1 - i / 5, 0.7])),
                    stroke=Solid(torch.tensor([0.0, 0, 0, 1])), stroke_width=torch.tensor(1.5))
              for i in range(5)]
    scene = Scene(width=80, height=70, shapes=shapes)
    a = vecfit.render(scene, samples=3, seed=7, threads=1)
    b = vecfit.render(scene, samples=3, seed=7, threads=2)
    c = vecfit.render(scene, samples=3, seed=8, threads=2)
    assert torch.equal(a, b)
    assert not torch.equal(a, c)


def test_output_size_keeps_aspect():
    scene = Scene(width=200, height=100)
    assert output_size(scene, None, None) == (200, 100)
    assert output_size(scene, 301, None) == (301, 150)  # 150.5 rounds to even
    assert output_size(scene, None, 33) == (66, 33)


@pytest.mark.slow
@pytest.mark.parametrize("mode,samples,filter", [("mc", 2, "box"), ("mc", 3, "tent"), ("analytic", 2, "box")])
def test_tiles_match_brute_force(mode, samples, filter):
    """The per-tile segment lists and corner windings give exactly what testing every
    segment of every draw gives (tiger: fills with even-odd holes, thin strokes). In MC
    mode this also pins the CPU's draw-by-draw forward pass (tile_forward) to the
    sample-by-sample one (pixel_forward, which brute force runs), bit for bit."""
    import warnings
    from pathlib import Path as FilePath
    tiger = FilePath(__file__).resolve().parents[3] / "examples" / "tiger.svg"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(tiger)
    fast = vecfit.render(scene, 248, 255, samples=samples, mode=mode, filter=filter)
    with brute_force():
        brute = vecfit.render(scene, 248, 255, samples=samples, mode=mode, filter=filter)
    assert torch.equal(fast, brute)


def test_translucent_stack_matches_brute_force():
    """A dense translucent scene, as a fit of a photograph ends (small shapes, every one
    translucent, over a translucent page): no sample turns opaque, so the CPU's
    draw-by-draw forward pass visits each entry's samples by the pixel rows its draw's box
    reaches; the image is still the sample-by-sample one (pixel_forward, which brute force
    runs), bit for bit, and every shape shows through."""
    rng = np.random.default_rng(7)
    shapes = [square(-2, -2, 50, 42, [0.2, 0.3, 0.4, 0.999])]
    for _ in range(150):
        x, y = rng.uniform(-3, 47, 2)
        w, h = rng.uniform(0.7, 9, 2)
        shapes.append(square(x, y, x + w, y + h, [*rng.uniform(0, 1, 3), rng.uniform(0.3, 0.95)]))
    scene = Scene(width=48, height=40, shapes=shapes)
    for samples in (2, 3):
        fast = vecfit.render(scene, 48, 40, samples=samples, seed=3)
        with brute_force():
            brute = vecfit.render(scene, 48, 40, samples=samples, seed=3)
        assert torch.equal(fast, brute)
    # (no sample is opaque: the page's alpha shows in every pixel's)
    assert float(fast[..., 3].max()) < 1


@pytest.mark.parametrize("mode", slow_unless(["mc", "analytic"], ["mc"]))
def test_tiles_independent_of_thread_count(mode):
    """The tiles are binned by runs of draws on as many threads as the render has and
    joined in draw order: the image (whose compositing order and windings come from the
    tiles) is the one-thread image bit for bit, whatever the count (odd ones too)."""
    import warnings
    from pathlib import Path as FilePath
    tiger = FilePath(__file__).resolve().parents[3] / "examples" / "tiger.svg"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(tiger)
    one = vecfit.render(scene, 248, 255, samples=2, mode=mode, threads=1)
    for threads in (2, 3, 7):
        assert torch.equal(vecfit.render(scene, 248, 255, samples=2, mode=mode, threads=threads), one)

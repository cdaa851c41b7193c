"""vecfit.render_batch: B scenes in one call of the core equal B separate renders, images
and gradients, in both modes; bad batches are refused with a clear message."""
from __future__ import annotations

import numpy as np
import pytest
import torch

import vecfit
from vecfit.scene import LinearGradient, Path, Scene, Shape, Solid


def digit_like(seed: int, size: int = 32) -> Scene:
    """Three stroked cubics (one with round caps) and a translucent filled blob with a
    linear gradient: the parts a decoder's scene has, plus a fill."""
    rng = np.random.default_rng(seed)
    shapes = []
    for k in range(3):
        pts = torch.tensor(rng.uniform(4, size - 4, (4, 2)), dtype=torch.float32, requires_grad=True)
        shapes.append(Shape(geometry=Path(points=pts, degrees=np.array([3]), subpaths=[(0, 1, False)]),
                            stroke=Solid(torch.tensor(rng.uniform(0.1, 0.9, 4), dtype=torch.float32,
                                                      requires_grad=True)),
                            stroke_width=torch.tensor(float(rng.uniform(1, 3)), requires_grad=True),
                            linecap="round" if k == 0 else "butt"))
    c = rng.uniform(10, size - 10, 2)
    blob = torch.tensor(np.array([c + [-6, 0], c + [-6, -8], c + [6, -8], c + [6, 0], c + [6, 8], c + [-6, 8]]),
                        dtype=torch.float32, requires_grad=True)
    grad = LinearGradient(start=torch.tensor(c - 6, dtype=torch.float32, requires_grad=True),
                          end=torch.tensor(c + 6, dtype=torch.float32, requires_grad=True),
                          offsets=torch.tensor([0.0, 1.0]), units="userSpaceOnUse",
                          colors=torch.tensor([[0.9, 0.2, 0.1, 0.6], [0.1, 0.3, 0.9, 0.8]], requires_grad=True))
    shapes.insert(0, Shape(geometry=Path(points=blob, degrees=np.array([3, 1, 1]), subpaths=[(0, 3, True)]),
                           fill=grad))
    return Scene(width=size, height=size, shapes=shapes)


def leaves(scene: Scene) -> list[torch.Tensor]:
    return [t for kind in scene.parameters().values() for t in kind if t.requires_grad]


@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_batch_equals_separate_renders(mode):
    """Bit-identical images; gradients bit-identical too, since each scene of the batch runs
    on one thread as a threads=1 render does."""
    samples = 2 if mode == "mc" else 1
    seeds = [3, 4, 5, 6, 7]
    weight = torch.rand(len(seeds), 32, 32, 4, generator=torch.Generator().manual_seed(0))

    batch_scenes = [digit_like(s) for s in seeds]
    images = vecfit.render_batch(batch_scenes, 32, 32, samples=samples, mode=mode, seed=seeds,
                                 background=(1, 1, 1), threads=2, interior_samples=1)
    assert images.shape == (5, 32, 32, 4)
    (images * weight).sum().backward()

    for b, s in enumerate(seeds):
        scene = digit_like(s)
        image = vecfit.render(scene, 32, 32, samples=samples, mode=mode, seed=s, background=(1, 1, 1),
                              threads=1, interior_samples=1)
        assert torch.equal(image, images[b].detach())
        (image * weight[b]).sum().backward()
        got, want = leaves(batch_scenes[b]), leaves(scene)
        assert len(got) == len(want) > 0
        for g, w in zip(got, want):
            assert g.grad is not None and torch.isfinite(g.grad).all()
            assert torch.equal(g.grad, w.grad)
        assert any(bool((t.grad != 0).any()) for t in got)


def test_one_seed_for_all_and_no_grad():
    scenes = [digit_like(1), digit_like(2)]
    with torch.no_grad():
        images = vecfit.render_batch(scenes, 24, 20, seed=9)
    assert not images.requires_grad and images.shape == (2, 20, 24, 4)
    alone = vecfit.render(digit_like(2), 24, 20, seed=9)
    assert torch.equal(images[1], alone.detach())


def test_bad_batches_are_refused():
    with pytest.raises(vecfit.VecfitError, match="at least one scene"):
        vecfit.render_batch([], 8, 8)
    with pytest.raises(vecfit.VecfitError, match="2 seeds for 1 scenes"):
        vecfit.render_batch([digit_like(0)], 8, 8, seed=[1, 2])
    with pytest.raises(vecfit.VecfitError, match="mode"):
        vecfit.render_batch([digit_like(0)], 8, 8, mode="exact")
    bad = digit_like(0)
    with torch.no_grad():
        bad.shapes[1].geometry.points[0, 0] = float("nan")
    with pytest.raises(vecfit.VecfitError, match="non-finite"):
        vecfit.render_batch([digit_like(1), bad], 8, 8)

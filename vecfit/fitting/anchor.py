"""Keeping what an edit did not touch in place (`vecfit edit`): which parameter elements
act on a region of the image, and a penalty on moving the others.

Which elements act on the region is asked of the renderer itself: the gradient of a
randomly weighted sum of the region's pixels is non-zero exactly for the elements that
change those pixels (a point whose segments cross the region, the colour of a shape
seen there, ...), whatever the element's kind, transforms or paint. The random weights
keep two changes from cancelling (an edge between two colours of equal sum)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from vecfit.renderer.raster import render
from vecfit.scene import Path, Scene

from .rates import LENGTH_KINDS, learning_rate_scales

NEIGHBOURS = 3  # points of a path this close (in index) to a free point are free too


@dataclass
class Anchors:
    """The penalty's terms: (tensor, its initial value, coefficient per element)."""
    terms: list
    free: int      # elements free to move (they act on the region)
    anchored: int  # elements held in place by the penalty

    def __call__(self) -> torch.Tensor:
        total = torch.zeros(())
        for t, start, coef in self.terms:
            total = total + (coef * (t - start) ** 2).sum()
        return total


def acting_on(scene: Scene, region: np.ndarray, kinds: list[str], *, samples: int = 2,
              boundary_samples: float = 8.0, seed: int = 0, threads: int = 0,
              background=None, device: str = "cpu") -> dict[int, torch.Tensor]:
    """id(tensor) -> bool tensor of its shape: whether the element changes the pixels where
    ``region`` ([H, W] bool, at the size to render) is True. For the tensors of ``kinds``."""
    h, w = region.shape
    tensors = [t for kind in kinds for t in scene.parameters()[kind]]
    for t in tensors:
        t.requires_grad_(True)
        t.grad = None
    try:
        weights = torch.from_numpy(np.random.default_rng(seed).uniform(0.5, 1.5, (h, w, 4)).astype(np.float32))
        weights *= torch.from_numpy(region.astype(np.float32))[..., None]
        image = render(scene, w, h, samples=samples, seed=seed, background=background, threads=threads,
                       boundary_samples=boundary_samples, device=device)
        out = {id(t): torch.zeros(t.shape, dtype=torch.bool) for t in tensors}
        if image.requires_grad:
            (weights * image).sum().backward()
            for t in tensors:
                if t.grad is not None:
                    out[id(t)] = t.grad.detach() != 0
    finally:
        for t in tensors:
            t.requires_grad_(False)
            t.grad = None
    # A short segment may draw no boundary sample: the points next to a free point of the
    # same path are free too.
    for shape in scene.shapes:
        g = shape.geometry
        if isinstance(g, Path) and id(g.points) in out:
            free = out[id(g.points)].any(dim=1).numpy()
            if free.any():
                grown = free.copy()
                for k in range(1, min(NEIGHBOURS, len(free) - 1) + 1):
                    grown[k:] |= free[:-k]
                    grown[:-k] |= free[k:]
                out[id(g.points)] = torch.from_numpy(grown)[:, None].expand(g.points.shape).clone()
    return out


def anchors(scene: Scene, free: dict[int, torch.Tensor], kinds: list[str], held: float, loose: float,
            loose_colors: float, width: int, height: int, channels: int) -> Anchors:
    """The penalty: per element, ``held`` (for one that does not act on the region) or
    ``loose`` / ``loose_colors`` (a length / a colour or offset that does) x its squared
    change, lengths in pixels of the optimised image (``width`` x ``height``), colours and
    offsets as they are; divided by the number of values the loss averages (pixels x
    ``channels``), so a weight of 1 makes moving an element by a pixel cost as much as one
    channel of one pixel wrong by 1.

    The loose weights are small: they only keep an element that the image barely
    constrains (an occluded control point, a colour seen in a few pixels, whose tiny
    gradient Adam would turn into full-rate steps) from wandering."""
    scales = learning_rate_scales(scene, width, height)  # units per pixel
    per_value = 1.0 / (width * height * channels)
    terms, n_free, n_held = [], 0, 0
    for kind in kinds:
        length = kind in LENGTH_KINDS
        for t in scene.parameters()[kind]:
            acts = free.get(id(t), torch.zeros(t.shape, dtype=torch.bool))
            n_free += int(acts.sum())
            n_held += int((~acts).sum())
            weight = torch.where(acts, loose if length else loose_colors, held) * per_value
            if not bool((weight > 0).any()):
                continue
            unit = scales.get(id(t), 1.0) if length else 1.0
            terms.append((t, t.detach().clone(), weight / unit ** 2))
    return Anchors(terms, n_free, n_held)

"""Gradients where a boundary lies exactly on a line the renderer decides on: the canvas
border, a line between pixels, a pixel centre (DESIGN.md, "An edge on the canvas border
is a kink" and "Analytical prefilter").

- Monte Carlo: a boundary sample's change is at p+, just outside the boundary; it counts
  only where p+ is on the canvas (so an edge on the border facing out counts for nothing,
  on all four sides), for the pixels whose half-open support holds p (on a line: the pixel
  on its +x / +y side). Neither decision is taken at rounding level: moving the geometry
  a sample point by a few ulps (double) changes neither. Rounding is what differed between
  the CPU and a GPU (nvcc's fused multiply-adds round a sample point differently: tiger's
  background rect got 5.29, -1.69, ... on one and 0 on the other), and what these tests
  catch without one (the pixel rule is the core's own function, through a test hook).
- Analytical: a pixel centre exactly on an edge takes the edge's normal; on a vertex, half
  of each segment's (the central derivative of the kink).
Cost: about 3 s.
"""
from __future__ import annotations

import numpy as np
import pytest
import torch

import vecfit
from vecfit.scene import Path, Rect, Scene, Shape, Solid

SIZE = 20


def rect_path(x0, y0, x1, y1):
    pts = torch.tensor([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=torch.float32)
    return Path(points=pts, degrees=np.array([1, 1, 1, 1]), subpaths=[(0, 4, True)])


def weights(seed=0):
    """Random weights, not zero on the border: the border pixels are what is tested."""
    return torch.rand(SIZE, SIZE, 4, generator=torch.Generator().manual_seed(seed))


def mc_grad(shapes, moved, offset=(0.0, 0.0), seed=0):
    """dL/d(points of shapes[moved]) with its points moved by offset (L = sum W image)."""
    shapes = list(shapes)
    g = shapes[moved].geometry
    pts = (g.points.detach() + torch.tensor(offset)).requires_grad_(True)
    shapes[moved] = Shape(geometry=Path(points=pts, degrees=g.degrees, subpaths=g.subpaths), fill=shapes[moved].fill)
    img = vecfit.render(Scene(width=SIZE, height=SIZE, shapes=shapes), SIZE, SIZE, samples=4, seed=seed,
                        boundary_samples=16, background=(1, 1, 1))
    (img * weights()).sum().backward()
    return pts.grad


def test_canvas_sized_rect_under_its_twin_gets_no_gradient():
    """Tiger's first two paths: a black canvas-sized rect under a white one of the same
    geometry. Moving the black one's edges outwards or inwards changes no pixel (off the
    canvas, or under the white one): its gradient is 0 exactly, at the border and one
    float32 ulp either side of it (CPU and GPU once disagreed here: 5.29, -1.69, ... against 0)."""
    ulp = float(np.spacing(np.float32(SIZE)))
    for offset in (0.0, ulp, -ulp):
        shapes = [Shape(geometry=rect_path(0, 0, SIZE, SIZE), fill=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0]))),
                  Shape(geometry=rect_path(0, 0, SIZE, SIZE), fill=Solid(torch.tensor([1.0, 1.0, 1.0, 1.0])))]
        grad = mc_grad(shapes, 0, (offset, offset))
        assert torch.count_nonzero(grad) == 0, f"offset {offset}: {grad}"


@pytest.mark.parametrize("side", ["left", "right", "top", "bottom"])
def test_edge_on_the_border_facing_in(side):
    """A black rect just off the canvas whose edge lies on the border, facing in. The image
    has a kink there; the gradient is the one-sided derivative towards +x / +y, as for an
    edge on a line between pixels: on the left and top, moving the rect that way darkens
    the border column or row at rate 1 per pixel of the box filter (minus the sum of W's
    red, green and blue there); on the right and bottom it moves off the canvas: 0. The
    same one float32 ulp further along +x / +y (the derivative is the one towards there)."""
    E = SIZE + 10
    box = {"left": (-10, -5, 0, E), "right": (SIZE, -5, E, E), "top": (-5, -10, E, 0), "bottom": (-5, SIZE, E, E)}[side]
    axis = {"left": (1, 0), "right": (1, 0), "top": (0, 1), "bottom": (0, 1)}[side]
    W = weights()
    border = {"left": W[:, 0], "right": W[:, -1], "top": W[0], "bottom": W[-1]}[side]
    expected = -float(border[:, :3].sum()) if side in ("left", "top") else 0.0
    ulp = float(np.spacing(np.float32(SIZE)))
    for offset in (0.0, ulp):
        shapes = [Shape(geometry=rect_path(*box), fill=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0])))]
        grad = mc_grad(shapes, 0, (offset, offset))
        along = float((grad @ torch.tensor(axis, dtype=torch.float32)).sum())
        assert abs(along - expected) <= 0.03 * abs(expected), f"offset {offset}: {along} vs {expected}"


def ulps(x, k):
    for _ in range(abs(k)):
        x = float(np.nextafter(x, np.inf if k > 0 else -np.inf))
    return x


@pytest.mark.parametrize("R", [0.5, 1.0])
def test_boundary_pixels_are_not_decided_by_rounding(R):
    """The core's pixel rule for a boundary sample (the function both devices run), at
    points on pixel lines, pixel centres and the canvas border, each moved by up to 4
    ulps: the pixels must not change. Then the rule itself on the border, box filter."""
    pixels = vecfit._core.boundary_pixels
    for x, y in [(0.0, 5.0), (20.0, 5.0), (5.0, 0.0), (5.0, 20.0), (7.0, 9.0), (7.5, 9.5), (0.0, 0.0), (20.0, 20.0)]:
        for n in [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0), (0.6, -0.8)]:
            want = sorted(pixels((x, y), n, R, SIZE, SIZE))
            for kx in range(-4, 5):
                for ky in (-4, 0, 4):
                    got = sorted(pixels((ulps(x, kx), ulps(y, ky)), n, R, SIZE, SIZE))
                    assert got == want, f"p = ({x}, {y}) + ({kx}, {ky}) ulps, n = {n}: {got} vs {want}"
    if R == 0.5:
        assert pixels((0.0, 5.5), (-1.0, 0.0), R, SIZE, SIZE) == []            # on the left border facing out
        assert pixels((0.0, 5.5), (1.0, 0.0), R, SIZE, SIZE) == [(0, 5)]       # facing in
        assert pixels((20.0, 5.5), (1.0, 0.0), R, SIZE, SIZE) == []            # right border facing out
        assert pixels((20.0, 5.5), (-1.0, 0.0), R, SIZE, SIZE) == []           # facing in: the +x side is off
        assert pixels((7.0, 5.5), (-1.0, 0.0), R, SIZE, SIZE) == [(7, 5)]      # a pixel line: its +x side
        assert pixels((7.0, 5.5), (1.0, 0.0), R, SIZE, SIZE) == [(7, 5)]


def test_analytic_fill_with_pixel_centres_on_its_edges():
    """45-degree edges through integer points pass through pixel centres, as in mcseem2;
    there the direction to the closest point is 0/0. Fig. 9 (move right) at a small step."""
    pts = torch.tensor([[3.0, 10.0], [10.0, 3.0], [17.0, 10.0], [10.0, 17.0]])
    W = weights(1)

    def loss(dx):
        path = Path(points=pts + torch.stack([dx, torch.zeros_like(dx)]), degrees=np.array([1, 1, 1, 1]),
                    subpaths=[(0, 4, True)])
        shapes = [Shape(geometry=path, fill=Solid(torch.tensor([0.2, 0.5, 0.9, 1.0])))]
        img = vecfit.render(Scene(width=SIZE, height=SIZE, shapes=shapes), SIZE, SIZE, samples=1, mode="analytic",
                            background=(1, 1, 1))
        return (img.double() * W.double()).sum()

    dx = torch.tensor(0.0, requires_grad=True)
    loss(dx).backward()
    h = 1e-3
    with torch.no_grad():
        fd = float(loss(torch.tensor(h)) - loss(torch.tensor(-h))) / (2 * h)
    assert abs(dx.grad.item() - fd) <= 0.01 * abs(fd), (dx.grad.item(), fd)


@pytest.mark.parametrize("samples", [1, 2])
def test_analytic_rect_edges_on_sample_centres_and_pixel_lines(samples):
    """Each edge coordinate of a rect against central differences, analytical mode, with
    edges through sample centres (within ON_EDGE) and on a pixel line. Across one edge the
    signed distance is linear (-+|d|, the sign flipping where |d| kinks), so the edge's
    inward normal is its derivative from either side. On a corner it is a kink, the max of
    the two edges' signed distances, whose central derivative is the mean of the two: the
    corners (4 + c, 3 + c) and (4 + c, 12 + c) lie on sample centres, and with one segment
    taken (before) p_min.x was 8.04 against 9.26 by differences at 1x1. On the pixel line
    the edge is one kernel radius from the centres, where the kernel's slope is 0: gradient
    and differences are both about 0."""
    c = 0.5 / samples  # a sample centre's offset from the pixel corner
    lo = torch.tensor([4.0 + c, 3.0 + c])     # through sample centres
    hi = torch.tensor([15.0, 12.0 + c])       # x on a pixel line, y through sample centres
    W = weights(2)

    def loss(p_min, p_max):
        shapes = [Shape(geometry=Rect(p_min=p_min, p_max=p_max), fill=Solid(torch.tensor([0.2, 0.5, 0.9, 1.0])))]
        img = vecfit.render(Scene(width=SIZE, height=SIZE, shapes=shapes), SIZE, SIZE, samples=samples,
                            mode="analytic", background=(1, 1, 1))
        return (img.double() * W.double()).sum()

    p_min, p_max = lo.clone().requires_grad_(True), hi.clone().requires_grad_(True)
    loss(p_min, p_max).backward()
    got = torch.cat([p_min.grad, p_max.grad]).double()
    h = 1e-3
    fd = []
    for k in range(4):
        e = torch.zeros(4)
        e[k] = h
        with torch.no_grad():
            fd.append(float(loss(lo + e[:2], hi + e[2:]) - loss(lo - e[:2], hi - e[2:])) / (2 * h))
    fd = torch.tensor(fd, dtype=torch.float64)
    scale = float(fd.abs().max())
    assert scale > 1  # the edges through sample centres move pixels
    assert torch.allclose(got, fd, atol=0.01 * scale), (got, fd)

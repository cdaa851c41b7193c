"""Shape geometry in a shape's own space: rects as paths, bounding boxes, the control
points of a path's segments. In torch, differentiable where the renderer needs it (rect
corners and radii reach the core as path points); rects as paths and the placement in
NumPy too, for a Scene of NumPy arrays (ops.py). The rest computes in torch (imported
when first needed)."""
from __future__ import annotations

import numpy as np

from .arrays import as_torch, is_tensor
from .model import Circle, Ellipse, Path, Rect
from .ops import ops_for

KAPPA = 0.5522847498307936  # cubic approximation of a quarter ellipse


def value(t) -> float:
    """A tensor's value as a float, outside the autograd graph (for decisions only)."""
    if is_tensor(t):
        return float(t.detach())
    return float(np.asarray(t).reshape(())) if isinstance(t, np.ndarray) else float(t)


def affine_apply(m, p):
    """Apply a 3x3 affine matrix to points [n, 2]."""
    return p @ m[:2, :2].T + m[:2, 2]


def rect_path(rect: Rect) -> tuple:
    """A rect as a closed path: four lines, with quarter-ellipse cubics for round corners."""
    stack = ops_for(rect.p_min).stack
    x0, y0 = rect.p_min[0], rect.p_min[1]
    x1, y1 = rect.p_max[0], rect.p_max[1]
    rx, ry = rect.corner_radii[0], rect.corner_radii[1]
    if value(rx) <= 0 or value(ry) <= 0:
        pts = stack([stack([x0, y0]), stack([x1, y0]), stack([x1, y1]), stack([x0, y1])])
        return pts, [1, 1, 1, 1]
    kx, ky = KAPPA * rx, KAPPA * ry
    P = lambda x, y: stack([x, y])  # noqa: E731
    pts = [
        P(x0 + rx, y0), P(x1 - rx, y0),
        P(x1 - rx + kx, y0), P(x1, y0 + ry - ky), P(x1, y0 + ry),
        P(x1, y1 - ry),
        P(x1, y1 - ry + ky), P(x1 - rx + kx, y1), P(x1 - rx, y1),
        P(x0 + rx, y1),
        P(x0 + rx - kx, y1), P(x0, y1 - ry + ky), P(x0, y1 - ry),
        P(x0, y0 + ry),
        P(x0, y0 + ry - ky), P(x0 + rx - kx, y0),  # closing cubic ends at the start point
    ]
    return stack(pts), [1, 3, 1, 3, 1, 3, 1, 3]


def local_bbox(geometry) -> tuple | None:
    """Tight bounds (min, max) of the geometry in its local space, for bounding-box units
    (of a NumPy geometry: computed in torch, given back as NumPy)."""
    import torch
    if not isinstance(geometry, Rect) and not is_tensor(getattr(geometry, "points", getattr(geometry, "center", None))):
        box = local_bbox(as_torch(geometry))
        return None if box is None else (box[0].numpy(), box[1].numpy())
    if isinstance(geometry, (Circle, Ellipse)):
        r = geometry.radius.expand(2) if isinstance(geometry, Circle) else geometry.radii
        return geometry.center - r, geometry.center + r
    if isinstance(geometry, Rect):
        return geometry.p_min, geometry.p_max
    # Curves sampled at 33 parameters, all the segments of a degree at once (segment by
    # segment, a 30,000-segment path took a second here).
    t = torch.linspace(0, 1, 33, dtype=torch.float32)[:, None]
    u = 1 - t
    bernstein = {1: torch.tensor([[1.0, 0.0], [0.0, 1.0]]), 2: torch.cat([u * u, 2 * u * t, t * t], dim=1),
                 3: torch.cat([u ** 3, 3 * u * u * t, 3 * u * t * t, t ** 3], dim=1)}
    samples = []
    for d, index in _control_indices(geometry).items():
        ctrl = geometry.points[torch.from_numpy(index)]  # [m, d + 1, 2]
        samples.append(torch.einsum("sk,mkc->msc", bernstein[d].to(ctrl.dtype), ctrl).reshape(-1, 2))
    if not samples:
        return None
    allp = torch.cat(samples)
    return allp.min(dim=0).values, allp.max(dim=0).values


def _control_indices(path: Path) -> dict[int, np.ndarray]:
    """Degree -> [m, degree + 1] indices into path.points of each such segment's control points."""
    out: dict[int, list] = {}
    for (first, count, closed), (p0, n) in zip(path.subpaths, path.subpath_point_ranges()):
        degrees = np.asarray(path.degrees[first:first + count], dtype=np.int64)
        starts = np.concatenate([[0], np.cumsum(degrees)[:-1]]) if len(degrees) else degrees
        for d in (1, 2, 3):
            k = starts[degrees == d]
            if len(k):
                idx = k[:, None] + np.arange(d + 1)
                out.setdefault(d, []).append(p0 + (idx % n if closed else idx))
    return {d: np.concatenate(v) for d, v in out.items()}


def path_segments(path: Path):
    """Per subpath: (list of control-point tensors per segment, degrees)."""
    for (first, count, closed), (p0, n) in zip(path.subpaths, path.subpath_point_ranges()):
        pts = path.points[p0:p0 + n]
        degrees = [int(d) for d in path.degrees[first:first + count]]
        ctrl, k = [], 0
        for d in degrees:
            idx = [(k + i) % n if closed else k + i for i in range(d + 1)]
            ctrl.append(pts[idx])
            k += d
        yield ctrl, degrees


def rect_as_path(rect: Rect) -> Path | None:
    if value(rect.p_max[0] - rect.p_min[0]) <= 0 or value(rect.p_max[1] - rect.p_min[1]) <= 0:
        return None
    pts, degrees = rect_path(rect)
    return Path(points=pts, degrees=np.array(degrees), subpaths=[(0, len(degrees), True)])


def ellipse_as_path(geometry: Circle | Ellipse) -> Path | None:
    """A circle or an ellipse as a closed path of four quarter-ellipse cubics, from
    (cx + rx, cy) through (cx, cy + ry) (SVG 2's start point and direction, as resvg),
    differentiable in the centre and radii; None when a radius is not positive."""
    import torch
    r = geometry.radius.reshape(1).expand(2) if isinstance(geometry, Circle) else geometry.radii
    if value(r.min()) <= 0:
        return None
    c = geometry.center.reshape(2)
    rx, ry = r[0], r[1]
    k = KAPPA
    unit = torch.tensor([[1, 0], [1, k], [k, 1], [0, 1], [-k, 1], [-1, k], [-1, 0],
                         [-1, -k], [-k, -1], [0, -1], [k, -1], [1, -k]], dtype=c.dtype)
    pts = c + unit * torch.stack([rx, ry]).to(c.dtype)
    return Path(points=pts, degrees=np.array([3, 3, 3, 3]), subpaths=[(0, 4, True)])



def local_bbox_size(geometry) -> float | None:
    """Geometric mean of the geometry's bounding-box sides (for bounding-box units)."""
    import torch
    with torch.no_grad():
        box = local_bbox(geometry)
    if box is None:
        return None
    size = (box[1] - box[0]).double()
    return float(torch.sqrt(torch.clamp(size[0], min=0) * torch.clamp(size[1], min=0)))

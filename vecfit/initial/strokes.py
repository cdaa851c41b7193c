"""Painterly rendering (Li et al. 2020, section 6.3): random strokes or closed shapes fitted
to a target with the shared optimisation loop. This module makes the random initial SVG,
re-seeds primitives that stopped contributing, and saves frames of the optimisation.

Re-seeding: every ``reseed_every`` iterations (not in the last fifth of the run, so the
final shapes settle), a primitive that has left the canvas, faded below ``reseed_alpha``
or thinned below ``reseed_width`` pixels is placed anew where the current error is
largest: a pixel is drawn with probability proportional to the squared error (blurred,
so a region of error beats a lone noisy pixel), the primitive is rebuilt around it with
the target's colour there, and the error around that spot is cleared before the next draw
so that several re-seeds do not land on one place.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np
import torch

from vecfit.errors import VecfitError
from vecfit.io.configs import defaults
from vecfit.names import PAINT_KINDS
from vecfit.scene import Path as PathGeometry
from vecfit.svg.document import SvgDocument
from vecfit.svg.pathdata import format_path_data


@dataclass
class PaintSettings:
    paths: int
    kind: str
    stroke_segments: int     # strokes: 1 to this many cubic segments
    shape_segments_min: int  # shapes: closed paths of min..max cubic segments
    shape_segments_max: int
    min_width: float         # stroke widths drawn uniformly in [min, max] pixels
    max_width: float
    radius: float            # control-point spread, as a fraction of the longer side
    reseed_every: int        # 0: never re-seed
    reseed_alpha: float
    reseed_width: float
    frames_every: int
    seed: int

    @classmethod
    def defaults(cls, **changes) -> "PaintSettings":
        """The defaults of configs/paint.toml ([paint], and [optimize]'s seed), with ``changes``."""
        table = {**defaults("paint", "paint"), "seed": defaults("paint", "optimize")["seed"]}
        return cls(**{**table, **changes})

    def check(self) -> None:
        if self.kind not in PAINT_KINDS:
            raise VecfitError(f"kind must be one of {', '.join(PAINT_KINDS)}, not {self.kind!r}")
        if self.paths < 1:
            raise VecfitError("paths must be at least 1")
        if self.stroke_segments < 1 or not 1 <= self.shape_segments_min <= self.shape_segments_max:
            raise VecfitError("segment counts must be at least 1 (and min <= max)")
        if not 0 <= self.min_width <= self.max_width:
            raise VecfitError("stroke widths need 0 <= min_width <= max_width")
        if not self.radius > 0:
            raise VecfitError("radius must be positive")


# ----------------------------------------------------------------- initial SVG

def _color(rgb, alpha) -> str:
    r, g, b = (int(round(float(c) * 255)) for c in rgb)
    return f"rgba({r},{g},{b},{float(alpha):.3f})"


def _stroke_points(rng, center, segments, spread) -> np.ndarray:
    """A random walk of 3 * segments + 1 control points starting at center."""
    steps = rng.uniform(-0.5, 0.5, size=(3 * segments, 2)) * spread
    return np.vstack([center, center + np.cumsum(steps, axis=0)])


def _shape_points(rng, center, segments, spread) -> np.ndarray:
    """3 * segments control points of a closed blob around center (angles sorted so the
    outline does not start out tangled)."""
    n = 3 * segments
    angles = np.sort(rng.uniform(0, 2 * math.pi, n))
    radii = spread * rng.uniform(0.25, 0.5, n)
    return center + np.stack([np.cos(angles) * radii, np.sin(angles) * radii], axis=1)


def _path_data(points: np.ndarray, closed: bool) -> str:
    """Cubics through ``points`` (3 per segment after the start); closed: the last cubic
    returns to the start, then Z (a closing line of zero length, as the reader makes)."""
    cubics = (len(points) if closed else len(points) - 1) // 3
    if closed:
        points = np.vstack([points, points[:1]])
        spans, degrees = [(0, cubics + 1, True)], [3] * cubics + [1]
    else:
        spans, degrees = [(0, cubics, False)], [3] * cubics
    return format_path_data(points, degrees, spans, decimals=2)


def initial_document(target: np.ndarray, settings: PaintSettings) -> SvgDocument:
    """Random primitives over the canvas of ``target`` ([H, W, 4]); colours are random,
    as in the paper (the optimisation finds the right ones)."""
    settings.check()
    h, w = target.shape[:2]
    rng = np.random.default_rng(settings.seed)
    spread = settings.radius * max(w, h)
    document = SvgDocument.new(w, h)
    for i in range(settings.paths):
        center = rng.uniform([0, 0], [w, h])
        rgb, alpha = rng.uniform(0, 1, 3), rng.uniform(0.3, 1.0)
        if settings.kind == "strokes":
            pts = _stroke_points(rng, center, int(rng.integers(1, settings.stroke_segments + 1)), spread)
            width = rng.uniform(settings.min_width, settings.max_width)
            document.add("path", {"id": f"s{i}", "d": _path_data(pts, False), "fill": "none",
                                  "stroke": _color(rgb, alpha), "stroke-width": f"{width:.2f}",
                                  "stroke-linecap": "round", "stroke-linejoin": "round"})
        else:
            segs = int(rng.integers(settings.shape_segments_min, settings.shape_segments_max + 1))
            pts = _shape_points(rng, center, segs, spread)
            document.add("path", {"id": f"s{i}", "d": _path_data(pts, True), "fill": _color(rgb, alpha)})
    return document


# --------------------------------------------------------------------- re-seeding

@dataclass
class Reseeder:
    """An optimisation hook (vecfit.fitting.loop.Step) that re-seeds wasted primitives."""
    settings: PaintSettings
    iterations: int
    reseeded: int = 0
    history: list = field(default_factory=list)  # (iteration, count)

    def __post_init__(self):
        self.rng = np.random.default_rng(self.settings.seed + 1)

    def __call__(self, step) -> None:
        every = self.settings.reseed_every
        if every <= 0 or (step.iteration + 1) % every or step.iteration + 1 > 0.8 * self.iterations:
            return
        scene = step.scene
        wasted = [s for s in scene.shapes if self._wasted(s, scene.width, scene.height)]
        if not wasted:
            return
        error = self._error_map(step)
        sh, sw = error.shape
        to_units = scene.width / sw
        goal = step.target.image.numpy()
        spread = self.settings.radius * max(scene.width, scene.height)
        for shape in wasted:
            flat = error.reshape(-1)
            total = float(flat.sum())
            if total <= 0:
                break
            k = int(self.rng.choice(flat.size, p=flat / total))
            y, x = divmod(k, sw)
            center = np.array([(x + 0.5) * to_units, (y + 0.5) * to_units])
            self._rebuild(shape, center, goal[y, x, :3], spread, step.reset)
            r = max(1, int(round(spread / to_units)))
            error[max(0, y - r):y + r + 1, max(0, x - r):x + r + 1] = 0
            self.reseeded += 1
        self.history.append((step.iteration + 1, len(wasted)))

    def _wasted(self, shape, width, height) -> bool:
        g = shape.geometry
        if not isinstance(g, PathGeometry):
            return False
        p = g.points.detach()
        outside = bool((p[:, 0].max() < 0) | (p[:, 0].min() > width) | (p[:, 1].max() < 0)
                       | (p[:, 1].min() > height))
        paint = shape.stroke if shape.stroke is not None else shape.fill
        alpha = float(paint.color[3]) * float(shape.opacity) if hasattr(paint, "color") else 1.0
        thin = shape.stroke is not None and float(shape.stroke_width) < self.settings.reseed_width
        return outside or alpha < self.settings.reseed_alpha or thin

    @staticmethod
    def _error_map(step) -> np.ndarray:
        diff = step.target.compared(step.image) - step.target.compared(step.target.image)
        err = (diff.numpy() ** 2).sum(axis=2).astype(np.float32)
        return cv2.GaussianBlur(err, (0, 0), 2.0).astype(np.float64)

    def _rebuild(self, shape, center, rgb, spread, reset) -> None:
        g = shape.geometry
        n = g.points.shape[0]
        if shape.stroke is not None:
            pts = _stroke_points(self.rng, center, (n - 1) // 3, spread)
            shape.stroke.color.copy_(torch.tensor([*rgb, 1.0], dtype=torch.float32))
            shape.stroke_width.fill_(float(self.rng.uniform(self.settings.min_width, self.settings.max_width)))
            reset(shape.stroke.color)
            reset(shape.stroke_width)
        else:
            pts = _shape_points(self.rng, center, n // 3, spread)
            shape.fill.color.copy_(torch.tensor([*rgb, 1.0], dtype=torch.float32))
            reset(shape.fill.color)
        shape.opacity.fill_(1.0)
        g.points.copy_(torch.as_tensor(pts[:n], dtype=torch.float32))
        reset(g.points)

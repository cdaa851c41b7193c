"""Scenes with clip paths, masks and filters, drawn in layers.

A shape or group with an effect is drawn on a layer of its own, as resvg and browsers do:
its content first (by the core, or by this module again where it holds effects itself),
then its filter, its clip (the clip's coverage multiplies the layer), its mask (the mask's
luminance or alpha multiplies it) and its opacity; the layer then goes over what is below
it. Runs of shapes without effects between such layers are drawn by the core in one pass
each, so a scene without effects is one pass, as before.

Every layer is a torch tensor of premultiplied RGBA over a frame of canvas pixels, and
every step is a torch operation, so gradients reach the clipped shapes, the clip's own
geometry, the mask's content and what a blur spreads (a blur is linear: its gradient is
exact). The clip and mask coverages are rendered by the core with the content's samples,
mode and pixel filter: they are anti-aliased as the content is.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Callable, Optional

import torch

from vecfit.scene import Group, Rect, Scene, Shape, Solid
from vecfit.scene.geometry import local_bbox
from vecfit.scene.placement import canvas_matrix, group_matrices

from . import filters

ONE = torch.tensor(1.0)
# How far beyond the canvas a filter's layer reaches (in canvas sizes, as resvg's), so
# that a blur near the edge sees what lies just outside.
FILTER_MARGIN = 2


@dataclass(frozen=True)
class Frame:
    """A rectangle of canvas pixels that a layer covers: x0, y0 and its size."""
    x0: int
    y0: int
    width: int
    height: int

    def matrix(self) -> torch.Tensor:
        """Canvas pixels -> this frame's pixels."""
        return torch.tensor([[1.0, 0.0, -self.x0], [0.0, 1.0, -self.y0], [0.0, 0.0, 1.0]])


# (A Scene sized in frame pixels, the draw's number) -> premultiplied RGBA. Premultiplied:
# through straight colour, a pixel that no sample covers would pass no gradient to its
# colour, and a boundary moving into it would be lost. Each draw of a render takes samples
# of its own (the seed and its number): a clip's coverage and the content it multiplies
# are then independent estimates, so the product's gradient is the product rule's (with
# the same samples, where a clip's edge runs along the content's, as in most emoji, their
# correlation biased Monte Carlo gradients by 5-30%). It is also what resvg draws there:
# the product of two anti-aliased coverages.
Draw = Callable[[Scene, int], torch.Tensor]


def over(top: torch.Tensor, below: torch.Tensor) -> torch.Tensor:
    """Premultiplied ``top`` over ``below``."""
    return top + below * (1 - top[..., 3:])


def reframe(image: torch.Tensor, source: Frame, target: Frame) -> torch.Tensor:
    """``image`` (over ``source``) cut or padded with transparency to ``target``."""
    if source == target:
        return image
    out = image.new_zeros((target.height, target.width, 4))
    x0, y0 = max(source.x0, target.x0), max(source.y0, target.y0)
    x1 = min(source.x0 + source.width, target.x0 + target.width)
    y1 = min(source.y0 + source.height, target.y0 + target.height)
    if x1 <= x0 or y1 <= y0:
        return out
    piece = image[y0 - source.y0:y1 - source.y0, x0 - source.x0:x1 - source.x0]
    return torch.nn.functional.pad(
        piece.permute(2, 0, 1), (x0 - target.x0, target.x0 + target.width - x1,
                                 y0 - target.y0, target.y0 + target.height - y1)).permute(1, 2, 0)


class LayeredRender:
    """One render of a Scene with effects: ``draw`` renders a Scene without effects (the
    core's pass, with the caller's samples, mode and seed) into premultiplied RGBA."""

    def __init__(self, scene: Scene, width: int, height: int, draw: Draw):
        self.scene, self._draw_with = scene, draw
        self._draws = 0
        self.canvas_frame = Frame(0, 0, width, height)
        self.canvas = canvas_matrix(scene, width, height)  # root user space -> canvas pixels
        self.group_matrix = group_matrices(scene, self.canvas)
        self.children: dict[int, list[tuple[str, int]]] = {-1: []}
        self.shapes_under: dict[int, list[int]] = {-1: []}
        self._build_tree()
        self.layered = {g: self._is_layered(g) for g in range(len(scene.groups))}

    def draw(self, sub: Scene) -> torch.Tensor:
        self._draws += 1
        return self._draw_with(sub, self._draws)

    # ------------------------------------------------------------------- the tree

    def _chain(self, group: int) -> list[int]:
        """The groups from the root down to ``group``."""
        out = []
        while group >= 0:
            out.append(group)
            group = self.scene.groups[group].parent
        return out[::-1]

    def _build_tree(self) -> None:
        """Each group's children in paint order (a group stands where its first shape is:
        the reader keeps a group's shapes together)."""
        placed = set()
        for g in range(len(self.scene.groups)):
            self.children[g] = []
            self.shapes_under[g] = []
        for i, shape in enumerate(self.scene.shapes):
            parent = -1
            for g in self._chain(shape.group):
                if g not in placed:
                    placed.add(g)
                    self.children[parent].append(("group", g))
                self.shapes_under[g].append(i)
                parent = g
            self.children[parent].append(("shape", i))
            self.shapes_under[-1].append(i)

    def _is_layered(self, g: int) -> bool:
        """Whether group ``g`` needs this module: it has effects, or something in it has."""
        if _has_effects(self.scene.groups[g]):
            return True
        return any(_has_effects(self.scene.shapes[i]) for i in self.shapes_under[g]) or any(
            _has_effects(self.scene.groups[h]) for h in self._groups_under(g))

    def _groups_under(self, g: int):
        for kind, index in self.children[g]:
            if kind == "group":
                yield index
                yield from self._groups_under(index)

    # ------------------------------------------------------------------- drawing

    def render(self, frame: Optional[Frame] = None) -> torch.Tensor:
        """The scene's premultiplied RGBA over ``frame`` (the canvas by default)."""
        return self._content(-1, frame or self.canvas_frame)

    def _content(self, parent: int, frame: Frame) -> torch.Tensor:
        """What group ``parent``'s children draw (without the group's own opacity and
        effects), premultiplied, over ``frame``."""
        result = None
        run: list[int] = []

        def add(layer):
            nonlocal result
            result = layer if result is None else over(layer, result)

        def flush():
            if run:
                add(self._plain(run, parent, frame))
                run.clear()

        for kind, index in self._inline_children(parent):
            if kind == "shape" and not _has_effects(self.scene.shapes[index]):
                run.append(index)
            elif kind == "group" and not self.layered[index]:
                run.extend(self.shapes_under[index])
            else:
                flush()
                layer = self._unit(kind, index, frame)
                owner = self.scene.shapes[index] if kind == "shape" else self.scene.groups[index]
                if layer is not None and owner.blend != "normal":
                    below = result if result is not None else torch.zeros_like(layer)
                    result = filters.blend(layer, below, owner.blend)
                elif layer is not None:
                    add(layer)
        flush()
        return result if result is not None else torch.zeros((frame.height, frame.width, 4))

    def _inline_children(self, parent: int):
        """``parent``'s children, with those of groups that are no layer of their own (no
        effects, opacity 1, not isolated) in their place: what they hold blends with
        what lies below them."""
        for kind, index in self.children[parent]:
            group = self.scene.groups[index] if kind == "group" else None
            if (group is not None and self.layered[index] and not _has_effects(group) and not group.isolate
                    and float(group.opacity.detach()) == 1.0):
                yield from self._inline_children(index)
            else:
                yield kind, index

    def _plain(self, shapes: list[int], parent: int, frame: Frame, own_opacity: bool = True) -> torch.Tensor:
        """Shapes without effects in one pass of the core. The opacities (and effects) of
        ``parent`` and the groups above it are this module's to apply, so the pass sees
        them as 1 (and none)."""
        neutral = set(self._chain(parent))
        groups = [dataclasses.replace(g, opacity=ONE if i in neutral else g.opacity, clip=None, mask=None,
                                      filter=None, blend="normal") if i in neutral or _has_effects(g) else g
                  for i, g in enumerate(self.scene.groups)]
        chosen = []
        for i in shapes:
            shape = self.scene.shapes[i]
            if _has_effects(shape) or not own_opacity:
                shape = dataclasses.replace(shape, clip=None, mask=None, filter=None, blend="normal",
                                            opacity=shape.opacity if own_opacity else ONE)
            chosen.append(shape)
        sub = Scene(width=frame.width, height=frame.height, shapes=chosen, groups=groups,
                    view=frame.matrix() @ self.canvas)
        return self.draw(sub)

    def _unit(self, kind: str, index: int, frame: Frame) -> Optional[torch.Tensor]:
        """A shape or group with effects (or holding some) as its own layer, over
        ``frame``; None where an effect leaves nothing to draw."""
        if kind == "shape":
            owner: Shape | Group = self.scene.shapes[index]
            space = self._group_space(owner.group) @ owner.transform.float()
            opacity = owner.opacity
        else:
            owner = self.scene.groups[index]
            space = self.group_matrix[index]
            opacity = owner.opacity
        box = _Lazy(lambda: self._bbox(kind, index))
        inner = frame
        if owner.filter is not None and not owner.filter.steps:
            return None  # a filter without steps draws nothing
        if owner.filter is not None:
            inner = self._filter_frame(owner.filter, space, _floats(box()))
            if inner is None:
                return None
        if kind == "shape":
            layer = self._plain([index], owner.group, inner, own_opacity=False)
        else:
            layer = self._content(index, inner)
        if owner.filter is not None:
            layer = filters.apply(owner.filter, layer, inner, inner.matrix() @ space, _floats(box()))
            layer = reframe(layer, inner, frame)
        pixels = frame.matrix() @ space  # the owner's user space -> frame pixels
        if owner.clip is not None:
            coverage = self.clip_coverage(owner.clip, pixels, box, frame)
            if coverage is None:
                return None
            layer = layer * coverage[..., None]
        if owner.mask is not None:
            values = self.mask_values(owner.mask, pixels, box, frame)
            if values is None:
                return None
            layer = layer * values[..., None]
        return layer * opacity

    def _group_space(self, group: int) -> torch.Tensor:
        return self.canvas if group < 0 else self.group_matrix[group]

    # ------------------------------------------------------------------- effects

    def clip_coverage(self, clip, pixels: torch.Tensor, box, frame: Frame) -> Optional[torch.Tensor]:
        """[h, w] coverage of ``clip`` referenced from a user space that ``pixels`` maps to
        the frame; None where it lets nothing through (bounding-box units on an element
        without an area)."""
        content = clip.content
        m = pixels @ content.view.float()  # the clip's transform comes before its units' box
        if clip.units == "objectBoundingBox":
            unit = _unit_square(box())
            if unit is None:
                return None
            m = m @ unit
        sub = Scene(width=frame.width, height=frame.height, shapes=content.shapes, groups=content.groups, view=m)
        coverage = self.draw_nested(sub)[..., 3]
        if clip.clip is not None:
            inner = self.clip_coverage(clip.clip, pixels, box, frame)
            if inner is None:
                return None
            coverage = coverage * inner
        return coverage

    def mask_values(self, mask, pixels: torch.Tensor, box, frame: Frame) -> Optional[torch.Tensor]:
        """[h, w] values of ``mask`` (luminance or alpha, within its region) referenced from
        a user space that ``pixels`` maps to the frame; None where it hides everything."""
        x, y, w, h = mask.region
        unit = None
        if mask.units == "objectBoundingBox" or mask.content_units == "objectBoundingBox":
            unit = _unit_square(box())
            if unit is None:
                return None
        if not (w > 0 and h > 0):
            return None
        corner = torch.tensor([float(x), float(y)])
        region = Scene(width=frame.width, height=frame.height,
                       view=pixels @ unit if mask.units == "objectBoundingBox" else pixels,
                       shapes=[Shape(geometry=Rect(p_min=corner, p_max=corner + torch.tensor([float(w), float(h)])),
                                     fill=Solid(torch.tensor([0.0, 0.0, 0.0, 1.0])))])
        inside = self.draw(region)[..., 3]
        content_space = pixels @ unit if mask.content_units == "objectBoundingBox" else pixels
        content = mask.content
        sub = Scene(width=frame.width, height=frame.height, shapes=content.shapes, groups=content.groups,
                    view=content_space @ content.view.float())
        image = self.draw_nested(sub)
        if mask.kind == "alpha":
            values = image[..., 3]
        else:  # luminance of the premultiplied sRGB colour: already weighted by alpha
            values = image[..., 0] * 0.2125 + image[..., 1] * 0.7154 + image[..., 2] * 0.0721
        values = values * inside
        if mask.mask is not None:
            inner = self.mask_values(mask.mask, pixels, box, frame)
            if inner is None:
                return None
            values = values * inner
        return values

    def draw_nested(self, sub: Scene) -> torch.Tensor:
        """Premultiplied RGBA of a clip's or mask's content, which may hold effects itself."""
        if sub.has_effects():
            nested = LayeredRender(sub, int(sub.width), int(sub.height), self._draw_with)
            nested._draws = self._draws + 1000 * (1 + self._draws)  # numbers of their own
            return nested.render()
        return self.draw(sub)

    def _filter_frame(self, filt, space: torch.Tensor, bounds) -> Optional[Frame]:
        """The frame a filter works in: its region in canvas pixels (whole pixels, as
        resvg's), within the canvas grown by FILTER_MARGIN canvas sizes each side."""
        region = filters.region_rect(filt, bounds)
        if region is None:
            return None
        x, y, w, h = region
        corners = torch.tensor([[x, y, 1.0], [x + w, y, 1.0], [x, y + h, 1.0], [x + w, y + h, 1.0]],
                               dtype=torch.float32) @ space.detach().T
        x0, y0 = corners[:, 0].min().floor(), corners[:, 1].min().floor()
        x1, y1 = corners[:, 0].max().ceil(), corners[:, 1].max().ceil()
        cw, ch = self.canvas_frame.width, self.canvas_frame.height
        x0, y0 = max(int(x0), -FILTER_MARGIN * cw), max(int(y0), -FILTER_MARGIN * ch)
        x1, y1 = min(int(x1), (FILTER_MARGIN + 1) * cw), min(int(y1), (FILTER_MARGIN + 1) * ch)
        if x1 <= x0 or y1 <= y0:
            return None
        return Frame(x0, y0, x1 - x0, y1 - y0)

    # ------------------------------------------------------------------- bounds

    def _bbox(self, kind: str, index: int):
        """The element's bounding box in its own user space, (min, max) tensors of 2,
        differentiable in its geometry (bounding-box units follow the shapes they
        measure), or None when it has no geometry (strokes are not counted, as in SVG)."""
        if kind == "shape":
            return local_bbox(self.scene.shapes[index].geometry)
        to_group = torch.linalg.inv(self.group_matrix[index].detach())
        corners = []
        for i in self.shapes_under[index]:
            shape = self.scene.shapes[i]
            box = local_bbox(shape.geometry)
            if box is None:
                continue
            m = to_group @ self._group_space(shape.group) @ shape.transform.float()
            lo, hi = box
            pts = torch.stack([lo, torch.stack([hi[0], lo[1]]), torch.stack([lo[0], hi[1]]), hi])
            corners.append(pts @ m[:2, :2].T + m[:2, 2])
        if not corners:
            return None
        every = torch.cat(corners)
        return every.min(dim=0).values, every.max(dim=0).values


def straight(image: torch.Tensor) -> torch.Tensor:
    """Premultiplied RGBA -> straight."""
    alpha = image[..., 3:]
    rgb = torch.where(alpha > 0, image[..., :3] / alpha.clamp_min(1e-12), torch.zeros_like(image[..., :3]))
    return torch.cat([rgb.clamp(0, 1), alpha.clamp(0, 1)], dim=-1)


def _has_effects(x) -> bool:
    return x.clip is not None or x.mask is not None or x.filter is not None or x.blend != "normal"


def _unit_square(bounds) -> Optional[torch.Tensor]:
    """The map from the bounding box's unit square to user space; None for a box without
    an area (bounding-box units then draw nothing)."""
    if bounds is None:
        return None
    lo, hi = bounds
    size = hi - lo
    if not (float(size[0].detach()) > 0 and float(size[1].detach()) > 0):
        return None
    zero, one = torch.zeros(()), torch.ones(())
    return torch.stack([torch.stack([size[0], zero, lo[0]]), torch.stack([zero, size[1], lo[1]]),
                        torch.stack([zero, zero, one])]).float()


def _floats(bounds):
    """Bounds as ((x0, y0), (x1, y1)) floats (for whole-pixel regions), or None."""
    if bounds is None:
        return None
    lo, hi = bounds[0].detach(), bounds[1].detach()
    return (float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1]))


class _Lazy:
    """A value computed on first use (the bounding box: only bounding-box units need it)."""

    def __init__(self, compute):
        self._compute, self._done, self._value = compute, False, None

    def __call__(self):
        if not self._done:
            self._value, self._done = self._compute(), True
        return self._value


def render_layered(scene: Scene, width: int, height: int, draw: Draw, background=None) -> torch.Tensor:
    """Straight RGBA [H, W, 4] of a scene with effects; ``background`` (RGBA in [0, 1] or
    None) goes under it."""
    image = LayeredRender(scene, width, height, draw).render()
    if background is not None:
        bg = torch.as_tensor(background, dtype=torch.float32)
        image = over(image, torch.cat([bg[:3] * bg[3], bg[3:]]).expand_as(image))
    return straight(image)

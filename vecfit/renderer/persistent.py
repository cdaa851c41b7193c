"""The scene packed once for a fitting loop: each iteration refreshes only the floats.

Packing a Scene (pack.py) walks its shapes in Python and builds an autograd graph through
every shape's tensors: on a 705-shape trace that is 7 ms a call and 11 ms of autograd in
the backward pass, an eighth of an iteration. In a fitting loop the structure (segments,
draws, paints, layers) does not change, and while transforms and opacities stay fixed,
every float the core reads is an affine function of the optimised values: a point is its
shape's matrix times the point, a colour's alpha the colour's times fixed opacities, a
width the width times its shape's scale. So the Packer is run once with a Provenance that
records where each tensor's values land and with which coefficient, and an iteration
computes all float arrays at once:

    floats = base + scatter(coefficient * gather(x))

where x is the optimiser's flat parameter tensors side by side; autograd of that is a
gather and a scatter, so gradients reach the flat tensors by index.

PersistentPack.build answers None where that does not hold (transforms or opacities
optimised; a rounded rect's corners, or geometry under a bounding-box gradient, optimised;
a dashed stroke, whose dashes change in number and place as the points move) and the
loop packs on every iteration as before. The build checks itself once against the
Packer: the same floats, and the same gradients for a random image adjoint.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import torch

from vecfit.scene import Scene
from vecfit.scene.dashes import dash_pattern

from .layout import COLUMNS
from .pack import Packer
from .raster import FLOAT_INPUTS
from .stopwatch import phase

# Parameter kinds (Scene.parameters) whose values enter the packed floats non-linearly
# (matrix products, alpha products): with either optimised, the loop packs the scene on
# every iteration.
NON_AFFINE_KINDS = ("transforms", "opacities")


class FlatTensors(Protocol):
    """Scene tensors laid side by side in one flat tensor (an optimiser's parameter
    group): what the persistent pack reads the optimised values from."""
    tensors: list[torch.Tensor]
    flat: torch.Tensor
    offsets: dict[int, int]  # id(tensor) -> its first element in flat


@dataclass
class _Route:
    """out[out_index] (+)= coefficient * tensor.reshape(-1)[source_index] (+ constant)."""
    array: str
    out_index: np.ndarray
    tensor: torch.Tensor
    source_index: np.ndarray
    coefficient: np.ndarray
    constant: np.ndarray | None = None  # the part that does not depend on the tensor (else 0)
    gate: torch.Tensor | None = None    # the route applies while this tensor's values are all > 0 (else 0)


class Provenance:
    """What the Packer tells about where scene tensors' values land (see pack.Packer)."""

    def __init__(self):
        self.routes: list[_Route] = []
        self.nonlinear: set[int] = set()   # ids of tensors used in other ways
        self.presence: list[tuple] = []    # (tensor, draws present, reduce): see present_if_positive
        self.differences: list[tuple] = []  # (a, i, b, j, present): a draw exists while a[i] > b[j]

    def copy(self, array: str, first: int, tensor: torch.Tensor) -> None:
        n = tensor.numel()
        self.routes.append(_Route(array, first + np.arange(n), tensor, np.arange(n), np.ones(n)))

    def scaled(self, array: str, first: int, tensor: torch.Tensor, scale: float) -> None:
        n = tensor.numel()
        self.routes.append(_Route(array, first + np.arange(n), tensor, np.arange(n), np.full(n, scale)))

    def colors(self, array: str, first: int, tensor: torch.Tensor, alpha) -> None:
        """RGBA rows: RGB copied, A times the row's ``alpha`` (fixed opacities)."""
        n = tensor.numel()
        coefficient = np.ones((n // 4, 4))
        coefficient[:, 3] = np.asarray(alpha, dtype=np.float64).reshape(-1)
        self.routes.append(_Route(array, first + np.arange(n), tensor, np.arange(n), coefficient.reshape(-1)))

    def points(self, array: str, row: int, tensor: torch.Tensor, m: np.ndarray) -> None:
        """[n, 2] points mapped by the affine matrix m into rows row... of a 2-column array."""
        n = len(tensor)
        k = np.arange(n)
        for c in range(2):  # out[.., c] = m[c, 0] x + m[c, 1] y + m[c, 2]
            for j in range(2):
                if m[c, j] != 0:
                    self.routes.append(_Route(array, 2 * (row + k) + c, tensor, 2 * k + j, np.full(n, m[c, j]),
                                              np.full(n, m[c, 2])))

    def ellipse(self, row: int, center: torch.Tensor, radii: torch.Tensor, m: np.ndarray) -> None:
        """An ellipses row: centre mapped by m, axes = m's linear part times diag(radii)
        while every radius is > 0, else 0 (the draw stays, drawing nothing: see
        Packer._add_ellipse), so that a radius crossing 0 changes no structure."""
        first = row * COLUMNS["ellipses"]
        for c in range(2):
            for j in range(2):
                if m[c, j] != 0:
                    self.routes.append(_Route("ellipses", np.array([first + c]), center, np.array([j]),
                                              np.array([m[c, j]]), np.array([m[c, 2]])))
        circle = radii.numel() == 1
        for i in range(2):
            for j in range(2):
                self.routes.append(_Route("ellipses", np.array([first + 2 + 2 * i + j]), radii,
                                          np.array([0 if circle else j]), np.array([m[i, j]]), gate=radii))

    def rect(self, rect) -> None:
        """A rect becomes a path (geometry.rect_as_path): with square corners, its corners
        are its p_min and p_max (rect_corners); rounded, the radii enter non-linearly. It
        is drawn while its width and height are above 0 and keeps square corners while a
        radius is 0 (conditions)."""
        rx, ry = (float(v) for v in rect.corner_radii.detach())
        if rx > 0 and ry > 0:
            self.used_otherwise(rect.p_min, rect.p_max, rect.corner_radii)
            return
        self.present_if_positive(rect.corner_radii, False, every=True)
        for axis in range(2):
            size = float(rect.p_max.detach()[axis] - rect.p_min.detach()[axis])
            self.differences.append((rect.p_max, axis, rect.p_min, axis, size > 0))

    def rect_corners(self, array: str, row: int, rect, m: np.ndarray) -> None:
        """A square-cornered rect's four corners (x0 y0, x1 y0, x1 y1, x0 y1) mapped by m."""
        corners = np.arange(4)
        x_of = {id(rect.p_min): corners[[0, 3]], id(rect.p_max): corners[[1, 2]]}
        y_of = {id(rect.p_min): corners[[0, 1]], id(rect.p_max): corners[[2, 3]]}
        for tensor in (rect.p_min, rect.p_max):
            for j, of in ((0, x_of), (1, y_of)):
                k = of[id(tensor)]
                for c in range(2):
                    if m[c, j] != 0:
                        self.routes.append(_Route(array, 2 * (row + k) + c, tensor, np.full(len(k), j),
                                                  np.full(len(k), m[c, j]), np.full(len(k), m[c, 2])))

    def used_otherwise(self, *tensors: torch.Tensor) -> None:
        self.nonlinear.update(id(t) for t in tensors)

    def present_if_positive(self, tensor: torch.Tensor, present: bool, every: bool = False) -> None:
        """A draw exists while the tensor's largest value (``every``: its smallest) is > 0."""
        self.presence.append((tensor, bool(present), every))


class PersistentPack:
    """See the module's docstring. ``arrays(leaves)`` gives the core's integer tables and
    float arrays for this iteration; ``leaves`` are the kinds' flat tensors (requiring
    grad), in the order of the kinds given to build."""

    def __init__(self, structure, shapes, base, destination, source, coefficient, conditions, gates=None):
        self.structure = structure
        self._shapes = shapes          # FLOAT_INPUTS' shapes, in order
        self._base = base              # all float arrays side by side (float32)
        self._destination = destination
        self._source = source
        self._coefficient = coefficient
        self._conditions = conditions  # (kind, a, b, expected): see _conditions
        self._gates = gates            # (entries, coefficients, x index, run starts, open): see _gate

    @classmethod
    def build(cls, scene: Scene, width: int, height: int, kinds: list[FlatTensors]) -> "PersistentPack | None":
        """The pack of ``scene`` at width x height whose floats follow the values in
        ``kinds`` (side by side, in order), or None where they are not affine in them."""
        if scene.has_effects():  # drawn in layers (renderer/layers.py), several packs a render
            return None
        kinds = list(kinds)
        if any(s.stroke is not None and dash_pattern(s.dash_array) is not None for s in scene.shapes):
            return None  # dashes: the segments and draws change as the points move
        optimised = {id(t) for k in kinds for t in k.tensors}
        parameters = scene.parameters()
        if any(id(t) in optimised for kind in NON_AFFINE_KINDS for t in parameters[kind]):
            return None
        provenance = Provenance()
        with torch.enable_grad():  # (the graph serves the check in _agrees)
            arrays = Packer(scene, width, height, provenance=provenance).pack().arrays()
        at: dict[int, int] = {}  # id(tensor) -> its first element in x (the kinds side by side)
        offset = 0
        for k in kinds:
            at.update((i, offset + o) for i, o in k.offsets.items())
            offset += k.flat.numel()
        if any(i in at for i in provenance.nonlinear):
            return None
        packed = [arrays[name].to(torch.float32) for name in FLOAT_INPUTS]
        floats = [f.detach() for f in packed]
        starts = np.concatenate([[0], np.cumsum([f.numel() for f in floats])])
        first_of = dict(zip(FLOAT_INPUTS, starts[:-1]))
        base = torch.cat([f.reshape(-1) for f in floats]) if floats else torch.zeros(0)
        dst, src, coef, constant_at, constant = [], [], [], [], []
        gated = []  # (first entry, entries, gate tensor's first element in x, its size)
        n_entries = 0
        for r in provenance.routes:
            where = at.get(id(r.tensor))
            if where is None:
                continue  # a value the loop does not change: the packed one stays
            d = first_of[r.array] + r.out_index
            dst.append(d)
            src.append(where + r.source_index)
            coef.append(r.coefficient)
            constant_at.append(d)
            constant.append(r.constant if r.constant is not None else np.zeros(len(d)))
            if r.gate is not None:
                gated.append((n_entries, len(d), at.get(id(r.gate)), r.gate.numel(), r.gate))
            n_entries += len(d)
        base = base.clone()
        if dst:
            base[torch.from_numpy(np.concatenate(constant_at))] = torch.from_numpy(
                np.concatenate(constant)).float()
        as_index = lambda parts: torch.from_numpy(np.concatenate(parts).astype(np.int64)) if parts \
            else torch.zeros(0, dtype=torch.int64)  # noqa: E731
        coefficient = torch.from_numpy(np.concatenate(coef)).float() if coef else torch.zeros(0)
        pack = cls({k: v for k, v in arrays.items() if k not in FLOAT_INPUTS}, [f.shape for f in floats],
                   base, as_index(dst), as_index(src), coefficient,
                   _conditions(provenance.presence, provenance.differences, at), _gates(gated, coefficient))
        if pack._gates is not None:
            pack._gate(np.concatenate([k.flat.detach().reshape(-1).numpy() for k in kinds]))
        # (the check differentiates: a pack first built in a no-grad evaluation, the loop's
        # last, had no graph to check and raised)
        with torch.enable_grad():
            return pack if pack._agrees(kinds, packed) else None

    def arrays(self, leaves: list[torch.Tensor]) -> tuple[dict, list[torch.Tensor]]:
        """(integer tables, float arrays in FLOAT_INPUTS order), differentiable w.r.t. leaves."""
        with phase("pack"):
            x = torch.cat(leaves) if len(leaves) > 1 else leaves[0]
            out = self._base.index_add(0, self._destination, x.index_select(0, self._source) * self._coefficient)
            floats, offset = [], 0
            for shape in self._shapes:
                n = int(np.prod(shape))
                floats.append(out[offset:offset + n].view(shape))
                offset += n
        return self.structure, floats

    def still_valid(self, flats: list[torch.Tensor]) -> bool:
        """Whether every draw that exists because of a value (a stroke's width) still
        exists, and no other has come to exist. (An ellipse whose radii cross 0 keeps its
        draw: its axes' routes open or close, _gate.)"""
        if not self._conditions and self._gates is None:
            return True
        x = (torch.cat(flats) if len(flats) > 1 else flats[0]).detach().numpy()
        if self._gates is not None:
            self._gate(x)
        for kind, a, b, expected in self._conditions:
            if kind == "difference":
                values = x[a] - x[b]
            else:  # a: indices, b: where each tensor's run starts
                values = (np.minimum if kind == "every" else np.maximum).reduceat(x[a], b)
            if not np.array_equal(values > 0, expected):
                return False
        return True

    def _gate(self, x: np.ndarray) -> None:
        """Opens the gated routes whose gate tensor's values in x are all > 0 and closes
        the others (their coefficients 0: an ellipse's axes 0 while a radius is <= 0)."""
        entries, coefficients, index, starts, was_open = self._gates
        now_open = np.minimum.reduceat(x[index], starts) > 0
        if np.array_equal(now_open, was_open):
            return
        changed = np.flatnonzero(now_open != was_open)
        for k in changed:
            e = entries[k]
            self._coefficient[e] = coefficients[e] if now_open[k] else 0.0
        was_open[:] = now_open

    def _agrees(self, kinds, packed: list[torch.Tensor]) -> bool:
        """Once per build: the same floats as the Packer's (``packed``, with its autograd
        graph to the Scene's tensors), and the same gradients of the kinds' values for a
        random adjoint of the floats (a missed or wrong route shows)."""
        leaves = [k.flat.detach().clone().requires_grad_() for k in kinds]
        _, mine = self.arrays(leaves)
        for a, b in zip(mine, packed):
            if not torch.allclose(a.detach(), b.detach(), rtol=1e-5, atol=1e-5):
                return False
        generator = torch.Generator().manual_seed(0)
        adjoints = [torch.randn(f.shape, generator=generator) for f in packed]
        fast = torch.autograd.grad(sum((a * g).sum() for a, g in zip(mine, adjoints)), leaves, allow_unused=True)
        used = [t for k in kinds for t in k.tensors if t.requires_grad]
        slow = {}
        if used and any(f.requires_grad for f in packed):
            total = sum((f * g).sum() for f, g in zip(packed, adjoints) if f.requires_grad)
            slow = dict(zip(map(id, used), torch.autograd.grad(total, used, allow_unused=True)))
        for k, f in zip(kinds, fast):
            reference = torch.cat([(slow.get(id(t)) if slow.get(id(t)) is not None else torch.zeros_like(t))
                                   .reshape(-1) for t in k.tensors])
            f = f if f is not None else torch.zeros_like(reference)
            scale = float(reference.abs().max()) if reference.numel() else 0.0
            if not torch.allclose(f, reference, rtol=1e-4, atol=1e-4 * max(1.0, scale)):
                return False
        return True


def _gates(gated, coefficient: torch.Tensor):
    """The gated routes (see _Route.gate) by gate tensor, as PersistentPack._gate reads
    them: each gate's coefficient entries, the coefficients themselves, the gate tensors'
    elements in x with where each one's run starts, and which gates are open (none yet:
    the build opens those that are)."""
    rows = [(first, n, where, size, gate) for first, n, where, size, gate in gated if where is not None]
    if not rows:
        return None
    by_gate: dict[int, list] = {}
    order = []
    for first, n, where, size, gate in rows:
        if id(gate) not in by_gate:
            by_gate[id(gate)] = [[], where, size]
            order.append(id(gate))
        by_gate[id(gate)][0].append(np.arange(first, first + n))
    entries = [torch.from_numpy(np.concatenate(by_gate[g][0]).astype(np.int64)) for g in order]
    index = np.concatenate([by_gate[g][1] + np.arange(by_gate[g][2]) for g in order])
    starts = np.concatenate([[0], np.cumsum([by_gate[g][2] for g in order])[:-1]]).astype(np.int64)
    return entries, coefficient.clone(), index, starts, np.ones(len(order), dtype=bool)


def _conditions(presence, differences, at: dict[int, int]) -> list:
    """The conditions on optimised tensors as index arrays over x: (kind, a, b, expected)
    with kind "any" (a tensor's largest value > 0), "every" (its smallest > 0) or
    "difference" (x[a] - x[b] > 0)."""
    out = []
    for every in (False, True):
        rows = [(at[id(t)], t.numel(), present) for t, present, e in presence
                if e == every and id(t) in at and t.numel() > 0]
        if rows:
            index = np.concatenate([start + np.arange(n) for start, n, _ in rows])
            starts = np.concatenate([[0], np.cumsum([n for _, n, _ in rows])[:-1]])
            out.append(("every" if every else "any", index, starts, np.array([p for _, _, p in rows])))
    rows = [(at[id(a)] + i, at[id(b)] + j, present) for a, i, b, j, present in differences
            if id(a) in at and id(b) in at]
    if rows:
        a, b, expected = (np.array(v) for v in zip(*rows))
        out.append(("difference", a, b, expected))
    return out

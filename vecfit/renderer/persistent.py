"""The scene packed once for a fitting loop: each iteration refreshes only the floats.

Packing a Scene (pack.py) walks its shapes in Python and builds an autograd graph through
every shape's tensors: on a 705-shape trace that is 7 ms a call and 11 ms of autograd in
the backward pass, an eighth of an iteration. In a fitting loop the structure (segments,
draws, paints, layers) does not change, and while transforms and opacities stay fixed,
every float the core reads is an affine function of the optimised values: a point is its
shape's matrix times the point, a colour's alpha the colour's times fixed opacities, a
width the width times its shape's scale. So the scene is packed once, the routes of
routes.py say where each tensor's values land and with which coefficient, and an
iteration computes all float arrays at once:

    floats = base + scatter(coefficient * gather(x))

where x is the optimiser's flat parameter tensors side by side; autograd of that is a
gather and a scatter, so gradients reach the flat tensors by index.

PersistentPack.build answers None where that does not hold (transforms or opacities
optimised; a rounded rect's corners, or geometry under a bounding-box gradient, optimised;
a dashed stroke, whose dashes change in number and place as the points move; clip paths,
masks and filters, drawn in layers), and PersistentPack.attempt the reason instead; the
loop then packs on every iteration as before, and warns once a run with that reason. That the floats and their gradients are those of
packing anew is what tests/unit/renderer/test_persistent_pack.py checks, on every kind of
value a route serves; the build does not check itself.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np
import torch

from vecfit.scene import Scene
from vecfit.scene.dashes import dash_pattern

from .pack import pack_scene
from .raster import FLOAT_INPUTS
from .routes import routes_of
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
        pack = cls.attempt(scene, width, height, kinds)
        return pack if isinstance(pack, PersistentPack) else None

    @classmethod
    def attempt(cls, scene: Scene, width: int, height: int, kinds: list[FlatTensors]) -> "PersistentPack | str":
        """The pack as ``build`` makes it, or where it declines, why (a phrase)."""
        kinds = list(kinds)
        reason = _not_affine(scene, kinds)
        if reason is not None:
            return reason
        with torch.no_grad():
            packed = pack_scene(scene, width, height, keep_empty=True)
            arrays = packed.arrays()
        routes = routes_of(scene, packed)
        at: dict[int, int] = {}  # id(tensor) -> its first element in x (the kinds side by side)
        offset = 0
        for k in kinds:
            at.update((i, offset + o) for i, o in k.offsets.items())
            offset += k.flat.numel()
        if any(i in at for i in routes.nonlinear):
            return "a rounded rect's corners, or geometry under a bounding-box gradient, are optimised"
        floats = [arrays[name].to(torch.float32) for name in FLOAT_INPUTS]
        starts = np.concatenate([[0], np.cumsum([f.numel() for f in floats])])
        first_of = dict(zip(FLOAT_INPUTS, starts[:-1]))
        base = torch.cat([f.reshape(-1) for f in floats]) if floats else torch.zeros(0)
        dst, src, coef, constant_at, constant = [], [], [], [], []
        gated = []  # (first entry, entries, gate tensor's first element in x, its size)
        n_entries = 0
        for r in routes.routes:
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
                   _conditions(routes.presence, routes.differences, at), _gates(gated, coefficient))
        if pack._gates is not None:
            pack._gate(np.concatenate([k.flat.detach().reshape(-1).numpy() for k in kinds]))
        return pack

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


def _not_affine(scene: Scene, kinds: list[FlatTensors]) -> str | None:
    """Why the packed floats are not affine in the kinds' values, as far as the scene's
    structure tells (the routes tell the rest); None where they may be."""
    if scene.has_effects():
        return "clip paths, masks or filters (drawn in layers, several packs a render)"
    if any(s.stroke is not None and dash_pattern(s.dash_array) is not None for s in scene.shapes):
        return "dashed strokes (their dashes change in number and place as the points move)"
    optimised = {id(t) for k in kinds for t in k.tensors}
    parameters = scene.parameters()
    kinds_seen = [kind for kind in NON_AFFINE_KINDS if any(id(t) in optimised for t in parameters[kind])]
    if kinds_seen:
        return f"{' and '.join(kinds_seen)} optimised"
    return None


def _gates(gated, coefficient: torch.Tensor):
    """The gated routes (see routes.Route.gate) by gate tensor, as PersistentPack._gate reads
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

"""The tracer's region merger in the compiled core (csrc/trace/merge.cpp) makes the same
merges, in the same order, as the Python merger it replaced (kept here as the reference):
identical final labels on random label maps, budgets and speck sizes, and on a photo."""
from __future__ import annotations

import heapq

import numpy as np
import pytest
import skimage.data
from scipy import ndimage

from vecfit import _core
from vecfit.initial.tracer.quantize import quantize_colors
from vecfit.initial.tracer.regions import (adjacency, blends, components, merge_regions, merge_specks,
                                           region_stats, roots, thin_components)


class ReferenceMerger:
    """The Python merger as the tracer had it (heapq, dicts in insertion order)."""

    def __init__(self, area, color, thin, edges, min_area):
        n = len(area)
        self.min_area = min_area
        self.area = area.tolist()
        self.sum = (color * area[:, None]).tolist()
        self.thin = thin.tolist()
        self.small = (thin | (area < min_area)).tolist()
        self.parent = list(range(n))
        self.alive = [True] * n
        self.version = [0] * n
        self.adj: list[dict[int, int]] = [dict() for _ in range(n)]
        for a, b in edges.tolist():
            self.adj[a][b] = 1
            self.adj[b][a] = 1
        self.live = n
        self.heap = []
        for r in range(n):
            self.push(r)

    def cost(self, r, t):
        ar, (sr, sg, sb) = self.area[r], self.sum[r]
        if t < 0:
            return ((sr - ar) ** 2 + (sg - ar) ** 2 + (sb - ar) ** 2) / ar
        at, (tr, tg, tb) = self.area[t], self.sum[t]
        dr, dg, db = sr / ar - tr / at, sg / ar - tg / at, sb / ar - tb / at
        return ar * at / (ar + at) * (dr * dr + dg * dg + db * db)

    def push(self, r):
        best, target = np.inf, -1
        for t in self.adj[r]:
            c = self.cost(r, t)
            if c < best:
                best, target = c, t
        if target < 0:
            best = self.cost(r, -1)
        must = self.small[r] and (target >= 0 or self.area[r] < self.min_area)
        tv = self.version[target] if target >= 0 else 0
        heapq.heappush(self.heap, (0 if must else 1, best, r, self.version[r], target, tv))

    def run(self, budget):
        while self.heap:
            must, cost, r, rv, t, tv = self.heap[0]
            if must == 1 and self.live <= budget:
                return
            heapq.heappop(self.heap)
            if not self.alive[r]:
                continue
            if rv != self.version[r] or (t >= 0 and (not self.alive[t] or tv != self.version[t])):
                self.push(r)
                continue
            if t < 0:
                if self.live == 1:
                    return
                self.alive[r], self.parent[r] = False, -1
                self.live -= 1
            else:
                self.merge(r, t, cost)

    def merge(self, r, t, cost):
        keep, gone = (t, r) if len(self.adj[t]) >= len(self.adj[r]) else (r, t)
        self.thin[keep] = self.thin[r] and self.thin[t]
        self.area[keep] += self.area[gone]
        self.sum[keep] = [a + b for a, b in zip(self.sum[keep], self.sum[gone])]
        self.small[keep] = self.thin[keep] or self.area[keep] < self.min_area
        self.alive[gone], self.parent[gone] = False, keep
        self.live -= 1
        adj_keep = self.adj[keep]
        for n, length in self.adj[gone].items():
            if n == keep:
                continue
            adj_keep[n] = adj_keep.get(n, 0) + length
            an = self.adj[n]
            an[keep] = an.get(keep, 0) + an.pop(gone)
            self.version[n] += 1
        adj_keep.pop(gone, None)
        self.adj[gone] = {}
        self.version[keep] += 1
        if keep == r:
            if len(adj_keep) <= 64:
                self.push(keep)
            else:
                heapq.heappush(self.heap, (0 if self.small[keep] else 1, cost, keep, self.version[keep] - 1, -1, 0))


def reference(area, color, thin, edges, min_area, budget):
    m = ReferenceMerger(area, color, thin, edges, min_area)
    m.run(budget)
    return roots(np.array(m.parent), np.array(m.alive))


def merge_inputs(classes, rgb, min_area, specks=True):
    """What build_regions hands the merger: regions, their stats, slivers and adjacency."""
    comp, count = components(classes)
    area, color = region_stats(comp, count, rgb)
    edges = adjacency(comp, count)
    if specks and (area < min_area).any() and len(edges):
        comp, count = merge_specks(comp, count, area, color, edges, min_area)
        area, color = region_stats(comp, count, rgb)
        edges = adjacency(comp, count)
    thin = blends(thin_components(comp, count), edges, color, 0.04)
    return area, color, thin, edges


def random_image(rng, shape, levels, transparent):
    """Blobs of a few colours with noise (specks, slivers, and regions of all sizes)."""
    noise = ndimage.gaussian_filter(rng.random(shape), float(rng.uniform(0.6, 2.5)))
    classes = np.digitize(noise, np.quantile(noise, np.linspace(0, 1, levels + 1)[1:-1])).astype(np.int32)
    classes[rng.random(shape) < 0.03] = rng.integers(0, levels)  # specks
    if transparent:
        classes[ndimage.gaussian_filter(rng.random(shape), 3.0) > 0.52] = -1
    palette = rng.random((levels, 3))
    rgb = palette[np.maximum(classes, 0)] + rng.normal(0, 0.05, shape + (3,))
    return classes, rgb


@pytest.mark.parametrize("seed", range(12))
def test_merges_as_the_python_merger_on_random_label_maps(seed):
    rng = np.random.default_rng(seed)
    shape = (int(rng.integers(8, 90)), int(rng.integers(8, 90)))
    classes, rgb = random_image(rng, shape, int(rng.integers(2, 9)), transparent=seed % 3 == 0)
    min_area = float(rng.choice([0, 3, 8, 20]))
    inputs = merge_inputs(classes, rgb, min_area, specks=seed % 2 == 0)
    for budget in (1, 5, 40, 10_000):
        expected = reference(*inputs, min_area, budget)
        got = merge_regions(*inputs, min_area, budget)
        np.testing.assert_array_equal(got, expected)
        if budget == 10_000 and min_area == 0:
            assert got.max() + 1 == len(got) - np.count_nonzero(inputs[2])  # only slivers merged


@pytest.mark.slow
@pytest.mark.parametrize("budget", [60, 1000])
def test_merges_as_the_python_merger_on_a_photo(budget):
    """chelsea's colour classes as the tracer makes them: thousands of regions, some with
    hundreds of neighbours (the long neighbour lists, and their stale placeholders)."""
    rgb = skimage.data.chelsea().astype(np.float32) / 255
    classes = quantize_colors(rgb, np.ones(rgb.shape[:2], bool), 48, 0)
    inputs = merge_inputs(classes, rgb, 8.0)
    assert len(inputs[0]) > 3000
    expected = reference(*inputs, 8.0, budget)
    got = merge_regions(*inputs, 8.0, budget)
    assert got.max() + 1 == budget
    np.testing.assert_array_equal(got, expected)


def test_known_merges():
    # a row of three: 0 (black, 4 px), 1 (grey, 1 px), 2 (white, 4 px); the speck 1
    # joins its nearer neighbour... both are equally far: the lower index, 0
    area = np.array([4.0, 1.0, 4.0])
    color = np.array([[0.0] * 3, [0.5] * 3, [1.0] * 3])
    edges = np.array([[0, 1], [1, 2]])
    np.testing.assert_array_equal(merge_regions(area, color, np.zeros(3, bool), edges, 2.0, 10), [0, 0, 1])
    # a budget of one then merges the rest too; an isolated speck is dropped
    np.testing.assert_array_equal(merge_regions(area, color, np.zeros(3, bool), edges, 2.0, 1), [0, 0, 0])
    lone = merge_regions(np.array([1.0, 9.0]), color[:2], np.zeros(2, bool), np.zeros((0, 2), np.int64), 2.0, 5)
    np.testing.assert_array_equal(lone, [-1, 0])


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="out of range"):
        _core.merge_regions(np.ones(2), np.ones((2, 3)), np.zeros(2, bool), np.array([[0, 2]]), 1.0, 1)
    with pytest.raises(ValueError, match="expected"):
        _core.merge_regions(np.ones(2), np.ones((3, 3)), np.zeros(2, bool), np.array([[0, 1]]), 1.0, 1)

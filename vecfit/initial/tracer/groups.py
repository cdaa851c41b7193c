"""Compound paths: the regions of one colour drawn by one path.

A designer draws the letters of a word, the spots of a leopard or the stars of a flag as
one path of several subpaths, so a flat-art file has few paths and many pieces. A tracer
that spends one path per connected region cannot draw such a picture at the designer's
path count: the budget merges away whole letters. Here every region is kept (specks
and anti-aliased slivers still merge away) and the path budget bounds the number of
colours instead: regions are grouped by colour, by Ward's criterion (the pair of groups
whose merge adds the least squared error to the flat-colour picture merges first, as the
region merger does for neighbours, here for any two), until at most ``budget`` groups
are left, and each group becomes one region of several pieces painted with its mean
colour. The rest of the tracer draws it like any region: stacking order only decides
which shape reaches under which, and the pieces of a group fill the same pixels as before.

The background region of an opaque image (the tracer's full-canvas rect) keeps a group
of its own: pieces of its colour elsewhere (an eye's highlight) must be drawn above what
surrounds them, not under everything. Pieces of its colour on the canvas's edge are the
page too (the corners a logo's ring cuts off) and join it: as a group of their own they
took a colour from the budget, and at a budget of one path they were merged with the
logo into one grey shape (logos-052, 10.7 dB).
"""
from __future__ import annotations

import numpy as np

from .quantize import to_lab
from .regions import Regions, painted_regions

PAGE_COLOUR = 2.0  # CIELAB units: a piece on the canvas's edge this close to the page's colour is page
# CIELAB units: groups this close are one colour. (At 2 units, Noto's gradient bands
# joined too: 38 paths became 18 on noto-emoji-020, -0.97 dB after refining.)
SAME_COLOUR = 0.5


def ward_groups(area: np.ndarray, color: np.ndarray, budget: int) -> np.ndarray:
    """Group index (0 ..) of each of the items (areas, mean colours [n, 3]) merged by
    Ward's criterion down to ``budget`` groups: the groups that merging the cheapest pair
    each time leaves. The whole hierarchy is built by nearest-neighbour chains (O(n²));
    its merges, replayed cheapest first, stop at the budget (Ward's merge costs never
    fall up the hierarchy, so a merge's parts are always merged before it)."""
    n = len(area)
    if n <= budget:
        return np.arange(n)
    merges = _ward_hierarchy(area.astype(np.float64), color.astype(np.float64))
    merges.sort(key=lambda m: m[0])
    parent = np.arange(n)

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for _, a, b in merges[:n - budget]:
        parent[root(b)] = root(a)
    _, compact = np.unique([root(i) for i in range(n)], return_inverse=True)
    return compact


def _ward_hierarchy(size: np.ndarray, centre: np.ndarray) -> list[tuple[float, int, int]]:
    """Every merge (cost, kept item, merged item) of Ward's hierarchy over the items,
    each merged group named by one of its items."""
    size, centre = size.copy(), centre.copy()
    alive = np.ones(len(size), bool)
    merges, chain = [], []

    def costs(a: int) -> np.ndarray:
        d = ((centre - centre[a]) ** 2).sum(1)
        c = size[a] * size / np.maximum(size[a] + size, 1e-12) * d
        c[~alive] = np.inf
        c[a] = np.inf
        return c

    for _ in range(len(size) - 1):
        while True:
            if not chain:
                chain.append(int(np.flatnonzero(alive)[0]))
            a = chain[-1]
            c = costs(a)
            b = int(np.argmin(c))
            if len(chain) > 1 and c[chain[-2]] <= c[b]:
                b = chain[-2]
                break
            chain.append(b)
        chain.pop()
        chain.pop()
        total = size[a] + size[b]
        merges.append((float(c[b]), a, b))
        centre[a] = (size[a] * centre[a] + size[b] * centre[b]) / total
        size[a] = total
        alive[b] = False
    return merges


def grouped(regions: Regions, rgb: np.ndarray, budget: int, background: int | None) -> Regions:
    """The regions relabelled as at most ``budget`` colour groups (besides the background
    region, which keeps its own), each painted with its pixels' mean colour (its
    interior's, as the region builder does)."""
    n = regions.count
    if n == 0:
        return regions
    page = _page_pieces(regions, background)
    others = np.array([i for i in range(n) if i != background and not page[i]], np.int64)
    group = np.empty(n, np.int64)
    if len(others):
        group[others] = ward_groups(regions.area[others], regions.color[others], max(int(budget), 1))
        group[others] = _same_colours_joined(group[others], regions.area[others], regions.color[others])
    count = int(group[others].max()) + 1 if len(others) else 0
    if background is not None:
        group[background] = count
        group[page] = count
        count += 1
    labels = np.where(regions.labels >= 0, group[np.maximum(regions.labels, 0)], -1).astype(np.int32)
    return painted_regions(labels, count, rgb)


def _page_pieces(regions: Regions, background: int | None) -> np.ndarray:
    """[count] bool: the regions besides the background that touch the canvas's edge in
    the background's colour (within PAGE_COLOUR)."""
    page = np.zeros(regions.count, bool)
    if background is None:
        return page
    labels = regions.labels
    edge = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
    edge = edge[(edge >= 0) & (edge != background)]
    if len(edge):
        lab = to_lab(np.asarray(regions.color, np.float64).reshape(-1, 3))
        page[edge] = np.linalg.norm(lab[edge] - lab[background], axis=1) < PAGE_COLOUR
    return page


def _same_colours_joined(group: np.ndarray, area: np.ndarray, color: np.ndarray) -> np.ndarray:
    """Ward's groups renumbered 0.. with groups of one colour (means within SAME_COLOUR)
    joined: a budget above the number of colours must not split a colour over two paths
    (a flag's white cross as two paths of L-shaped pieces)."""
    ids, group = np.unique(group, return_inverse=True)
    weight = np.bincount(group, area, minlength=len(ids))
    mean = np.stack([np.bincount(group, area * color[:, c], minlength=len(ids)) for c in range(3)], 1)
    lab = to_lab(mean / np.maximum(weight, 1e-12)[:, None])
    into = np.arange(len(ids))
    for g in range(len(ids)):
        close = np.flatnonzero(np.linalg.norm(lab[:g] - lab[g], axis=1) < SAME_COLOUR)
        if len(close):
            into[g] = into[close[0]]
    return np.unique(into, return_inverse=True)[1][group]

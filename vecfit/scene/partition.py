"""A drawing of filled shapes as a planar partition: pieces that do not overlap and that
share their boundaries exactly (cut-outs, vecfit/svg/cutouts.py).

The shapes are sampled on a fine grid (``scale`` samples a pixel side), each sample
taking the stack of shapes that cover it: the topmost opaque one and any translucent ones
over it. Samples with the same stack are one piece. Each piece's outline runs along the
grid lines between samples, so two neighbours' outlines meet edge to edge; cut at the
junctions (grid corners where three pieces meet, or two across a diagonal) they become
chains, each shared by the two pieces on its sides. The caller fits each chain once and
writes it in both pieces, forwards in one and backwards in the other: no gap, no
overlap.

Grid coordinates: the grid corner (i, j) lies at x = j / scale, y = i / scale pixels.
An outline keeps its piece on its left (y pointing down: counter-clockwise on screen), and
a hole's outline runs the other way, so the pieces fill under the nonzero rule.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

OUTSIDE = -2  # the label beyond the canvas
EMPTY = -1    # samples no shape covers

# directions of a grid edge, as steps (di, dj): east, south, west, north
STEPS = np.array([[0, 1], [1, 0], [0, -1], [-1, 0]], np.int64)


# ------------------------------------------------------------------ sampling

def winding_samples(polygons: list[np.ndarray], evenodd: bool, box: tuple[int, int, int, int],
                    scale: int) -> np.ndarray:
    """Which samples of ``box`` (i0, i1, j0, j1 in samples) the closed ``polygons`` (pixels,
    [n, 2] each) fill: sample (i, j) is the point ((j + 0.5) / scale, (i + 0.5) / scale),
    filled where the winding number is non-zero (odd for ``evenodd``). A sample exactly on
    an edge belongs to the side to its right, so shapes that abut fill it once."""
    i0, i1, j0, j1 = box
    rows, cols = i1 - i0, j1 - j0
    diff = np.zeros((rows, cols + 1), np.int32)
    for poly in polygons:
        if len(poly) < 3:
            continue
        p = poly * scale - 0.5  # sample centres at integers
        a, b = p, np.roll(p, -1, axis=0)
        ya, yb = a[:, 1], b[:, 1]
        lo = np.ceil(np.minimum(ya, yb)).astype(np.int64)
        hi = np.ceil(np.maximum(ya, yb)).astype(np.int64)  # rows lo .. hi-1 cross
        lo, hi = np.maximum(lo, i0), np.minimum(hi, i1)
        count = np.maximum(hi - lo, 0)
        if not count.any():
            continue
        edge = np.repeat(np.arange(len(a)), count)
        row = lo[edge] + (np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count))
        t = (row - ya[edge]) / (yb[edge] - ya[edge])
        x = a[edge, 0] + t * (b[edge, 0] - a[edge, 0])
        col = np.clip(np.ceil(x).astype(np.int64) - j0, 0, cols)
        direction = np.where(yb[edge] > ya[edge], 1, -1).astype(np.int32)
        np.add.at(diff, (row - i0, col), direction)
    winding = np.cumsum(diff[:, :cols], axis=1)
    return (winding & 1).astype(bool) if evenodd else winding != 0


@dataclass
class Stacks:
    """The sampled drawing: ``labels`` [H, W] int64, each sample's piece (EMPTY where no
    shape is), and for each piece the shapes of its stack, bottom to top (``stacks``)."""
    labels: np.ndarray
    stacks: list[tuple[int, ...]]


def sample_stacks(shapes: list[tuple[list[np.ndarray], bool, bool]], width: int, height: int,
                  scale: int) -> Stacks:
    """Samples the shapes ((polygons in pixels, evenodd, opaque) each, in drawing order) on a
    ``width`` x ``height`` canvas at ``scale`` samples a pixel side."""
    h, w = height * scale, width * scale
    keys = np.full((h, w), -1, np.int64)  # index into `stack_of`
    stack_of: list[tuple[int, ...]] = []
    index: dict[tuple[int, ...], int] = {}

    def key(stack):
        k = index.get(stack)
        if k is None:
            k = index[stack] = len(stack_of)
            stack_of.append(stack)
        return k

    for n, (polygons, evenodd, opaque) in enumerate(shapes):
        pts = [p for p in polygons if len(p) >= 3]
        if not pts:
            continue
        allp = np.vstack(pts) * scale
        i0, j0 = (max(int(np.floor(allp[:, k].min())) - 1, 0) for k in (1, 0))
        i1, j1 = min(int(np.ceil(allp[:, 1].max())) + 1, h), min(int(np.ceil(allp[:, 0].max())) + 1, w)
        if i1 <= i0 or j1 <= j0:
            continue
        inside = winding_samples(pts, evenodd, (i0, i1, j0, j1), scale)
        view = keys[i0:i1, j0:j1]
        if opaque:
            view[inside] = key((n,))
            continue
        below = view[inside]  # translucent: on top of whatever stack is there
        olds, where = np.unique(below, return_inverse=True)
        news = np.array([key((stack_of[o] if o >= 0 else ()) + (n,)) for o in olds.tolist()], np.int64)
        view[inside] = news[where.reshape(-1)]
    # pieces numbered by their first sample (raster order), so the output does not depend
    # on the order stacks were met
    used, first = np.unique(keys, return_index=True)
    used_pieces = used[used >= 0]
    order = np.argsort(first[used >= 0], kind="stable")
    renumber = np.full(len(stack_of) + 1, EMPTY, np.int64)
    renumber[used_pieces[order]] = np.arange(len(order))
    labels = renumber[keys]  # keys -1 read renumber[-1]: EMPTY
    return Stacks(labels, [stack_of[k] for k in used_pieces[order].tolist()])


def absorb_specks(labels: np.ndarray, min_samples: int) -> np.ndarray:
    """Each 4-connected run of samples under ``min_samples`` given to the neighbour it
    shares the most grid edges with (a speck of a shape peeking out from under another
    draws next to nothing and makes a tiny piece a cutter cannot cut). Empty samples stay."""
    from skimage.measure import label as components

    labels = labels.copy()
    for _ in range(3):  # specks next to specks: a few rounds
        comp = components(labels, background=-3, connectivity=1)  # every value a component
        sizes = np.bincount(comp.ravel())
        small = (sizes < min_samples)
        small[0] = False
        if not small[comp].any():
            break
        pairs = []
        for a, b in ((comp[:, :-1], comp[:, 1:]), (comp[:-1, :], comp[1:, :])):
            diff = a != b
            pairs.append(np.stack([a[diff], b[diff]], 1))
            pairs.append(np.stack([b[diff], a[diff]], 1))
        pairs = np.concatenate(pairs)
        pairs = pairs[small[pairs[:, 0]] & ~small[pairs[:, 1]]]
        if not len(pairs):
            break
        label_of = np.zeros(len(sizes), np.int64)
        label_of[comp.ravel()] = labels.ravel()
        keep = label_of[pairs[:, 1]] != EMPTY  # never grow the empty area over a speck
        pairs = pairs[keep]
        uniq, counts = np.unique(pairs, axis=0, return_counts=True)
        # for each small component, its neighbour with the most shared edges
        order = np.lexsort((-counts, uniq[:, 0]))
        uniq = uniq[order]
        firsts = np.r_[True, uniq[1:, 0] != uniq[:-1, 0]]
        target = label_of.copy()
        target[uniq[firsts, 0]] = label_of[uniq[firsts, 1]]
        labels = np.where(small[comp] & (labels != EMPTY), target[comp], labels)
    return labels


# ------------------------------------------------------------------ outlines

@dataclass
class Chain:
    """A stretch of boundary between two junctions (or a whole closed loop): grid corners
    [n, 2] as (i, j), with ``left`` and ``right`` the pieces on its sides (EMPTY or
    OUTSIDE for none)."""
    corners: np.ndarray
    left: int
    right: int
    closed: bool


@dataclass
class Partition:
    """Every piece's outlines as chains: ``outlines[piece]`` lists its closed outlines, each
    a list of (chain index, reversed) in order."""
    chains: list[Chain]
    outlines: dict[int, list[list[tuple[int, bool]]]]


def _directed_edges(padded: np.ndarray):
    """Every grid edge between two different labels, both ways: start corners (i, j),
    directions (0 east, 1 south, 2 west, 3 north) and the label on the left."""
    h, w = padded.shape[0] - 2, padded.shape[1] - 2
    # east edges from (i, j), i in 0..h, j in 0..w-1: above P[i, j+1], below P[i+1, j+1]
    above, below = padded[:-1, 1:-1], padded[1:, 1:-1]
    hi, hj = np.nonzero(above != below)
    # south edges from (i, j), i in 0..h-1, j in 0..w: left pixel P[i+1, j], right P[i+1, j+1]
    west, east = padded[1:-1, :-1], padded[1:-1, 1:]
    vi, vj = np.nonzero(west != east)
    i = np.concatenate([hi, hi, vi, vi + 1])
    j = np.concatenate([hj, hj + 1, vj, vj])
    d = np.concatenate([np.zeros_like(hi), np.full_like(hi, 2), np.ones_like(vi), np.full_like(vi, 3)])
    # east: left is above; west (from (i, j+1)): left is below; south: left is the east
    # pixel; north (from (i+1, j)): left is the west pixel
    left = np.concatenate([above[hi, hj], below[hi, hj], east[vi, vj], west[vi, vj]])
    return i.astype(np.int64), j.astype(np.int64), d.astype(np.int64), left, (h, w)


def _quadrants(padded, i, j):
    """The labels round grid corner (i, j): NW, NE, SW, SE."""
    return padded[i, j], padded[i, j + 1], padded[i + 1, j], padded[i + 1, j + 1]


# for a heading d, which quadrants of the corner ahead are front-left and front-right
# (indices into NW, NE, SW, SE)
_FRONT_LEFT = np.array([1, 3, 2, 0])   # east: NE, south: SE, west: SW, north: NW
_FRONT_RIGHT = np.array([3, 2, 0, 1])  # east: SE, south: SW, west: NW, north: NE


def _rank_in_cycles(succ: np.ndarray):
    """For a permutation ``succ`` (each element's successor), each element's cycle (the
    smallest element in it) and position along it from there."""
    n = len(succ)
    # the smallest element of each cycle, by doubling: after k rounds best[x] is the least
    # of the 2^k elements from x on
    best, jump = np.arange(n), succ.copy()
    for _ in range(int(np.ceil(np.log2(max(n, 2)))) + 1):
        best = np.minimum(best, best[jump])
        jump = jump[jump]
    root = best
    # list ranking with the cycle cut before its root: distance to the last element
    nxt = succ.copy()
    last = succ == root[succ]  # x's successor is the root: x is the end of the list
    nxt[last] = np.flatnonzero(last)
    dist = np.where(last, 0, 1).astype(np.int64)
    for _ in range(int(np.ceil(np.log2(max(n, 2)))) + 1):
        dist = dist + dist[nxt]
        nxt = nxt[nxt]
    length = np.bincount(root, minlength=n)
    return root, length[root] - 1 - dist


def partition(labels: np.ndarray) -> Partition:
    """The outlines of every piece of ``labels`` (non-negative: pieces; EMPTY: none),
    split into chains shared by the pieces on their two sides."""
    padded = np.pad(labels, 1, constant_values=OUTSIDE)
    i, j, d, left, (h, w) = _directed_edges(padded)
    n = len(i)
    if n == 0:
        return Partition([], {})
    key = (i * (w + 1) + j) * 4 + d
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]

    def find(ii, jj, dd):
        at = np.searchsorted(sorted_key, (ii * (w + 1) + jj) * 4 + dd)
        return order[np.minimum(at, n - 1)]

    # the successor keeps the same label on the left: turn left if the front-left quadrant
    # is another label, else straight on if the front-right one is, else turn right
    ei, ej = i + STEPS[d, 0], j + STEPS[d, 1]
    quads = np.stack(_quadrants(padded, ei, ej), 1)
    fl = quads[np.arange(n), _FRONT_LEFT[d]]
    fr = quads[np.arange(n), _FRONT_RIGHT[d]]
    nd = np.where(fl != left, (d + 3) % 4, np.where(fr != left, d, (d + 1) % 4))
    succ = find(ei, ej, nd)
    # junctions: corners with three labels or more, or two across a diagonal
    nw, ne, sw, se = _quadrants(padded, i, j)
    distinct = 1 + (ne != nw) + ((sw != nw) & (sw != ne)) + ((se != nw) & (se != ne) & (se != sw))
    junction = (distinct >= 3) | ((nw == se) & (ne == sw) & (nw != ne))
    cycle, pos = _rank_in_cycles(succ)
    # each edge's opposite twin, and its undirected id (the east or south one's index)
    twin = find(i + STEPS[d, 0], j + STEPS[d, 1], (d + 2) % 4)
    undirected = np.where(d < 2, np.arange(n), twin)

    # walk the cycles in order; a chain starts at each junction (a cycle without one is
    # one closed chain)
    walk = np.lexsort((pos, cycle))
    cyc = cycle[walk]
    starts_cycle = np.r_[True, cyc[1:] != cyc[:-1]]
    cycle_first = np.flatnonzero(starts_cycle)
    cycle_len = np.diff(np.r_[cycle_first, n])
    has_junction = np.add.reduceat(junction[walk].astype(np.int64), cycle_first) > 0
    # rotate each cycle with a junction to start at its first junction
    chains: list[Chain] = []
    chain_of: dict[tuple, int] = {}
    outlines: dict[int, list[list[tuple[int, bool]]]] = {}
    right_of = np.empty(n, np.int64)
    right_of[:] = left[twin]
    for c, (f, m) in enumerate(zip(cycle_first.tolist(), cycle_len.tolist())):
        edges = walk[f:f + m]
        piece = int(left[edges[0]])
        if piece < 0:
            continue  # the empty area and the outside get no outline
        if not has_junction[c]:
            u = undirected[edges]
            k = int(np.argmin(u))
            edges = np.roll(edges, -k)
            ident = ("loop", int(u[k]))
            forward = bool(d[edges[0]] < 2)
            pieces = [(edges, forward, ident, True)]
        else:
            at = np.flatnonzero(junction[edges])
            edges = np.roll(edges, -int(at[0]))
            at = at - at[0]
            bounds = np.r_[at, m]
            pieces = []
            for a, b in zip(bounds[:-1].tolist(), bounds[1:].tolist()):
                run = edges[a:b]
                ua, ub = int(undirected[run[0]]), int(undirected[run[-1]])
                forward = ua < ub or (ua == ub and d[run[0]] < 2)
                pieces.append((run, forward, ("run", min(ua, ub), max(ua, ub)), False))
        outline = []
        for run, forward, ident, closed in pieces:
            k = chain_of.get(ident)
            if k is None:
                k = chain_of[ident] = len(chains)
                canon = run if forward else twin[run[::-1]]
                corners = np.stack([i[canon], j[canon]], 1)
                end = corners[-1] + STEPS[d[canon[-1]]]
                if not closed:
                    corners = np.vstack([corners, end[None]])
                chains.append(Chain(corners, int(left[canon[0]]), int(right_of[canon[0]]), closed))
            outline.append((k, not forward))
        outlines.setdefault(piece, []).append(outline)
    return Partition(chains, outlines)

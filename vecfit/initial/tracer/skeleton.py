"""Centerlines of line work: a binary mask's skeleton as a graph of pixel chains, cleaned of
spurs and joined through its junctions into long paths.

The skeleton (cv2.ximgproc.thinning) is one pixel wide. Its pixels are linked to their
8-neighbours, less a diagonal link where an orthogonal pair joins the same two pixels (so
a staircase counts as a chain, not as a run of junctions). Pixels with one link are ends,
with three or more junction pixels; touching junction pixels are one junction. The chains
between ends and junctions are the graph's edges; a skeleton loop with neither is a cycle.

Spurs (an edge from a junction to an end, shorter than the line is wide: the skeleton
reaching into a corner or a bump of the outline) are removed, and the skeleton rebuilt,
until none is left. Then, at every junction, the two edges that continue each other most
nearly straight are paired (a T's bar, an X's two lines), so a path runs on through the
junction; edges left unpaired end there.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

# A spur is an end branch whose end's disk (its distance to the outline) lies within this
# many times the disk at its junction: it adds next to nothing to the shape (where a wide
# line turns a sharp outer corner, or its outline has a bump, the skeleton forks towards
# it). A short line out of a junction reaches past the junction's disk.
SPUR_LENGTH = 1.5
# Two edges meeting at a junction are one line where they continue each other within this
# many degrees of straight.
MAX_BEND = 50.0
# Each edge's direction at a junction: from the junction to its point this many half widths
# along (near the junction the skeleton bends towards the other lines).
DIRECTION_REACH = 1.5
# Two forks joined by an edge no longer than this many half widths (the wider one's) are a
# crossing, thinned.
BRIDGE = 2.5

OFFSETS = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)]


@dataclass
class Chain:
    """A centerline: pixel centres [N, 2] (x, y) in order, and whether it closes;
    ``crossings`` [J, 3]: the centre (x, y) and the line's half width there (the distance
    to the outline) of each crossing (a junction of four arms or more) the chain runs
    through or ends at, where its skeleton bends towards the other lines. (At a T the bar
    may bend for real: a book's spine meeting its cover's top in two arcs.)"""
    points: np.ndarray
    closed: bool
    crossings: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))


THINNINGS = {"zhang-suen": cv2.ximgproc.THINNING_ZHANGSUEN, "guo-hall": cv2.ximgproc.THINNING_GUOHALL}


def skeleton_of(mask: np.ndarray, thinning: str = "zhang-suen") -> np.ndarray:
    """The one-pixel skeleton of a bool mask (Zhang-Suen or Guo-Hall thinning), bool."""
    thin = cv2.ximgproc.thinning(mask.astype(np.uint8) * 255, thinningType=THINNINGS[thinning])
    return thin > 0


def _links(skel: np.ndarray) -> dict[int, list[int]]:
    """Each skeleton pixel's (flat index) linked neighbours (see the module docstring)."""
    h, w = skel.shape
    padded = np.pad(skel, 1)
    ys, xs = np.nonzero(skel)
    links: dict[int, list[int]] = {}
    for y, x in zip(ys.tolist(), xs.tolist()):
        near = []
        for dy, dx in OFFSETS:
            if not padded[y + 1 + dy, x + 1 + dx]:
                continue
            if dy and dx and (padded[y + 1 + dy, x + 1] or padded[y + 1, x + 1 + dx]):
                continue  # the orthogonal neighbours join these two already
            near.append((y + dy) * w + x + dx)
        links[y * w + x] = near
    return links


def _graph(links):
    """(junction id of each junction pixel, edges [(start pixel, end pixel, pixels)], cycles
    [pixels]) of the linked skeleton."""
    junction_of: dict[int, int] = {}
    for p, near in links.items():  # touching junction pixels form one junction (flood fill)
        if len(near) < 3 or p in junction_of:
            continue
        junction_id, stack = len(set(junction_of.values())), [p]
        junction_of[p] = junction_id
        while stack:
            q = stack.pop()
            for r in links[q]:
                if len(links[r]) >= 3 and r not in junction_of:
                    junction_of[r] = junction_id
                    stack.append(r)
    nodes = [p for p, near in links.items() if len(near) != 2]
    seen_steps: set[tuple[int, int]] = set()
    edges, visited = [], set()
    for start in nodes:
        for first in links[start]:
            if (start, first) in seen_steps:
                continue
            if start in junction_of and junction_of.get(first) == junction_of[start]:
                continue  # inside one junction
            path, prev, cur = [start, first], start, first
            while len(links[cur]) == 2:
                nxt = links[cur][0] if links[cur][0] != prev else links[cur][1]
                prev, cur = cur, nxt
                path.append(cur)
                if cur == start:
                    break
            seen_steps.add((start, first))
            seen_steps.add((path[-1], path[-2]))
            visited.update(path)
            edges.append(path)
    cycles = []
    for p, near in links.items():  # loops of chain pixels only
        if p in visited or len(near) != 2:
            continue
        path, prev, cur = [p], None, p
        while True:
            visited.add(cur)
            nxt = [q for q in links[cur] if q != prev]
            if not nxt or nxt[0] == p or nxt[0] in visited:
                break
            prev, cur = cur, nxt[0]
            path.append(cur)
        if len(path) >= 3:
            cycles.append(path)
    return junction_of, edges, cycles


def _prune(skel: np.ndarray, radius: np.ndarray) -> bool:
    """Remove the spurs of the skeleton (in place); whether any was removed."""
    links = _links(skel)
    junction_of, edges, _ = _graph(links)
    flat = skel.reshape(-1)
    removed = False
    for path in edges:
        a, b = path[0], path[-1]
        a_end, b_end = len(links[a]) == 1, len(links[b]) == 1
        if a_end == b_end:
            continue  # end to end (a line) or junction to junction
        junction, end = (b, a) if a_end else (a, b)
        w = skel.shape[1]
        reach = np.hypot(junction % w - end % w, junction // w - end // w) + float(radius.reshape(-1)[end])
        if reach <= SPUR_LENGTH * max(float(radius.reshape(-1)[junction]), 1.5):
            flat[[q for q in path if q not in junction_of]] = False
            removed = True
    return removed


def _crossings(ends_at: dict[int, list], edges: list, junction_of: dict[int, int], half_width: dict[int, float],
               w: int) -> set[int]:
    """The junctions where lines cross: four arms or more meet there, counting those of
    junctions a bridge of at most BRIDGE half widths (``half_width``: each junction's)
    away (thinning splits a crossing at an angle into two forks, each with an arm of each
    line, a bridge apart)."""
    arms = {j: len(ends) for j, ends in ends_at.items()}
    for path in edges:
        a, b = junction_of.get(path[0]), junction_of.get(path[-1])
        if a is None or b is None or a == b:
            continue
        if np.hypot(path[0] % w - path[-1] % w, path[0] // w - path[-1] // w) <= BRIDGE * max(half_width[a], half_width[b]):
            arms[a], arms[b] = arms[a] + len(ends_at[b]) - 2, arms[b] + len(ends_at[a]) - 2
    return {j for j, n in arms.items() if n >= 4}


def centerlines(mask: np.ndarray, radius: np.ndarray, thinning: str = "zhang-suen") -> list[Chain]:
    """The centerlines of a bool mask's line work; ``radius`` the distance transform of the
    mask (each pixel's distance to the nearest pixel outside). ``thinning``: of THINNINGS
    (Zhang-Suen keeps a T's bar straight through the junction; Guo-Hall keeps both lines
    of a fat X with short arms, where Zhang-Suen erodes one of them away)."""
    h, w = mask.shape
    skel = skeleton_of(mask, thinning)
    for _ in range(4):
        if not _prune(skel, radius):
            break
        skel = skeleton_of(skel, thinning)  # a removed spur may leave a pixel or two of staircase
    links = _links(skel)
    junction_of, edges, cycles = _graph(links)
    xy = lambda p: (p % w + 0.5, p // w + 0.5)  # noqa: E731  (pixel centres)
    flat_radius = radius.reshape(-1)

    # each junction's centre, and the edge ends meeting there: (edge, which end)
    members: dict[int, list[int]] = {}
    for p, j in junction_of.items():
        members.setdefault(j, []).append(p)
    centre = {j: np.mean([xy(p) for p in ps], axis=0) for j, ps in members.items()}
    half_width = {j: max(float(flat_radius[p]) for p in ps) for j, ps in members.items()}
    ends_at: dict[int, list[tuple[int, int]]] = {}
    for e, path in enumerate(edges):
        for which, p in ((0, path[0]), (1, path[-1])):
            if p in junction_of:
                ends_at.setdefault(junction_of[p], []).append((e, which))

    def direction(e: int, which: int, j: int) -> np.ndarray:
        path = edges[e] if which == 0 else edges[e][::-1]
        reach = DIRECTION_REACH * max(float(flat_radius[path[0]]), 1.5)
        k = min(len(path) - 1, max(2, int(round(reach))))
        v = np.asarray(xy(path[k])) - centre[j]
        n = float(np.hypot(*v))
        return v / n if n > 1e-9 else v

    crossings = _crossings(ends_at, edges, junction_of, half_width, w)

    # pair the edge ends that continue each other most nearly straight, greedily
    partner: dict[tuple[int, int], tuple[int, int]] = {}
    limit = np.cos(np.radians(MAX_BEND))
    for j, ends in ends_at.items():
        dirs = [direction(e, which, j) for e, which in ends]
        pairs = sorted(((float(dirs[a] @ -dirs[b]), a, b) for a in range(len(ends)) for b in range(a + 1, len(ends))),
                       reverse=True)
        used: set[int] = set()
        for straightness, a, b in pairs:
            if straightness < limit:
                break
            if a in used or b in used:
                continue
            used.update((a, b))
            partner[ends[a]] = ends[b]
            partner[ends[b]] = ends[a]

    chains, done = [], set()

    def walk(e: int, which: int) -> tuple[list, bool]:
        """From edge e's end `which`, on through paired junctions: (pixels, closed)."""
        pixels, start = [], (e, which)
        while True:
            done.add(e)
            path = edges[e] if which == 0 else edges[e][::-1]
            pixels.extend(path if not pixels or pixels[-1] != path[0] else path[1:])
            nxt = partner.get((e, 1 - which))
            if nxt is None:
                return pixels, False
            if nxt == start:
                return pixels, True
            e, which = nxt
            if e in done:
                return pixels, False

    for e, path in enumerate(edges):  # open chains start at an unpaired end
        for which in (0, 1):
            if e not in done and (e, which) not in partner:
                pixels, closed = walk(e, which)
                chains.append((pixels, closed))
    for e in range(len(edges)):  # what is left goes round through junctions
        if e not in done:
            chains.append(walk(e, 0))
    chains += [(c, True) for c in cycles]
    out = []
    for pixels, closed in chains:
        if closed and len(pixels) > 1 and pixels[-1] == pixels[0]:
            pixels = pixels[:-1]
        points = np.array([xy(p) for p in pixels], np.float64)
        # an end at a junction goes to the junction's centre (into the line it meets)
        for k in ((0, -1) if not closed else ()):
            j = junction_of.get(pixels[k])
            if j is not None:
                points[k] = centre[j]
        passed = sorted({junction_of[p] for p in pixels if p in junction_of and junction_of[p] in crossings})
        crossed = np.array([[*centre[j], half_width[j]] for j in passed], np.float64).reshape(-1, 3)
        out.append(Chain(points, closed, crossed))
    return out

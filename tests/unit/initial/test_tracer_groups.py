"""Compound paths: regions of one colour in one path (vecfit/initial/tracer/groups.py)."""
from __future__ import annotations

import re

import numpy as np
import pytest

from vecfit.initial.tracer import TraceSettings, trace_image
from vecfit.initial.tracer.groups import ward_groups

from test_trace import coverage, paint, psnr, render


def greedy_ward(area, color, budget):
    """The reference: merge the cheapest pair of groups, one merge at a time."""
    groups = [[i] for i in range(len(area))]
    size = list(map(float, area))
    centre = [np.asarray(c, float) for c in color]
    while len(groups) > budget:
        best = None
        for i in range(len(groups)):
            for j in range(i + 1, len(groups)):
                cost = size[i] * size[j] / (size[i] + size[j]) * float(((centre[i] - centre[j]) ** 2).sum())
                if best is None or cost < best[0]:
                    best = (cost, i, j)
        _, i, j = best
        centre[i] = (size[i] * centre[i] + size[j] * centre[j]) / (size[i] + size[j])
        size[i] += size[j]
        groups[i] += groups.pop(j)
        size.pop(j)
        centre.pop(j)
    return sorted(sorted(g) for g in groups)


@pytest.mark.parametrize("seed", range(6))
def test_ward_groups_merge_as_the_cheapest_pair_first(seed):
    rng = np.random.default_rng(seed)
    n = 25
    area = rng.integers(1, 200, n).astype(float)
    color = rng.uniform(0, 1, (n, 3))
    for budget in (1, 4, 11, 25, 40):
        label = ward_groups(area, color, budget)
        assert label.max() + 1 == min(budget, n)
        got = sorted(sorted(np.flatnonzero(label == g).tolist()) for g in range(label.max() + 1))
        assert got == greedy_ward(area, color, budget)


def spots(w=120, h=80):
    """Twelve dark spots and three red bars on a light ground: flat art whose designer
    would draw two paths (the spots, the bars)."""
    layers = []
    for k in range(12):
        cx, cy = 12 + (k % 6) * 19, 18 + (k // 6) * 22
        layers.append((coverage(lambda x, y, cx=cx, cy=cy: (x - cx) ** 2 + (y - cy) ** 2 < 5.5 ** 2, w, h),
                       (0.15, 0.12, 0.1)))
    for k in range(3):
        layers.append((coverage(lambda x, y, k=k: (x > 10 + 36 * k) & (x < 36 + 36 * k) & (y > 60) & (y < 70),
                                w, h), (0.8, 0.1, 0.15)))
    return paint(layers, w, h, background=(0.95, 0.93, 0.85))


def test_flat_art_draws_every_piece_at_a_designers_path_count(tmp_path):
    image = spots()
    grouped = trace_image(image, TraceSettings.defaults(paths=2))
    single = trace_image(image, TraceSettings.defaults(paths=2, compound=False))
    assert grouped.paths == 2  # the spots' path, the bars' path (over the background rect)
    spot_path = [d for d in re.findall(r' d="([^"]*)"', grouped.svg) if d.count("M") + d.count("m") == 12]
    assert len(spot_path) == 1  # twelve pieces, one path
    out, before = render(grouped, 120, 80, tmp_path), render(single, 120, 80, tmp_path)
    assert psnr(image[..., :3], out[..., :3]) >= 26
    assert psnr(image[..., :3], out[..., :3]) >= psnr(image[..., :3], before[..., :3]) + 8


def test_photographs_keep_a_path_per_region():
    rng = np.random.default_rng(0)
    noise = rng.uniform(0, 1, (48, 64, 3)).astype(np.float32)
    image = np.concatenate([noise, np.ones_like(noise[..., :1])], 2)
    a = trace_image(image, TraceSettings.defaults(paths=20))
    b = trace_image(image, TraceSettings.defaults(paths=20, compound=False))
    assert a.svg == b.svg

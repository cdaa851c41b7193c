"""One long path at 64 x 64 px, both modes: what a segment costs (issue 28).

    python benchmarks/long_paths.py [--threads 2] [--repeats 3] [--sizes 3000,30000,300000]

Scenes (a 64-unit canvas rendered at 64 px, one sample per pixel as `vecfit render`
--samples 1):
  walk      one closed path of N cubics, a random walk of 2-unit steps, filled;
  wide      N mixed lines / quadratics / cubics (a walk of 6-unit steps), a linear
            gradient fill and stroke-width 1e7 (the fuzzer's failing case);
  across    N cubics whose control points are spread over the whole canvas (each
            segment crosses every row of tiles: the worst case, where a segment reaches
            most pixels), filled.
The paths are built as Scenes (300,000 segments is over the SVG reader's limit). Each row:
the median wall time of `vecfit.render` over --repeats runs (packing included), and that
divided by N. Targets: the analytical mode within a small factor of Monte Carlo, and
<= 1 s for 30,000 segments.
"""
from __future__ import annotations

import argparse
import random
import time
import warnings

import common  # noqa: F401  (OMP_WAIT_POLICY before torch)

import numpy as np
import torch

import vecfit
from vecfit.scene import Path

NS = 'xmlns="http://www.w3.org/2000/svg"'
TEMPLATES = {
    "walk": '<path d="M 0 0 L 1 1 Z" fill="#3a6"/>',
    "wide": ('<defs><linearGradient id="g"><stop offset="0" stop-color="red"/><stop offset="1" stop-color="blue"/>'
             '</linearGradient></defs><path d="M 0 0 L 1 1 Z" fill="url(#g)" stroke="green" stroke-width="1e7"/>'),
    "across": '<path d="M 0 0 L 1 1 Z" fill="#3a6" fill-rule="evenodd"/>',
}


def geometry(kind: str, n: int, seed: int = 0) -> Path:
    rng = random.Random(seed)
    degrees = np.array([3] * n if kind != "wide" else [(1, 2, 3)[i % 3] for i in range(n)], dtype=np.int64)
    step = {"walk": 2.0, "wide": 6.0, "across": None}[kind]
    x = y = 32.0
    pts = [(x, y)]
    for _ in range(int(degrees.sum()) - 1):  # closed: the last segment ends at the start
        if step is None:
            x, y = rng.uniform(0, 64), rng.uniform(0, 64)
        else:
            x = min(max(x + rng.uniform(-step, step), 0.0), 64.0)
            y = min(max(y + rng.uniform(-step, step), 0.0), 64.0)
        pts.append((x, y))
    return Path(points=torch.tensor(pts, dtype=torch.float32), degrees=degrees, subpaths=[(0, n, True)])


def scene_of(kind: str, n: int, tmp) -> vecfit.Scene:
    svg = tmp / f"{kind}.svg"
    svg.write_text(f'<svg {NS} width="64" height="64">{TEMPLATES[kind]}</svg>')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(svg)
    scene.shapes[0].geometry = geometry(kind, n)
    return scene


def main():
    import tempfile
    from pathlib import Path as FsPath
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--sizes", default="3000,30000,300000")
    parser.add_argument("--kinds", default="walk,wide,across")
    a = parser.parse_args()
    sizes = [int(s) for s in a.sizes.split(",")]
    print(f"{'path':7} {'segments':>9} {'mc s':>8} {'analytic s':>11} {'mc us/seg':>10} {'an. us/seg':>11}")
    with tempfile.TemporaryDirectory() as tmp:
        for kind in a.kinds.split(","):
            for n in sizes:
                scene = scene_of(kind, n, FsPath(tmp))
                row = {}
                for mode in ("mc", "analytic"):
                    times = []
                    for _ in range(a.repeats):
                        start = time.perf_counter()
                        image = vecfit.render(scene, 64, 64, samples=1, mode=mode, threads=a.threads)
                        times.append(time.perf_counter() - start)
                    assert torch.isfinite(image).all()
                    row[mode] = float(np.median(times))
                print(f"{kind:7} {n:9} {row['mc']:8.3f} {row['analytic']:11.3f} {1e6 * row['mc'] / n:10.2f} "
                      f"{1e6 * row['analytic'] / n:11.2f}", flush=True)


if __name__ == "__main__":
    main()

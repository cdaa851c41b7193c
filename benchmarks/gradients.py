"""Backward speed: forward and backward times on the benchmark scenes, and a painterly
workload (random open cubic strokes) as one Adam iteration would run it.

    python benchmarks/gradients.py [--threads 2] [--repeats 5]

Loss = sum of the squared image (as in diffvg's timings). Times are medians after a
warm-up; "iteration" is forward + backward + an Adam step.
"""
from __future__ import annotations

import argparse
import statistics
import time

from common import scene_workload, timed  # first: it sets up threads before torch loads

import numpy as np
import torch

import vecfit
from vecfit.scene import Path, Scene, Shape, Solid


def strokes_scene(n, size, seed=0):
    """n open strokes of 1-3 cubic segments, widths 1-5 px, random colours with alpha."""
    rng = np.random.default_rng(seed)
    shapes = []
    for _ in range(n):
        segs = int(rng.integers(1, 4))
        start = rng.uniform(0, size, 2)
        pts = [start]
        for _ in range(segs):
            for _ in range(3):
                pts.append(pts[-1] + rng.normal(0, size / 12, 2))
        path = Path(points=torch.tensor(np.array(pts), dtype=torch.float32, requires_grad=True),
                    degrees=np.full(segs, 3), subpaths=[(0, segs, False)])
        shapes.append(Shape(geometry=path, stroke=Solid(torch.tensor(rng.uniform(0, 1, 4), dtype=torch.float32,
                                                                     requires_grad=True)),
                            stroke_width=torch.tensor(float(rng.uniform(1, 5)), requires_grad=True),
                            linecap="round", linejoin="round"))
    return Scene(width=size, height=size, shapes=shapes)


def strokes_workload(size, threads, repeats):
    scene = strokes_scene(256, size)
    params = scene.parameters()
    tensors = params["points"] + params["colors"] + params["stroke_widths"]
    opt = torch.optim.Adam(tensors, lr=0.01)
    target = torch.rand(size, size, 4, generator=torch.Generator().manual_seed(1))

    def run():
        t0 = time.perf_counter()
        opt.zero_grad()
        img = vecfit.render(scene, samples=2, threads=threads)
        t1 = time.perf_counter()
        ((img - target) ** 2).sum().backward()
        t2 = time.perf_counter()
        opt.step()
        t3 = time.perf_counter()
        return t1 - t0, t2 - t1, t3 - t0
    return timed(run, repeats)


def growth(size, threads, iterations=100):
    """Time per Adam iteration at the start and at the end of a run on the painterly
    workload (diffvg's grows by half as the strokes spread). Widths stay in the workload's
    1-5 px, as diffvg's painterly script clamps them to [1, max_width]."""
    scene = strokes_scene(256, size, seed=3)
    params = scene.parameters()
    opt = torch.optim.Adam([{"params": params["points"], "lr": 1.0},
                            {"params": params["colors"], "lr": 0.01},
                            {"params": params["stroke_widths"], "lr": 0.1}])
    yy, xx = torch.meshgrid(torch.linspace(0, 1, size), torch.linspace(0, 1, size), indexing="ij")
    target = torch.stack([xx, yy, 1 - xx, torch.ones_like(xx)], dim=-1)
    times = []
    for _ in range(iterations):
        t0 = time.perf_counter()
        opt.zero_grad()
        img = vecfit.render(scene, samples=2, threads=threads)
        ((img - target) ** 2).sum().backward()
        opt.step()
        with torch.no_grad():
            for w in params["stroke_widths"]:
                w.clamp_(1.0, 5.0)  # the workload's 1-5 px, clamped as diffvg's painterly script does
            for c in params["colors"]:
                c.clamp_(0, 1)
        times.append(time.perf_counter() - t0)
    return statistics.median(times[1:11]), statistics.median(times[-10:])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    print(f"threads={args.threads}, median of {args.repeats}; seconds")
    print(f"{'workload':34s} {'forward':>9s} {'backward':>9s} {'iteration':>10s}")
    for name in ["tiger", "mcseem2", "boston"]:
        f, b = scene_workload(name, "mc", 2, args.threads, args.repeats)
        print(f"{name + ', MC 2x2':34s} {f:9.3f} {b:9.3f} {'':>10s}")
    for name in ["tiger", "mcseem2", "boston"]:
        f, b = scene_workload(name, "analytic", 1, args.threads, args.repeats)
        print(f"{name + ', analytic 1x1':34s} {f:9.3f} {b:9.3f} {'':>10s}")
    for size in (256, 512):
        f, b, it = strokes_workload(size, args.threads, args.repeats)
        print(f"{f'256 strokes at {size}x{size}, MC 2x2':34s} {f:9.3f} {b:9.3f} {it:10.3f}")
    for size in (256, 512):
        first, last = growth(size, args.threads)
        print(f"painterly run at {size}x{size}: iterations 2-11 {first:.3f} s, last 10 of 100 {last:.3f} s "
              f"({last / first:.2f}x)")


if __name__ == "__main__":
    main()

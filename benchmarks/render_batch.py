"""A training step's rendering: B digit-like scenes (4 stroked cubics each, as
examples/vector_digits.py's decoder makes them) at 32x32, forward + backward, rendered
by one vecfit.render_batch call against one vecfit.render call per scene. Medians of
interleaved runs; also where a batch's time goes (packing in Python, the core's passes).

    python benchmarks/render_batch.py [--batch 64] [--threads 2] [--repeats 7]
"""
from __future__ import annotations

import argparse
import statistics
import time

import common  # noqa: F401  (first: it sets up threads before torch loads)
import numpy as np
import torch

import vecfit
from vecfit.scene import Path, Scene, Shape, Solid
from vecfit.renderer.stopwatch import Stopwatch, lap


def digit_scenes(batch: int, size: int = 32, strokes: int = 4, seed: int = 0) -> tuple[list[Scene], list]:
    rng = np.random.default_rng(seed)
    points = torch.tensor(rng.uniform(4, size - 4, (batch, strokes, 4, 2)), dtype=torch.float32, requires_grad=True)
    widths = torch.tensor(rng.uniform(1, 2.5, (batch, strokes)), dtype=torch.float32, requires_grad=True)
    black = torch.tensor([0.0, 0.0, 0.0, 1.0])
    scenes = [Scene(width=size, height=size, shapes=[
        Shape(geometry=Path(points=points[b, k], degrees=np.array([3]), subpaths=[(0, 1, False)]),
              stroke=Solid(black), stroke_width=widths[b, k], linecap="round", linejoin="round")
        for k in range(strokes)]) for b in range(batch)]
    return scenes, [points, widths]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--batch", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    target = torch.rand(args.batch, 32, 32, 4, generator=torch.Generator().manual_seed(1))

    def batched():
        scenes, leaves = digit_scenes(args.batch)
        images = vecfit.render_batch(scenes, 32, 32, samples=2, background=(1, 1, 1), threads=args.threads)
        ((images - target) ** 2).mean().backward()

    def one_by_one():
        scenes, leaves = digit_scenes(args.batch)
        images = torch.stack([vecfit.render(s, 32, 32, samples=2, background=(1, 1, 1), threads=args.threads)
                              for s in scenes])
        ((images - target) ** 2).mean().backward()

    times = {"render_batch": [], "render per scene": []}
    fns = {"render_batch": batched, "render per scene": one_by_one}
    with Stopwatch() as sw:
        for r in range(args.repeats + 1):
            for name, fn in fns.items():
                start = time.perf_counter()
                fn()
                seconds = time.perf_counter() - start
                lap(seconds)
                if r:
                    times[name].append(seconds)
    print(f"B = {args.batch} digit scenes at 32x32, MC 2x2, forward + backward, {args.threads} threads, "
          f"median of {args.repeats}")
    print()
    print("| how | per batch (s) | per scene (ms) | ratio |")
    print("|---|---|---|---|")
    base = statistics.median(times["render per scene"])
    for name in fns:
        t = statistics.median(times[name])
        print(f"| {name} | {t:.4f} | {1000 * t / args.batch:.2f} | {t / base:.2f}x |")
    batch_laps = sw.laps[2::2]  # render_batch's laps after the warm-up round
    print()
    print("render_batch's time by phase (median seconds per batch):")
    print()
    print("| phase | seconds |")
    print("|---|---|")
    for name in sorted({k for l in batch_laps for k in l}):
        print(f"| {name} | {statistics.median(l.get(name, 0.0) for l in batch_laps):.4f} |")


if __name__ == "__main__":
    main()

"""The pixel filter radius's gradient (pydiffvg's PixelFilter.radius), issue 41.

    python benchmarks/filter_radius.py [--iterations 100]

1. dL/dr against central differences of the same renderer (same seed both sides, a step
   of 10% of r; the analytical mode 1%), L = sum(W * image) with W the difference between
   a wide filter's image and a sharp one, on tests/oracles/test_filter_radius.py's scene,
   r = 1.3, means over seeds: per filter, mode and samples per pixel.
2. diffvg's apps/optimize_pixel_filter.py as it runs on the drop-in: a circle of radius 40
   on 256 px, Adam at lr 1.0 on a Hann filter's radius from 1 towards the target's 8,
   2 x 2 samples with a new seed each step. Prints the loss at the first and last steps,
   the radius, and the loss at the target's own samples (which the noise of two 2 x 2
   renders does not hold up).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import common  # noqa: F401  (first: it sets up threads before torch loads)
import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "oracles"))

import diffvg  # noqa: E402
import pydiffvg  # noqa: E402
import test_filter_radius as oracle  # noqa: E402


def gradient_table():
    print("| filter | mode | samples | seeds | gradient | central difference | relative |")
    print("|---|---|---|---|---|---|---|")
    for filter in ("tent", "gaussian", "parabolic", "hann"):
        for samples, seeds in ((2, 64), (4, 32), (8, 16), (16, 8)):
            oracle.SAMPLES, oracle.SEEDS = samples, seeds
            ad, fd = oracle.means("mc", filter)
            print(f"| {filter} | MC | {samples}x{samples} | {seeds} | {ad:.3f} | {fd:.3f} | {100 * (ad - fd) / abs(fd):+.1f}% |",
                  flush=True)
        ad, fd = oracle.means("analytic", filter)
        print(f"| {filter} | analytical | 1x1 | 1 | {ad:.3f} | {fd:.3f} | {100 * (ad - fd) / abs(fd):+.1f}% |", flush=True)


def pixel_filter_script(iterations):
    size = 256
    circle = pydiffvg.Circle(radius=torch.tensor(40.0), center=torch.tensor([128.0, 128.0]))
    group = pydiffvg.ShapeGroup(shape_ids=torch.tensor([0]), fill_color=torch.tensor([0.3, 0.6, 0.3, 1.0]))

    def render(radius, seed):
        args = pydiffvg.RenderFunction.serialize_scene(
            size, size, [circle], [group], filter=pydiffvg.PixelFilter(type=diffvg.FilterType.hann, radius=radius))
        return pydiffvg.RenderFunction.apply(size, size, 2, 2, seed, None, *args)

    with torch.no_grad():
        target = render(torch.tensor(8.0), 0)
    radius = torch.tensor(1.0, requires_grad=True)
    optimizer = torch.optim.Adam([radius], lr=1.0)
    losses, radii = [], []
    start = time.perf_counter()
    for t in range(iterations):
        optimizer.zero_grad()
        loss = (render(radius, t + 1) - target).pow(2).sum()
        loss.backward()
        optimizer.step()
        losses.append(float(loss.detach()))
        radii.append(float(radius.detach()))
    seconds = time.perf_counter() - start

    def at_target_samples(r):
        with torch.no_grad():
            return float((render(torch.tensor(r), 0) - target).pow(2).sum())
    last = radii[-10:]
    print(f"optimize_pixel_filter.py, {iterations} steps ({seconds:.1f} s): loss {losses[0]:.1f} -> {losses[-1]:.1f} "
          f"({losses[-1] / losses[0]:.2f}x; last 10 steps' mean {np.mean(losses[-10:]):.1f}); radius {radii[-1]:.2f} "
          f"(last 10 steps {min(last):.2f}-{max(last):.2f}); at the target's samples "
          f"{at_target_samples(1.0):.1f} -> {at_target_samples(radii[-1]):.1f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--iterations", type=int, default=100)
    args = ap.parse_args()
    gradient_table()
    pixel_filter_script(args.iterations)


if __name__ == "__main__":
    main()

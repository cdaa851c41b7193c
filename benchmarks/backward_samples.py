"""What the Monte Carlo backward pass's sample counts cost: the core's interior and
boundary phases on real traces for a few (interior_samples, boundary_samples) settings,
measured interleaved (setting A, B, C, A, B, C, ...) so that load from other work on the
machine falls on all settings alike. Forward at 2x2 samples, loss = sum of a fixed
random weighting of the image, as a refine iteration's backward sees it.

    python benchmarks/backward_samples.py [--threads 2] [--repeats 7] [--scenes peppers,kitty]
"""
from __future__ import annotations

import argparse
import statistics

from common import SHARED  # first: it sets up threads before torch loads

import torch


import vecfit
from vecfit import _core

SCENES = {"peppers": SHARED / "data" / "photos" / "peppers.svg",
          "kitty": SHARED / "data" / "photos" / "kitty.svg",
          "tiger": SHARED / "data" / "scenes" / "tiger.svg"}
# (interior_samples, boundary_samples): 0 = all of a pixel's 2x2 samples
SETTINGS = [(0, 2.0), (1, 2.0), (2, 2.0), (1, 1.0)]


def one_pass(scene, tensors, weight, threads, interior, boundary, seed):
    for t in tensors:
        t.grad = None
    h, w = weight.shape[:2]
    image = vecfit.render(scene, w, h, samples=2, seed=seed, threads=threads,
                          interior_samples=interior, boundary_samples=boundary)
    _core.phase_seconds()  # only the backward's phases below
    (image * weight).sum().backward()
    return _core.phase_seconds()


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--scenes", default="peppers,kitty")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    print("| scene | interior samples | boundary samples | backward interior (s) | backward boundary (s) | both |")
    print("|---|---|---|---|---|---|")
    for name in args.scenes.split(","):
        scene = vecfit.load_svg(SCENES[name])
        params = scene.parameters()
        tensors = [t for kind in ("points", "colors", "stroke_widths") for t in params.get(kind, [])]
        for t in tensors:
            t.requires_grad_(True)
        w, h = round(scene.width), round(scene.height)
        weight = torch.rand(h, w, 4, generator=torch.Generator().manual_seed(0))
        times = {s: [] for s in SETTINGS}
        for r in range(args.repeats + 1):
            for s in SETTINGS:
                ph = one_pass(scene, tensors, weight, args.threads, *s, seed=r)
                if r:  # the first round warms up
                    times[s].append((ph.get("backward interior", 0.0), ph.get("backward boundary", 0.0)))
        for s in SETTINGS:
            interior = statistics.median(t[0] for t in times[s])
            boundary = statistics.median(t[1] for t in times[s])
            both = statistics.median(t[0] + t[1] for t in times[s])
            label = "all (4)" if s[0] == 0 else str(s[0])
            print(f"| {name} {w}x{h} | {label} | {s[1]:g} | {interior:.4f} | {boundary:.4f} | {both:.4f} |")


if __name__ == "__main__":
    main()

"""One long path at 64 x 64 px, both modes, forward and backward: what a segment costs
(issue 28).

    python benchmarks/long_paths.py [--threads 2] [--repeats 3] [--samples 2]
                                    [--sizes 3000,30000,300000] [--kinds walk,wide,across]
                                    [--budget 120]

Scenes (a 64-unit canvas rendered at 64 px; --samples N: N x N samples per pixel, 2 as
`vecfit render` by default):
  walk      one closed path of N cubics, a random walk of 2-unit steps, filled;
  wide      N mixed lines / quadratics / cubics (a walk of 6-unit steps), a linear
            gradient fill and stroke-width 1e7 (the fuzzer's failing case);
  across    N cubics whose control points are spread over the whole canvas (each
            segment crosses every row of tiles: the worst case, where a segment reaches
            most pixels), filled;
  canvas    issue 41's case: N cubics spread over a 200-unit canvas (viewBox) drawn at
            64 px, filled and stroked 2 units wide (run the analytical mode with
            --samples 1, as the issue does).
The paths are built as Scenes (300,000 segments is over the SVG reader's limit). Each row:
the median wall time over --repeats of `vecfit.render` (forward: packing included) and
of the backward pass of a random image adjoint into every point (backward), and each
divided by N. A pass stopped at --budget seconds (the core cancels it as it would for a
Ctrl-C) shows `>` and the budget, and the larger sizes of that path and mode are not run.
Targets: a 64-px render of 30,000 segments in <= 1 s on 2 threads in either mode.
"""
from __future__ import annotations

import argparse
import random
import signal
import time
import warnings
from contextlib import contextmanager

import common  # noqa: F401  (OMP_WAIT_POLICY before torch)
from machine import machine_unit

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
    "canvas": '<path d="M 0 0 L 1 1 Z" fill="#3a6" stroke="#123" stroke-width="2"/>',
}
SPAN = {"canvas": 200.0}  # user units the control points spread over (others: the 64 px canvas)


def geometry(kind: str, n: int, seed: int = 0) -> Path:
    rng = random.Random(seed)
    degrees = np.array([3] * n if kind != "wide" else [(1, 2, 3)[i % 3] for i in range(n)], dtype=np.int64)
    step = {"walk": 2.0, "wide": 6.0, "across": None, "canvas": None}[kind]
    span = SPAN.get(kind, 64.0)
    x = y = span / 2
    pts = [(x, y)]
    for _ in range(int(degrees.sum()) - 1):  # closed: the last segment ends at the start
        if step is None:
            x, y = rng.uniform(0, span), rng.uniform(0, span)
        else:
            x = min(max(x + rng.uniform(-step, step), 0.0), 64.0)
            y = min(max(y + rng.uniform(-step, step), 0.0), 64.0)
        pts.append((x, y))
    return Path(points=torch.tensor(pts, dtype=torch.float32), degrees=degrees, subpaths=[(0, n, True)])


def scene_of(kind: str, n: int, tmp) -> vecfit.Scene:
    svg = tmp / f"{kind}.svg"
    span = SPAN.get(kind, 64.0)
    svg.write_text(f'<svg {NS} width="64" height="64" viewBox="0 0 {span:g} {span:g}">{TEMPLATES[kind]}</svg>')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(svg)
    scene.shapes[0].geometry = geometry(kind, n)
    return scene


class Overtime(Exception):
    pass


@contextmanager
def deadline(seconds: float):
    """Raises Overtime in the block after `seconds` (the core polls for signals while it
    works and cancels its call)."""
    def alarm(signum, frame):
        raise Overtime
    previous = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def timed(scene, mode: str, samples: int, threads: int, repeats: int, budget: float):
    """Median seconds of the forward pass and of the backward pass (None: over budget)."""
    points = scene.shapes[0].geometry.points
    points.requires_grad_(True)
    forward, backward = [], []
    adjoint = torch.rand(64, 64, 4, generator=torch.Generator().manual_seed(0))
    for _ in range(repeats):
        points.grad = None
        try:
            with deadline(budget):
                start = time.perf_counter()
                image = vecfit.render(scene, 64, 64, samples=samples, mode=mode, threads=threads)
                forward.append(time.perf_counter() - start)
        except Overtime:
            return None, None
        assert torch.isfinite(image).all()
        try:
            with deadline(budget):
                start = time.perf_counter()
                image.backward(adjoint)
                backward.append(time.perf_counter() - start)
        except Exception as e:  # (Overtime, perhaps as autograd passes it on)
            if "Overtime" not in repr(e) and not isinstance(e, Overtime):
                raise
            return float(np.median(forward)), None
        assert torch.isfinite(points.grad).all()
    return float(np.median(forward)), float(np.median(backward))


def main():
    import tempfile
    from pathlib import Path as FsPath
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--samples", type=int, default=2)
    parser.add_argument("--sizes", default="3000,30000,300000")
    parser.add_argument("--kinds", default="walk,wide,across")
    parser.add_argument("--modes", default="mc,analytic")
    parser.add_argument("--budget", type=float, default=120.0, help="seconds a pass may take")
    a = parser.parse_args()
    sizes = [int(s) for s in a.sizes.split(",")]
    unit = machine_unit()
    print(f"machine unit R = {unit:.4f} s (benchmarks/machine.py)")
    print(f"{'path':7} {'segments':>9} {'mode':9} {'forward s':>10} {'backward s':>11} {'fwd us/seg':>11} "
          f"{'bwd us/seg':>11} {'forward R':>10} {'backward R':>11}")
    cell = lambda v, w: f"{v:{w}.3f}" if v is not None else f"{'>' + format(a.budget, 'g'):>{w}}"  # noqa: E731
    per = lambda v, n, w: f"{1e6 * v / n:{w}.2f}" if v is not None else f"{'-':>{w}}"  # noqa: E731
    with tempfile.TemporaryDirectory() as tmp:
        for kind in a.kinds.split(","):
            for mode in a.modes.split(","):
                over = False
                for n in sizes:
                    if over:
                        print(f"{kind:7} {n:9} {mode:9} {'-':>10} {'-':>11} (not run: a smaller size was over "
                              f"the budget)", flush=True)
                        continue
                    scene = scene_of(kind, n, FsPath(tmp))
                    fwd, bwd = timed(scene, mode, a.samples, a.threads, a.repeats, a.budget)
                    over = fwd is None or bwd is None
                    in_r = lambda v, w: f"{v / unit:{w}.2f}" if v is not None else f"{'-':>{w}}"  # noqa: E731
                    print(f"{kind:7} {n:9} {mode:9} {cell(fwd, 10)} {cell(bwd, 11)} {per(fwd, n, 11)} "
                          f"{per(bwd, n, 11)} {in_r(fwd, 10)} {in_r(bwd, 11)}", flush=True)


if __name__ == "__main__":
    main()

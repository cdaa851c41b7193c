"""pydiffvg's eval_positions: the SDF (and colour) at given points, and diffvg's
apps/test_eval_positions.py as it runs on the drop-in.

    python benchmarks/eval_positions.py [--steps 200] [--positions 1000] [--repeats 9]

Rows: one call at N positions of a 1-shape scene (a circle, as the script's) and of a
6-shape one, forward and forward+backward (medians of --repeats); then the script itself
(256 x 256 canvas, the target SDF image, 200 Adam steps each evaluating the SDF at 1,000
random positions), its wall time and the fitted circle. Targets (issue 28): 1,000
positions of a 1-shape scene in <= 2 ms; the script in <= 10 s.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import common  # noqa: F401  (OMP_WAIT_POLICY before torch)

import torch

# (benchmarks/pydiffvg.py would shadow the module)
sys.path = [p for p in sys.path if Path(p or ".").resolve() != Path(__file__).resolve().parent]
import pydiffvg  # noqa: E402


def few_shapes():
    """Six groups: circle, ellipse, rect, a closed cubic path, an open stroke, a polygon."""
    t = torch.tensor
    shapes = [pydiffvg.Circle(t(40.0), t([80.0, 90.0])), pydiffvg.Ellipse(t([60.0, 30.0]), t([170.0, 60.0])),
              pydiffvg.Rect(t([20.0, 150.0]), t([120.0, 230.0])),
              pydiffvg.Path(t([2, 2, 2]), t([[150.0, 120.0], [190, 90], [240, 110], [240, 160], [235, 200],
                                             [190, 230], [160, 200], [130, 170], [140, 140]]), True),
              pydiffvg.Path(t([2]), t([[20.0, 20.0], [80, 10], [150, 60], [230, 20]]), False, stroke_width=t(3.0)),
              pydiffvg.Polygon(t([[130.0, 240.0], [250, 250], [180, 180]]), True)]
    groups = [pydiffvg.ShapeGroup(t([i]), t([0.2 + 0.1 * i, 0.5, 0.3, 1.0]),
                                  stroke_color=t([0.0, 0.0, 0.0, 1.0]) if i >= 3 else None) for i in range(6)]
    return shapes, groups


def circle_scene(radius=40.0, center=(128.0, 128.0)):
    circle = pydiffvg.Circle(radius=torch.tensor(radius), center=torch.tensor(center))
    group = pydiffvg.ShapeGroup(shape_ids=torch.tensor([0]), fill_color=torch.tensor([0.3, 0.6, 0.3, 1.0]))
    return [circle], [group]


def timed_call(shapes, groups, n, grad, repeats, output=pydiffvg.OutputType.sdf):
    positions = torch.rand(n, 2, generator=torch.Generator().manual_seed(0)) * 256
    params = [t for s in shapes for t in vars(s).values() if isinstance(t, torch.Tensor) and t.is_floating_point()]
    times = []
    for _ in range(repeats + 2):
        for t in params:
            t.requires_grad_(grad)
            t.grad = None
        start = time.perf_counter()
        args = pydiffvg.RenderFunction.serialize_scene(256, 256, shapes, groups, output_type=output,
                                                       eval_positions=positions)
        out = pydiffvg.RenderFunction.apply(256, 256, 0, 0, 0, None, *args)
        if grad:
            out.pow(2).mean().backward()
        times.append(time.perf_counter() - start)
    for t in params:
        t.requires_grad_(False)
    return statistics.median(times[2:])


def script(steps: int, n: int):
    """apps/test_eval_positions.py, its prints and image writes left out."""
    render = pydiffvg.RenderFunction.apply
    shapes, groups = circle_scene()
    circle, group = shapes[0], groups[0]
    args = pydiffvg.RenderFunction.serialize_scene(256, 256, shapes, groups, output_type=pydiffvg.OutputType.sdf)
    target = render(256, 256, 2, 2, 0, None, *args) / 256
    radius_n = torch.tensor(20.0 / 256.0, requires_grad=True)
    center_n = torch.tensor([108.0 / 256.0, 138.0 / 256.0], requires_grad=True)
    color = torch.tensor([0.3, 0.2, 0.8, 1.0], requires_grad=True)
    optimizer = torch.optim.Adam([radius_n, center_n, color], lr=1e-2)
    start = time.perf_counter()
    for t in range(steps):
        optimizer.zero_grad()
        circle.radius = radius_n * 256
        circle.center = center_n * 256
        group.fill_color = color
        eval_positions = torch.rand(n, 2) * 256
        grid = (eval_positions / 256.0) * 2.0 - 1.0
        args = pydiffvg.RenderFunction.serialize_scene(256, 256, shapes, groups, output_type=pydiffvg.OutputType.sdf,
                                                       eval_positions=eval_positions)
        samples = render(256, 256, 0, 0, t + 1, None, *args) / 256
        target_sampled = torch.nn.functional.grid_sample(target.view(1, 1, 256, 256), grid.view(1, -1, 1, 2),
                                                         mode="nearest", align_corners=False)
        loss = (samples - target_sampled).pow(2).mean()
        loss.backward()
        optimizer.step()
    seconds = time.perf_counter() - start
    return seconds, float(radius_n.detach()) * 256, [round(float(v), 2) for v in center_n.detach() * 256]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--positions", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=9)
    a = parser.parse_args()
    torch.manual_seed(0)
    print(f"{'scene':10} {'output':7} {'positions':>9} {'forward ms':>11} {'fwd+bwd ms':>11}")
    for name, (shapes, groups) in (("1 circle", circle_scene()), ("6 shapes", few_shapes())):
        for output in (pydiffvg.OutputType.sdf, pydiffvg.OutputType.color):
            for n in (100, a.positions):
                f = timed_call(shapes, groups, n, False, a.repeats, output)
                b = timed_call(shapes, groups, n, True, a.repeats, output)
                print(f"{name:10} {output.name:7} {n:9} {1000 * f:11.2f} {1000 * b:11.2f}")
    seconds, radius, center = script(a.steps, a.positions)
    print(f"test_eval_positions.py: {a.steps} steps x {a.positions} positions in {seconds:.2f} s "
          f"({1000 * seconds / a.steps:.1f} ms a step); circle r {radius:.2f} at {center} (truth 40 at [128, 128])")


if __name__ == "__main__":
    main()

"""The pydiffvg adapter's cost: pydiffvg's RenderFunction against vecfit.render on the
same scene.

    python benchmarks/pydiffvg.py [--threads 2] [--repeats 7]

For each scene, the pydiffvg side calls serialize_scene and RenderFunction.apply (what
code written for diffvg does each iteration: flatten the shapes, turn them into a vecfit
Scene, render); the vecfit side renders the Scene that the adapter builds, made once,
with vecfit.render and the same settings. Forward: the render alone; forward+backward:
the render and the gradients of every point, colour and stroke width (loss: sum of the
squared image). Medians; the two sides alternate within one run, so the ratio is the
steadier figure on a shared machine. Target: the adapter costs at most 15% more.
"""
from __future__ import annotations

import argparse
import statistics
import time
import warnings

import torch

from common import ROOT, SCENES

import pydiffvg
from vecfit.pydiffvg.convert import Parsed, to_scene
import vecfit


def few_shapes():
    """A diffvg-style scene of 6 groups: circle, ellipse, rect, a closed cubic path with a
    linear gradient, an open stroke and a polygon."""
    t = torch.tensor
    shapes = [pydiffvg.Circle(t(40.0), t([80.0, 90.0])), pydiffvg.Ellipse(t([60.0, 30.0]), t([170.0, 60.0])),
              pydiffvg.Rect(t([20.0, 150.0]), t([120.0, 230.0])),
              pydiffvg.Path(t([2, 2, 2]), t([[150.0, 120.0], [190, 90], [240, 110], [240, 160], [235, 200],
                                             [190, 230], [160, 200], [130, 170], [140, 140]]), True),
              pydiffvg.Path(t([2]), t([[20.0, 20.0], [80, 10], [150, 60], [230, 20]]), False, stroke_width=t(3.0)),
              pydiffvg.Polygon(t([[130.0, 240.0], [250, 250], [180, 180]]), True)]
    grad = pydiffvg.LinearGradient(t([150.0, 100.0]), t([240.0, 220.0]), t([0.0, 1.0]),
                                   t([[1.0, 0.2, 0.1, 1.0], [0.1, 0.3, 0.9, 0.8]]))
    colors = [t([0.9, 0.6, 0.1, 1.0]), t([0.2, 0.7, 0.3, 0.7]), t([0.3, 0.3, 0.8, 1.0]), None, None,
              t([0.5, 0.1, 0.5, 0.6])]
    groups = []
    for i, c in enumerate(colors):
        if i == 3:
            groups.append(pydiffvg.ShapeGroup(t([i]), grad, stroke_color=t([0.0, 0.0, 0.0, 1.0])))
        elif i == 4:
            groups.append(pydiffvg.ShapeGroup(t([i]), None, stroke_color=t([0.1, 0.1, 0.1, 1.0])))
        else:
            groups.append(pydiffvg.ShapeGroup(t([i]), c))
    return 256, 256, shapes, groups


def leaves(shapes, groups) -> list[torch.Tensor]:
    """Every float tensor of the diffvg scene that optimisation code would fit."""
    out = []
    for s in shapes:
        for name in ("points", "center", "radius", "p_min", "p_max", "stroke_width"):
            v = getattr(s, name, None)
            if isinstance(v, torch.Tensor) and v.is_floating_point():
                out.append(v)
    for g in groups:
        for c in (g.fill_color, g.stroke_color):
            if isinstance(c, torch.Tensor):
                out.append(c)
            elif c is not None:
                out.append(c.stop_colors)
    return out


def vecfit_leaves(scene) -> list[torch.Tensor]:
    p = scene.parameters()
    return p["points"] + p["radii"] + p["colors"] + p["stroke_widths"]


def measure(name, width, height, shapes, groups, threads, repeats):
    for t in leaves(shapes, groups):
        t.requires_grad_(True)
    settings = dict(samples=2, mode="mc", filter="box", filter_radius=0.5, seed=0, threads=threads)
    with torch.no_grad():
        scene = to_scene(Parsed(pydiffvg.RenderFunction.serialize_scene(width, height, shapes, groups)))
    for t in vecfit_leaves(scene):
        t.requires_grad_(True)
    torch.set_num_threads(threads)

    def adapter(backward):
        args = pydiffvg.RenderFunction.serialize_scene(width, height, shapes, groups)
        img = pydiffvg.RenderFunction.apply(width, height, 2, 2, 0, None, *args)
        if backward:
            (img ** 2).sum().backward()

    def direct(backward):
        img = vecfit.render(scene, width, height, **settings)
        if backward:
            (img ** 2).sum().backward()

    results = {}
    for backward in (False, True):
        times = {"pydiffvg": [], "vecfit": []}
        for fn in (adapter, direct):
            fn(backward)  # warm-up
        for _ in range(repeats):  # alternate, so that both see the same machine load
            for key, fn in (("pydiffvg", adapter), ("vecfit", direct)):
                ctx = torch.enable_grad() if backward else torch.no_grad()
                with ctx:
                    t0 = time.perf_counter()
                    fn(backward)
                    times[key].append(time.perf_counter() - t0)
        results[backward] = {k: statistics.median(v) for k, v in times.items()}
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    torch.manual_seed(0)
    scenes = [("6 shapes 256x256", *few_shapes())]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for label, path in (("tiger", ROOT / "examples" / "tiger.svg"), ("mcseem2", SCENES / "mcseem2.svg")):
            if path.exists():
                w, h, shapes, groups = pydiffvg.svg_to_scene(path)
                scenes.append((f"{label} {w}x{h}", w, h, shapes, groups))
    print(f"threads={args.threads}, MC 2x2, box filter, median of {args.repeats}; time in s")
    head = (f"{'scene':24s} {'shapes':>6s} {'fwd pydiffvg':>13s} {'fwd vecfit':>11s} {'ratio':>6s}"
            f" {'f+b pydiffvg':>13s} {'f+b vecfit':>11s} {'ratio':>6s}")
    print(head)
    print("-" * len(head))
    for label, w, h, shapes, groups in scenes:
        r = measure(label, w, h, shapes, groups, args.threads, args.repeats)
        f, b = r[False], r[True]
        print(f"{label:24s} {len(shapes):6d} {f['pydiffvg']:13.4f} {f['vecfit']:11.4f} "
              f"{f['pydiffvg'] / f['vecfit']:6.3f} {b['pydiffvg']:13.4f} {b['vecfit']:11.4f} "
              f"{b['pydiffvg'] / b['vecfit']:6.3f}")


if __name__ == "__main__":
    main()

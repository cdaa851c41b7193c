"""What clip paths, masks and blurs cost (the issue "Real SVG files render as browsers
draw them"): forward and backward medians, interleaved, on 2 threads.

- Scenes without effects: tiger and kitty's Adobe trace, through vecfit.render as it is
  and with the effects check bypassed (the only code a scene without effects now runs).
- An emoji (Noto, 256 px) alone; with its drawing under a clip path (a circle); the
  circle alone (a clip should cost about what drawing its shape costs); under a mask;
  and with a blurred group (deviation 4 px).

    python benchmarks/effects.py [--repeats 7] [--threads 2]
"""
from __future__ import annotations

import argparse
import copy
import statistics
import time
import warnings

import common
import torch

from vecfit.scene import Circle, ClipPath, Filter, FilterStep, Group, Mask, Scene, Shape, Solid


def load(path):
    import vecfit
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return vecfit.load_svg(path)


def wrapped(scene: Scene, **effects) -> Scene:
    """The scene's drawing inside one new group carrying ``effects``."""
    out = copy.copy(scene)
    out.groups = [Group(**effects)] + [copy.copy(g) for g in scene.groups]
    for g in out.groups[1:]:
        g.parent = 0 if g.parent < 0 else g.parent + 1
    out.shapes = [copy.copy(s) for s in scene.shapes]
    for s in out.shapes:
        s.group = 0 if s.group < 0 else s.group + 1
    return out


def disc(scene: Scene) -> Scene:
    """A circle over the middle of the scene's user space (through its view)."""
    inv = torch.linalg.inv(scene.view)
    center = (inv @ torch.tensor([scene.width / 2, scene.height / 2, 1.0]))[:2]
    radius = float(inv[0, 0]) * scene.width * 0.4
    return Scene(width=1, height=1, shapes=[Shape(geometry=Circle(center=center, radius=torch.tensor(radius)),
                                                  fill=Solid(torch.tensor([1.0, 1.0, 1.0, 1.0])))])


def workloads(args):
    emoji = load(common.SHARED / "realworld" / "cases" / "noto-emoji-060.svg")
    circle = disc(emoji)
    blur = Filter([FilterStep("GaussianBlur", ["SourceGraphic"], params={"std": (2.0, 2.0)})])
    only_circle = Scene(width=emoji.width, height=emoji.height, shapes=circle.shapes, view=emoji.view)
    return {
        "emoji": emoji,
        "emoji, clipped by a circle": wrapped(emoji, clip=ClipPath(circle)),
        "the circle alone": only_circle,
        "emoji, masked by a circle": wrapped(emoji, mask=Mask(circle, units="userSpaceOnUse",
                                                               region=(-1e4, -1e4, 2e4, 2e4))),
        "emoji, blurred (4 px)": wrapped(emoji, filter=blur),
    }


def run_once(scene, width, threads):
    import vecfit
    params = scene.parameters()["points"]
    for p in params:
        p.requires_grad_(True)
    t0 = time.perf_counter()
    image = vecfit.render(scene, width, None, samples=2, threads=threads, background=(1, 1, 1))
    t1 = time.perf_counter()
    (image ** 2).sum().backward()
    t2 = time.perf_counter()
    for p in params:
        p.grad = None
    return t1 - t0, t2 - t1


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--threads", type=int, default=2)
    args = p.parse_args(argv)

    # Scenes without effects, with and without the check, interleaved.
    plain = {"tiger": (load(common.SCENES / "tiger.svg"), None)}
    dense = common.SHARED / "data" / "photos" / "kitty.svg"
    if dense.exists():
        scene = load(dense)
        plain[f"kitty, Adobe trace ({len(scene.shapes):,} paths)"] = (scene, 512)
    print("| scene without effects | forward | backward | forward, check bypassed | backward, check bypassed |")
    print("|---|---:|---:|---:|---:|")
    for name, (scene, width) in plain.items():
        width = width or int(scene.width)
        times = {True: [], False: []}
        run_once(scene, width, args.threads)
        original = Scene.has_effects
        for _ in range(args.repeats):
            for check in (True, False):
                if not check:
                    Scene.has_effects = lambda self: False
                try:
                    times[check].append(run_once(scene, width, args.threads))
                finally:
                    Scene.has_effects = original
        med = {k: [statistics.median(x) for x in zip(*v)] for k, v in times.items()}
        print(f"| {name} | {1e3 * med[True][0]:.1f} ms | {1e3 * med[True][1]:.1f} ms | "
              f"{1e3 * med[False][0]:.1f} ms | {1e3 * med[False][1]:.1f} ms |")

    print()
    print("| Noto emoji at 256 px (MC 2x2, over white) | forward | backward |")
    print("|---|---:|---:|")
    scenes = workloads(args)
    times = {k: [] for k in scenes}
    for scene in scenes.values():
        run_once(scene, 256, args.threads)
    for _ in range(args.repeats):
        for name, scene in scenes.items():
            times[name].append(run_once(scene, 256, args.threads))
    for name, v in times.items():
        f, b = (statistics.median(x) for x in zip(*v))
        print(f"| {name} | {1e3 * f:.1f} ms | {1e3 * b:.1f} ms |")


if __name__ == "__main__":
    main()

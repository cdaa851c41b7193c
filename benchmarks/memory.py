"""Memory for one render (issue 28): the peak resident memory a render adds, against the
arrays it is given (the packed scene) and the image it returns.

    python benchmarks/memory.py [--cases tiger,paths,walk,across,wide] [--modes mc,analytic]
                                [--threads 2] [--samples 2] [--budget 60]

Each row runs in a fresh process (Linux only: it reads /proc/self/status): the scene is
built, torch and the core are warmed up on a small scene, the peak resident set is reset
(`/proc/self/clear_refs`), then one `vecfit.render` (forward), or a render and its
backward pass (`backward`), and the peak's growth over the resident set before it is the
render's memory. `arrays`: the packed scene the core reads (every array of
`packed_for_core`, integers and floats); `image`: the [H, W, 4] float32 result. The ratio
is the render's memory over arrays + image (the issue's target: within 2x).

Scenes: tiger (examples/tiger.svg, 495 x 510); paths (3,000 random closed paths of 8
cubics, every third also stroked, 512 x 512); walk and across (one path of 300,000 /
30,000 cubics at 64 px, as benchmarks/long_paths.py builds them); wide (30,000 mixed
segments, gradient fill, stroke-width 1e7, 64 px).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def status_kb(key: str) -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(key + ":"):
            return int(line.split()[1])
    raise KeyError(key)


def build(case: str):
    import random
    import tempfile
    import warnings

    import torch

    import vecfit
    sys.path.insert(0, str(HERE))
    import long_paths

    if case == "tiger":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = vecfit.load_svg(ROOT / "examples" / "tiger.svg")
        return scene, int(round(float(scene.width))), int(round(float(scene.height)))
    if case in ("walk", "across", "wide"):
        n = {"walk": 300_000, "across": 30_000, "wide": 30_000}[case]
        with tempfile.TemporaryDirectory() as tmp:
            return long_paths.scene_of(case, n, Path(tmp)), 64, 64
    assert case == "paths", case
    rng = random.Random(0)
    parts = []
    for i in range(3000):
        cx, cy, r = rng.uniform(0, 512), rng.uniform(0, 512), rng.uniform(4, 24)
        import math
        pts = [(cx + r * rng.uniform(0.6, 1.2) * math.cos(2 * math.pi * k / 24),
                cy + r * rng.uniform(0.6, 1.2) * math.sin(2 * math.pi * k / 24)) for k in range(24)]
        d = f"M {pts[0][0]:.2f} {pts[0][1]:.2f} " + " ".join(
            f"C {pts[(3 * j + 1) % 24][0]:.2f} {pts[(3 * j + 1) % 24][1]:.2f} {pts[(3 * j + 2) % 24][0]:.2f} "
            f"{pts[(3 * j + 2) % 24][1]:.2f} {pts[(3 * j + 3) % 24][0]:.2f} {pts[(3 * j + 3) % 24][1]:.2f}"
            for j in range(8)) + " Z"
        colour = f"#{rng.randrange(1 << 24):06x}"
        stroke = ' stroke="#222" stroke-width="2"' if i % 3 == 0 else ""
        parts.append(f'<path d="{d}" fill="{colour}" fill-opacity="0.8"{stroke}/>')
    svg = f'<svg xmlns="http://www.w3.org/2000/svg" width="512" height="512">{"".join(parts)}</svg>'
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "paths.svg"
        path.write_text(svg)
        return vecfit.load_svg(path), 512, 512


def child(case: str, mode: str, backward: bool, threads: int, samples: int) -> dict:
    import common  # noqa: F401  (OMP_WAIT_POLICY before torch)
    import torch

    import vecfit
    from vecfit.renderer.raster import packed_for_core

    scene, w, h = build(case)
    structure, floats = packed_for_core(scene, w, h)
    arrays = sum(v.nbytes for v in structure.values() if hasattr(v, "nbytes")) + \
        sum(t.numel() * t.element_size() for t in floats)
    image = w * h * 4 * 4
    del structure, floats
    # warm-up on a small scene (not this one: its freed memory would be reused): torch's
    # and the core's one-time allocations (thread pool, autograd)
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "w.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="8" height="8">'
                                         '<path d="M 1 1 C 7 1 7 7 1 7 Z" fill="red" stroke="blue"/></svg>')
        warm = vecfit.load_svg(Path(tmp) / "w.svg")
    wpts = warm.shapes[0].geometry.points.requires_grad_(backward)
    img = vecfit.render(warm, 8, 8, samples=samples, mode=mode, threads=threads)
    if backward:
        img.sum().backward()
    pts = scene.shapes[0].geometry.points
    pts.requires_grad_(backward)
    del img, wpts, warm
    Path("/proc/self/clear_refs").write_text("5")
    before = status_kb("VmRSS")
    img = vecfit.render(scene, w, h, samples=samples, mode=mode, threads=threads)
    if backward:
        (img * torch.rand_like(img)).sum().backward()
    peak = status_kb("VmHWM")
    return {"case": case, "mode": mode, "backward": backward, "arrays": arrays, "image": image,
            "extra": (peak - before) * 1024}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", default="tiger,paths,walk,across,wide")
    parser.add_argument("--modes", default="mc,analytic")
    parser.add_argument("--passes", default="forward,backward")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--samples", type=int, default=2)
    parser.add_argument("--budget", type=float, default=60.0,
                        help="seconds a row may take (Monte Carlo backward passes of canvas-wide paths take minutes)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    a = parser.parse_args()
    if a.child:
        case, mode, back = a.child.split(",")
        print(json.dumps(child(case, mode, back == "1", a.threads, a.samples)))
        return
    print(f"{'scene':8} {'mode':9} {'pass':9} {'arrays MB':>10} {'image MB':>9} {'render MB':>10} {'ratio':>7}", flush=True)
    for case in a.cases.split(","):
        for mode in a.modes.split(","):
            for p in a.passes.split(","):
                try:
                    out = subprocess.run([sys.executable, __file__, "--child", f"{case},{mode},{int(p == 'backward')}",
                                          "--threads", str(a.threads), "--samples", str(a.samples)],
                                         capture_output=True, text=True, cwd=HERE, env=dict(os.environ),
                                         timeout=a.budget)
                except subprocess.TimeoutExpired:
                    print(f"{case:8} {mode:9} {p:9} not measured: over the {a.budget:g} s budget", flush=True)
                    continue
                if out.returncode != 0:
                    print(f"{case:8} {mode:9} {p:9} failed: {out.stderr.strip().splitlines()[-1:]}")
                    continue
                r = json.loads(out.stdout.strip().splitlines()[-1])
                base = r["arrays"] + r["image"]
                print(f"{case:8} {mode:9} {p:9} {r['arrays'] / 1e6:10.2f} {r['image'] / 1e6:9.2f} "
                      f"{r['extra'] / 1e6:10.1f} {r['extra'] / base:7.1f}", flush=True)


if __name__ == "__main__":
    main()

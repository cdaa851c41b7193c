"""Flat iteration cost (issue 41, item 5): how much dearer a refinement's last iterations
are than its first, where the growth comes from, and what the settings that bound it cost.

    python benchmarks/iteration_growth.py [--inputs DIR] [--images kitty,peppers,astronaut1000,astronaut3000]
                                          [--variant NAME:KEY=VALUE,KEY=VALUE ...] [--no-defaults]
                                          [--threads 2] [--phases] [--end-state]

Inputs: Illustrator's traces of kitty and peppers (../shared/data/photos), and skimage's
astronaut (512x512) traced by vecfit at 1,000 paths (the default trace, ``--no-refine``)
and at 3,000 (``--paths 3000 --colors 128 --min-area 1 --no-refine``), made once in
--inputs (default a temporary folder; the refined SVGs and reports go to its out/).

Each image is refined by the default `vecfit refine` job in-process, once per variant
(``defaults`` always; each --variant adds config overrides, e.g.
``--variant snap:optimize.alpha_snap=0.99``), the variants of one image run back to back so
that the machine's load touches them alike. For each run: the job's wall time in seconds
and in R (benchmarks/machine.py, measured at the start), the mean of its first 10 and of
its last 10 iterations (``seconds.iterations`` of the report) and their ratio, also in the process's CPU time
(which other work on a shared machine disturbs less than wall time); when the run
starts at half size (optimize.coarse), also the first 10 at full size and that ratio; the
gain of the written SVG rendered by resvg against the photo; and the end state that sets
an iteration's cost: the control polygons' length (px per pixel of the image, start ->
end) and how many shapes are drawn translucent. --phases: where the time of the first and
the last iterations goes (benchmarks/refine.py's split). --end-state: one forward +
backward of the start and of each run's end state, taking turns, in CPU time: the growth
without the run's own noise, and which of the core's passes it is in.
"""
from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

from common import SHARED, parse_sets, resvg_rgb
from machine import in_r, machine_unit

from vecfit.io.colors import parse_background
from vecfit.fitting.metrics import compare, to_rgb
from vecfit.fitting.rates import outline_density
from vecfit.jobs.config import resolve
from vecfit.jobs.fit import load_target
from vecfit.jobs.protocol import Inputs, Outputs
from vecfit.jobs.refine import run as refine
from vecfit.renderer.stopwatch import Stopwatch
from vecfit.svg.read import load_svg
from refine import print_breakdown

PHOTOS = SHARED / "data" / "photos"
TRACES = {"astronaut1000": [], "astronaut3000": ["--paths", "3000", "--colors", "128", "--min-area", "1"]}
WINDOW = 10


def inputs(folder: Path, name: str) -> tuple[Path, Path]:
    """(target image, SVG to refine) for ``name``."""
    if name in ("kitty", "peppers"):
        return PHOTOS / {"kitty": "kitty.jpg", "peppers": "peppers.png"}[name], PHOTOS / f"{name}.svg"
    from PIL import Image
    from skimage import data

    photo = folder / "astronaut.png"
    if not photo.exists():
        Image.fromarray(data.astronaut()).save(photo)
    svg = folder / f"{name}.svg"
    if not svg.exists():
        subprocess.run([sys.executable, "-m", "vecfit", "trace", str(photo), "-o", str(svg), "--no-refine",
                        *TRACES[name]], check=True, capture_output=True)
    return photo, svg


def translucent_shapes(svg: Path) -> int:
    """Shapes written with an opacity below 1 (fill-opacity, stroke-opacity, opacity, or an
    rgba colour)."""
    text = svg.read_text()
    return len(re.findall(r'(?:fill-opacity|stroke-opacity|opacity)="0?\.\d+"', text))


def density(svg: Path, width: int, height: int) -> float:
    return outline_density(load_svg(svg), width, height)


def render_cost(target_path: Path, svgs: list, threads: int, repeats: int = 7) -> list[dict]:
    """CPU seconds of one Monte Carlo forward + backward at the loop's settings (2x2 samples,
    1 interior, boundary 2 per px with the budget of 2) of each SVG at the target's size,
    the SVGs taking turns (so that the machine's load touches them alike), medians of
    ``repeats``, with the core's phase clocks: the start and the end state of a run
    compared without the run's own noise."""
    import numpy as np
    import torch

    from vecfit import _core
    from vecfit.renderer.raster import render

    target = load_target(target_path)
    h, w = target.shape[:2]
    goal = torch.from_numpy(np.ascontiguousarray(target[..., :3])).float()
    scenes = []
    for svg in svgs:
        scene = load_svg(svg)
        for tensors in scene.parameters().values():
            for t in tensors:
                t.requires_grad_(True)
        scenes.append(scene)
    cpu = [[] for _ in svgs]
    phases = [[] for _ in svgs]
    for rep in range(repeats):
        for i, scene in enumerate(scenes):
            _core.phase_seconds()
            began = time.process_time()
            image = render(scene, w, h, samples=2, seed=rep, background=(1, 1, 1, 1), threads=threads,
                           boundary_samples=2.0, interior_samples=1, boundary_budget=2.0)
            ((image[..., :3] - goal) ** 2).mean().backward()
            cpu[i].append(time.process_time() - began)
            phases[i].append(_core.phase_seconds())
    return [{"cpu": statistics.median(c), **{k: statistics.median(p[k] for p in ph) for k in ph[0]}}
            for c, ph in zip(cpu, phases)]


def run_one(name: str, target_path: Path, svg_path: Path, overrides: dict, tmp: Path, label: str) -> dict:
    config = resolve("refine", overrides=overrides)
    out = Outputs.beside(tmp / f"{name}-{label}{target_path.suffix}")
    cpu = [time.process_time()]  # the process's CPU time after each iteration

    def progress(p) -> None:
        if hasattr(p, "iterations"):
            cpu.append(time.process_time())

    began = time.perf_counter()
    with warnings.catch_warnings(), Stopwatch() as watch:
        warnings.simplefilter("ignore")
        report = refine(Inputs(image=target_path, svg=svg_path), config, out, progress=progress)
    wall = time.perf_counter() - began
    out.svg.with_suffix(".cpu.json").write_text(json.dumps(cpu))
    target = load_target(target_path)
    bg = parse_background(report["background"])
    goal = to_rgb(target, bg)
    before = compare(resvg_rgb(svg_path, target.shape[1], bg), goal)["psnr"]
    after = compare(resvg_rgb(out.svg, target.shape[1], bg), goal)["psnr"]
    times = report["seconds"]["iterations"]
    coarse = report["coarse_iterations"]
    ow, oh = report["optimized_size"]
    first = statistics.mean(times[:WINDOW])
    last = statistics.mean(times[-WINDOW:])
    full = statistics.mean(times[coarse:coarse + WINDOW]) if coarse else first
    # (the first interval also holds the job's reading and setting up: left out)
    cpu_times = [b - a for a, b in zip(cpu[1:], cpu[2:])]
    start = max(coarse - 1, 0)
    cpu_ratio = (statistics.mean(cpu_times[-WINDOW:]) / statistics.mean(cpu_times[start:start + WINDOW])
                 if len(cpu_times) >= WINDOW else float("nan"))
    return {"name": name, "label": label, "wall": wall, "first": first, "full": full, "last": last,
            "coarse": coarse, "cpu_ratio": cpu_ratio, "before": before, "after": after,
            "density": (density(svg_path, ow, oh), density(out.svg, ow, oh)),
            "translucent": (translucent_shapes(svg_path), translucent_shapes(out.svg)),
            "shapes": report["shapes"], "laps": watch.laps, "written": out.svg}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--inputs", type=Path)
    ap.add_argument("--images", default="kitty,peppers,astronaut1000,astronaut3000")
    ap.add_argument("--variant", action="append", default=[],
                    help="NAME:KEY=VALUE[,KEY=VALUE...] config overrides to compare with the defaults")
    ap.add_argument("--no-defaults", action="store_true", help="run only the --variant settings")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--end-state", action="store_true",
                    help="also time one forward + backward of the start and of each run's end state, taking turns")
    ap.add_argument("--phases", action="store_true", help="also where the first and last iterations' time goes")
    args = ap.parse_args()
    variants = [] if args.no_defaults else [("defaults", {})]
    for v in args.variant:
        label, _, sets = v.partition(":")
        variants.append((label, parse_sets([s for s in sets.split(",") if s])))
    unit = machine_unit()
    print(f"machine unit R = {unit:.4f} s (benchmarks/machine.py)", flush=True)
    rows = []
    scratch = tempfile.TemporaryDirectory()  # (the inputs and outputs, without --inputs)
    folder = args.inputs or Path(scratch.name)
    folder.mkdir(parents=True, exist_ok=True)
    for name in args.images.split(","):
        target_path, svg_path = inputs(folder, name)
        for label, sets in variants:
            overrides = {k: dict(v) for k, v in sets.items()}
            overrides.setdefault("optimize", {})["threads"] = args.threads
            written = folder / "out"
            written.mkdir(exist_ok=True)
            row = run_one(name, target_path, svg_path, overrides, written, label)
            rows.append(row)
            print(f"  {name} {label}: {row['wall']:.1f} s, {row['first']:.3f} -> {row['last']:.3f} s/it, "
                  f"{row['after'] - row['before']:+.2f} dB, CPU ratio {row['cpu_ratio']:.2f}", flush=True)
    if args.phases:
        for r in rows:
            print_breakdown(f"{r['name']}, {r['label']}", r["laps"], r["coarse"])
    if args.end_state:
        print("\nOne forward + backward of the start and of each run's end (CPU seconds, medians, taking turns; "
              "the core's phase clocks)\n")
        for name in args.images.split(","):
            mine = [r for r in rows if r["name"] == name]
            target_path, svg_path = inputs(folder, name)
            costs = render_cost(target_path, [svg_path] + [r["written"] for r in mine], args.threads)
            keys = [k for k in costs[0] if k != "cpu"]
            print(f"| {name} | CPU | " + " | ".join(keys) + " |")
            print("|---|---:|" + "---:|" * len(keys))
            for label, c in zip(["start"] + [f"end, {r['label']}" for r in mine], costs):
                print(f"| {label} | {c['cpu']:.3f} s ({c['cpu'] / costs[0]['cpu']:.2f}x) | "
                      + " | ".join(f"{c[k]:.3f} ({c[k] / costs[0][k]:.2f}x)" if costs[0][k] else f"{c[k]:.3f}"
                                   for k in keys) + " |")
    scratch.cleanup()
    print(f"\nR = {unit:.4f} s, measured at the start of this run\n")
    print("| image | shapes | setting | job | first 10 | first 10 at full size | last 10 | last / first "
          "| last / first at full size | the same in CPU time | PSNR (resvg) | gain | polygons (px/px) | translucent |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---|---|")
    for r in rows:
        full = f"{r['full']:.3f} s" if r["coarse"] else "(no half size)"
        print(f"| {r['name']} | {r['shapes']} | {r['label']} | {in_r(r['wall'], unit)} | {r['first']:.3f} s "
              f"| {full} | {r['last']:.3f} s | {r['last'] / r['first']:.2f}x | {r['last'] / r['full']:.2f}x | {r['cpu_ratio']:.2f}x "
              f"| {r['before']:.2f} -> {r['after']:.2f} | {r['after'] - r['before']:+.2f} dB "
              f"| {r['density'][0]:.2f} -> {r['density'][1]:.2f} | {r['translucent'][0]} -> {r['translucent'][1]} |")


if __name__ == "__main__":
    main()

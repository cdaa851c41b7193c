"""Tracing quality and speed: skimage's photographs traced at several path budgets.

    python benchmarks/trace.py [--budgets 250,500,1000,2000] [--images astronaut,...]
                               [--emoji N] [--repeats 3] [--overlap-check]
                               [--refine 1000[,...]] [--iterations N] [--set KEY=VALUE ...]
                               [--colors-scan 16:128:8]

For each image and path budget: the paths and segments written, the trace time in-process
(median of --repeats; wall and the process's CPU time, which a machine shared with other
work disturbs less), where it goes (quantisation, regions, drawing order, outlines with
their sub-pixel placement, the Bezier fit with the SVG text), and the PSNR of the trace
rendered by vecfit (MC 2x2, box filter, over white) against the image
(skimage.metrics.peak_signal_noise_ratio on float RGB, data_range 1); then the mean PSNR
per budget. --emoji N adds N emoji of the shared real-world corpus (noto and fxemoji in
turn), rendered by resvg at 512 px, traced at the first budget (their transparency
stays transparent; PSNR over white). --overlap-check also traces at the default budget with shapes not reaching
under their neighbours (overlap 0), which shows the seams that overlap closes. --refine B
runs the whole `vecfit trace` job (trace, then refine with the defaults) at budget B and
scores the written SVG as resvg renders it, next to vecfit's own figures, with wall times,
how much dearer the last tenth of the iterations is than the first (wall and CPU time),
what the loop would take were every iteration as cheap as the first tenth (a flat loop's
floor, against which a time target can be judged), and where each run's iterations spend
their time at its start and its end.
--colors-scan FIRST:LAST:STEP traces each image at the default budget with each colour
count (the k of the k-means) and scores the trace as resvg renders it: a colour count
where a photo's PSNR falls well below its neighbours' shows a tracer bug that a
particular clustering exposes (one painted the coffee in a cup white at 88 colours).
Times are also given in R, the machine unit measured at the start (benchmarks/machine.py).
"""
from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

IMAGES = ["astronaut", "chelsea", "coffee", "rocket"]
BUDGETS = [250, 500, 1000, 2000]


def load(name: str) -> np.ndarray:
    """An skimage.data image as float RGBA [H, W, 4]."""
    import skimage.data

    rgb = getattr(skimage.data, name)().astype(np.float32) / 255
    return np.concatenate([rgb, np.ones_like(rgb[..., :1])], 2)


def render_svg(svg: str, width: int, height: int) -> np.ndarray:
    """The SVG text rendered by vecfit over white, float RGB [H, W, 3]."""
    import vecfit

    fd, path = tempfile.mkstemp(suffix=".svg")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(svg)
        scene = vecfit.load_svg(path)
    finally:
        os.unlink(path)
    return vecfit.render(scene, width, height, samples=2, background=[1, 1, 1, 1]).numpy()[..., :3]


STAGES = ["quantise", "regions", "order", "outline", "fit"]


def measure(image: np.ndarray, settings, repeats: int = 1) -> dict:
    """Trace `repeats` times: median time in all and per stage (from trace_image's
    progress calls), and the last trace's counts and PSNR."""
    from skimage.metrics import peak_signal_noise_ratio

    from vecfit.initial.tracer import trace_image
    from vecfit.io.compositing import composite

    times, cpu, stages = [], [], {k: [] for k in STAGES}
    for _ in range(repeats):
        marks = []

        def progress(stage, fraction):
            if not marks or marks[-1][0] != stage:
                marks.append((stage, time.perf_counter()))

        start, start_cpu = time.perf_counter(), time.process_time()
        result = trace_image(image, settings, progress=progress)
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        marks.append(("end", start + times[-1]))
        for (stage, a), (_, b) in zip(marks, marks[1:]):
            stages[stage].append(b - a)
    h, w = image.shape[:2]
    over_white = composite(image.astype(np.float64), (1.0, 1.0, 1.0))
    psnr = peak_signal_noise_ratio(over_white, render_svg(result.svg, w, h).astype(np.float64), data_range=1)
    return {"paths": result.paths, "segments": result.segments, "colors": result.colors,
            "seconds": float(np.median(times)), "cpu": float(np.median(cpu)), "psnr": psnr,
            "stages": {k: float(np.median(v)) if v else 0.0 for k, v in stages.items()}}


def emoji(count: int, width: int = 512) -> list[tuple[str, np.ndarray]]:
    """The first `count` emoji of the shared real-world corpus (noto-emoji and fxemoji in
    turn, every 8th of each), rendered by resvg at `width` px: float RGBA."""
    import csv
    import io

    import resvg_py
    from PIL import Image

    from common import SHARED  # (benchmarks/ is on sys.path: the script's own folder)
    root = SHARED / "realworld"
    with open(root / "manifest.tsv") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    sets = [[r for r in rows if r["tags"].split(",")[0] == tag][::8] for tag in ("noto-emoji", "fxemoji")]
    chosen = [r for pair in zip(*sets) for r in pair][:count]
    out = []
    for r in chosen:
        png = bytes(resvg_py.svg_to_bytes(svg_path=str(root / r["svg"]), width=width))
        rgba = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float32) / 255
        out.append((r["name"], rgba))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budgets", default=",".join(map(str, BUDGETS)))
    ap.add_argument("--images", default=",".join(IMAGES))
    ap.add_argument("--emoji", type=int, default=0, help="also trace this many emoji (512 px)")
    ap.add_argument("--repeats", type=int, default=3, help="traces timed per image (median)")
    ap.add_argument("--overlap-check", action="store_true")
    ap.add_argument("--refine", default="", help="budgets to trace and refine at, e.g. 1000")
    ap.add_argument("--iterations", type=int, help="refinement iterations (default: the config's)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--set", action="append", default=[],
                    help="with --refine: a config override, KEY=VALUE (e.g. optimize.coarse=0.3)")
    ap.add_argument("--colors-scan", default="", help="FIRST:LAST:STEP colour counts, e.g. 16:128:8")
    args = ap.parse_args()
    if args.colors_scan:
        first, last, step = (int(v) for v in args.colors_scan.split(":"))
        colors_scan(args.images.split(","), list(range(first, last + 1, step)))
        return
    from machine import machine_unit  # (benchmarks/ is on sys.path: the script's own folder)
    unit = machine_unit()
    print(f"machine unit R = {unit:.4f} s (benchmarks/machine.py)")
    if args.refine:
        refine_table([int(b) for b in args.refine.split(",")], args.images.split(","),
                     args.iterations, args.threads, args.set, unit)
        return
    budgets = [int(b) for b in args.budgets.split(",")]
    images = args.images.split(",")

    from vecfit.initial.tracer import TraceSettings

    defaults = TraceSettings.defaults()
    print(f"defaults: colors={defaults.colors} min_area={defaults.min_area} "
          f"tolerance={defaults.tolerance} corner_angle={defaults.corner_angle} "
          f"blur={defaults.blur} overlap={defaults.overlap} smoothing={defaults.smoothing}")
    head = (f"{'image':22s} {'budget':>6s} {'paths':>6s} {'segments':>8s} {'seg/path':>8s} "
            f"{'trace s':>8s} {'trace R':>8s} {'CPU s':>8s} {'PSNR dB':>8s}   " + " ".join(f"{k:>8s}" for k in STAGES))
    print(head)
    print("-" * len(head))
    inputs = [(f"{name} {im.shape[1]}x{im.shape[0]}", im, budgets) for name, im in
              [(n, load(n)) for n in images if n]]
    inputs += [(f"{name} {im.shape[1]}x{im.shape[0]}", im, budgets[:1]) for name, im in emoji(args.emoji)]
    psnr, seconds, cpu = {}, {}, {}
    for label, image, image_budgets in inputs:
        group = "emoji" if label.startswith(("noto", "fxemoji")) else "photos"
        for b in image_budgets:
            r = measure(image, TraceSettings.defaults(paths=b), args.repeats)
            psnr.setdefault((group, b), []).append(r["psnr"])
            seconds.setdefault((group, b), []).append(r["seconds"])
            cpu.setdefault((group, b), []).append(r["cpu"])
            print(f"{label:22s} {b:6d} {r['paths']:6d} {r['segments']:8d} "
                  f"{r['segments'] / r['paths']:8.1f} {r['seconds']:8.3f} {r['seconds'] / unit:8.2f} {r['cpu']:8.3f} "
                  f"{r['psnr']:8.2f}   "
                  + " ".join(f"{r['stages'][k]:8.3f}" for k in STAGES), flush=True)
    print("-" * len(head))
    for (group, b), values in psnr.items():
        print(f"{'mean ' + group:22s} {b:6d} {'':6s} {'':8s} {'':8s} {np.median(seconds[(group, b)]):8.3f} "
              f"{np.median(seconds[(group, b)]) / unit:8.2f} {np.median(cpu[(group, b)]):8.3f} {np.mean(values):8.2f}"
              "   (times: median)")

    if args.overlap_check:
        b = defaults.paths
        print(f"\nseams: PSNR at {b} paths with overlap 0 (shapes meet edge to edge) "
              f"and {defaults.overlap} (the default)")
        rows = []
        for name in images:
            image = load(name)
            r0 = measure(image, TraceSettings.defaults(paths=b, overlap=0))
            r1 = measure(image, TraceSettings.defaults(paths=b))
            rows.append((r0["psnr"], r1["psnr"]))
            print(f"{name:16s} {r0['psnr']:8.2f} {r1['psnr']:8.2f}", flush=True)
        print(f"{'mean':16s} {np.mean([r[0] for r in rows]):8.2f} {np.mean([r[1] for r in rows]):8.2f}")


def colors_scan(images, counts):
    """PSNR by resvg (over white, float RGB) of each image traced with each colour count,
    then each image's worst and default-setting figures."""
    from common import resvg_rgb
    from vecfit.initial.tracer import TraceSettings, trace_image

    default = TraceSettings.defaults().colors
    print(f"{'image':12s} " + " ".join(f"{k:>6d}" for k in counts))
    worst = {}
    with tempfile.TemporaryDirectory() as folder:
        for name in images:
            image = load(name)
            rgb = image[..., :3].astype(np.float64)
            row = {}
            for k in sorted(set(counts) | {default}):
                path = Path(folder) / "trace.svg"
                path.write_text(trace_image(image, TraceSettings.defaults(colors=k)).svg)
                row[k] = -10 * np.log10(np.mean((resvg_rgb(path, image.shape[1]) - rgb) ** 2))
            print(f"{name:12s} " + " ".join(f"{row[k]:6.2f}" for k in counts), flush=True)
            worst[name] = (min((row[k], k) for k in counts), row[default])
    for name, ((value, k), at_default) in worst.items():
        print(f"{name:12s} worst {value:.2f} dB at {k} colours; {at_default:.2f} dB at the default {default}")


def refine_table(budgets, images, iterations, threads, sets=(), unit=None):
    """Trace + refine with the defaults: PSNR before / after and wall time per image (and
    the total in R, the machine unit ``unit`` in seconds)."""
    from PIL import Image

    from vecfit.io.colors import parse_background
    from vecfit.jobs.config import resolve
    from vecfit.fitting.metrics import compare
    from vecfit.jobs.protocol import Inputs, Outputs
    from vecfit.jobs.trace import run as trace
    from common import parse_sets, resvg_rgb  # (benchmarks/ is on sys.path: the script's own folder)
    from machine import in_r, machine_unit
    from refine import print_breakdown

    from vecfit.renderer.stopwatch import Stopwatch

    unit = unit or machine_unit()
    print("| image | budget | paths | PSNR trace | PSNR refined (vecfit) | PSNR refined (resvg) "
          "| trace s | refine s | s/iter | growth (wall / CPU) | the loop at its start's cost | total |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    means = {b: [] for b in budgets}
    breakdowns = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in images:
            image = load(name)
            target = Path(tmp) / f"{name}.png"
            Image.fromarray((image[..., :3] * 255 + 0.5).astype(np.uint8)).save(target)
            for b in budgets:
                overrides = parse_sets(sets)
                overrides.setdefault("trace", {})["paths"] = b
                overrides.setdefault("optimize", {})["threads"] = threads
                if iterations is not None:
                    overrides["optimize"]["iterations"] = iterations
                config = resolve("trace", overrides=overrides)
                out = Outputs.beside(target, Path(tmp) / f"{name}_{b}.svg")
                cpu = []  # the process's CPU time after each iteration

                def progress(p, cpu=cpu) -> None:
                    if hasattr(p, "iterations"):
                        cpu.append(time.process_time())

                with Stopwatch() as watch:
                    rep = trace(Inputs(image=target), config, out, progress=progress)
                growth, flat = loop_growth(rep["seconds"]["iterations"], cpu)
                breakdowns.append((f"{name} at {b} paths", watch.laps, rep.get("coarse_iterations", 0)))
                bg = parse_background(rep["background"])
                theirs = resvg_rgb(out.svg, image.shape[1], bg)
                resvg_psnr = compare(theirs, image[..., :3].astype(np.float64))["psnr"]
                means[b].append(resvg_psnr)
                opt = rep["seconds"]["optimize"]
                print(f"| {name} {image.shape[1]}x{image.shape[0]} | {b} | {rep['trace']['paths']} "
                      f"| {rep['initial']['psnr']:.2f} | {rep['optimized']['psnr']:.2f} | {resvg_psnr:.2f} "
                      f"| {rep['trace']['seconds']:.1f} | {opt:.1f} | {rep['seconds']['per_iteration']:.3f} "
                      f"| {growth} | {in_r(flat, unit)} | {in_r(rep['seconds']['total'], unit)} |", flush=True)
    for b in budgets:
        print(f"mean PSNR (resvg) at {b} paths: {np.mean(means[b]):.2f} dB")
    for label, laps, coarse in breakdowns:
        print_breakdown(label, laps, coarse)


def loop_growth(times: list, cpu: list) -> tuple[str, float]:
    """How much dearer the loop's last tenth of iterations is than its first (medians),
    in wall time and in the process's CPU time (``cpu``: its clock after each iteration;
    a machine shared with other work disturbs it less), and what the loop would take at its
    first tenth's cost throughout: what a perfectly flat loop of this many iterations costs."""
    if not times:
        return "", 0.0
    n = max(1, len(times) // 10)
    first = statistics.median(times[:n])
    wall = statistics.median(times[-n:]) / first
    steps = [b - a for a, b in zip(cpu, cpu[1:])]  # (the first iteration's also holds the set-up: left out)
    k = max(1, len(steps) // 10)
    ratio = f"{statistics.median(steps[-k:]) / statistics.median(steps[:k]):.2f}x" if len(steps) >= 2 else "-"
    return f"{wall:.2f}x / {ratio}", first * len(times)


if __name__ == "__main__":
    main()

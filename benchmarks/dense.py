"""Dense scenes (issue 29): what an iteration of `vecfit refine` costs against the number of
shapes on one photo, where that time goes, and the whole default job on a dense trace.

    python benchmarks/dense.py [--counts 300,1000,3000,10000] [--iterations 16]
                               [--job 3000] [--inputs DIR] [--set KEY=VALUE ...]

Inputs (made here, kept in --inputs, default a temporary folder): skimage's coffee
resized to 512 px wide (512x341), traced by vecfit's tracer at each path budget with
128 colours and specks down to 1 px, so that the budget, not the tracer's merging, sets
the count (the tracer makes about 9,000 regions of this photo at most).

Curve: each trace refined at the refine defaults (MC 2x2, 2 threads) for --iterations
iterations, all at full size (coarse 0: the default already skips the half-size phase
at 1,000 shapes and more at this size), the median of the iterations after the first 4
per phase (the renderer's stopwatch, as benchmarks/refine.py splits it), and each
count's iteration against the 1,000-shape one.

Job (--job N, 0 for none): the whole default `vecfit refine` of the N-path trace, its wall
time, and the written SVG scored by resvg before and after against the photo.
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from common import parse_sets, resvg_rgb
from refine import KERNELS, PHASES, print_breakdown, split

TRACE = {"colors": 128, "min_area": 1.0}
SKIP = 4  # first iterations left out of the medians (warm-up, Adam's first steps)


def make_inputs(folder: Path, counts) -> tuple[Path, dict]:
    """coffee.png (512 px wide) and coffee_N.svg per path budget N, made once per folder."""
    from PIL import Image
    from skimage import data

    from vecfit.initial.tracer import TraceSettings, trace_image

    folder.mkdir(parents=True, exist_ok=True)
    target = folder / "coffee.png"
    if not target.exists():
        photo = Image.fromarray(data.coffee())
        photo.resize((512, round(512 * photo.height / photo.width)), Image.LANCZOS).save(target)
    rgb = np.asarray(Image.open(target).convert("RGB"), np.float32) / 255
    rgba = np.concatenate([rgb, np.ones_like(rgb[..., :1])], axis=2)
    svgs = {}
    for n in counts:
        svg = folder / f"coffee_{n}.svg"
        if not svg.exists():
            svg.write_text(trace_image(rgba, TraceSettings.defaults(paths=n, **TRACE)).svg)
        svgs[n] = svg
    return target, svgs


def refine(target: Path, svg: Path, overrides: dict, folder: Path):
    """The refine job on (target, svg) with the config overrides: its report, the laps of
    the stopwatch and the written SVG."""
    from vecfit.jobs.config import resolve
    from vecfit.jobs.protocol import Inputs, Outputs
    from vecfit.jobs.refine import run
    from vecfit.renderer.stopwatch import Stopwatch

    outputs = Outputs.beside(folder / f"{svg.stem}.png", svg=folder / f"{svg.stem}.refined.svg")
    with warnings.catch_warnings(), Stopwatch() as watch:
        warnings.simplefilter("ignore")
        report = run(Inputs(image=target, svg=svg), resolve("refine", overrides=overrides), outputs)
    return report, watch.laps, outputs.svg


def with_budget(overrides: dict, budget: float | None) -> tuple[dict, float]:
    """The overrides with optimize.boundary_budget set (None: the configured one, as given
    by --set or refine.toml), and the budget they give."""
    from vecfit.io.configs import defaults

    optimize = overrides.get("optimize", {})
    used = budget if budget is not None else optimize.get("boundary_budget",
                                                           defaults("refine", "optimize")["boundary_budget"])
    return {**overrides, "optimize": {**optimize, "boundary_budget": used}}, used


def curve(target: Path, svgs: dict, iterations: int, overrides: dict, folder: Path, budgets) -> None:
    rows = {}
    for n, svg in svgs.items():
        for budget in budgets:  # (alternating, so that the machine's load falls on both alike)
            changes, used = with_budget(overrides, budget)
            changes["optimize"].update(iterations=iterations, coarse=0.0)
            report, laps, _ = refine(target, svg, changes, folder)
            parts = [split(lap) for lap in laps[SKIP:] or laps]
            label = f"{report['shapes']:,} shapes" + ("" if isinstance(n, int) else ", refined")
            rows[(n, used)] = (label + (f", budget {used:g}" if len(budgets) > 1 else ""),
                               {k: statistics.median(p[k] for p in parts) for k in PHASES + ("iteration",)})
    base = {used: p["iteration"] for (n, used), (_, p) in rows.items() if n == 1000}
    print(f"\nms per iteration at full size (median of iterations {SKIP + 1}-{iterations}), by phase\n")
    print("| phase | " + " | ".join(label for label, _ in rows.values()) + " |")
    print("|---|" + "---:|" * len(rows))
    for phase in PHASES + ("iteration",):
        print(f"| {phase} | " + " | ".join(f"{p[phase] * 1000:.1f}" for _, p in rows.values()) + " |")
    if base:
        print("| against 1,000 shapes | " + " | ".join(f"{p['iteration'] / base[used]:.2f}x"
                                                     for (_, used), (_, p) in rows.items()) + " |")
    outside = [1 - sum(p[k] for k in KERNELS) / p["iteration"] for _, p in rows.values()]
    print("| outside the core's passes | " + " | ".join(f"{o:.0%}" for o in outside) + " |")


def job(target: Path, svg: Path, overrides: dict, budget: float, folder: Path) -> None:
    from PIL import Image

    from vecfit.fitting.metrics import compare, to_rgb
    from vecfit.io.colors import parse_background

    start = time.perf_counter()
    report, laps, written = refine(target, svg, overrides, folder)
    wall = time.perf_counter() - start
    photo = np.asarray(Image.open(target).convert("RGBA"), np.float64) / 255
    bg = parse_background(report["background"])
    goal = to_rgb(photo, bg)
    before = compare(resvg_rgb(svg, photo.shape[1], bg), goal)
    after = compare(resvg_rgb(written, photo.shape[1], bg), goal)
    times = report["seconds"]["iterations"]
    n = max(1, len(times) // 10)
    print(f"\nthe default refine job, {svg.name}, boundary budget {budget:g}, point rate "
          f"{report['point_rate']:.2f} px (outline density {report['outline_density']:.2f})\n")
    print("| shapes | iterations | job | s/iteration start -> end | PSNR before -> after (resvg) | gain |")
    print("|---:|---:|---:|---|---|---:|")
    print(f"| {report['shapes']:,} | {report['iterations']} | {wall:.1f} s "
          f"| {statistics.median(times[:n]):.3f} -> {statistics.median(times[-n:]):.3f} "
          f"| {before['psnr']:.2f} -> {after['psnr']:.2f} dB | {after['psnr'] - before['psnr']:+.2f} dB |")
    print_breakdown(svg.stem, laps, report["coarse_iterations"])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--counts", default="300,1000,3000,10000", help="path budgets for the curve ('' for none)")
    ap.add_argument("--iterations", type=int, default=16, help="iterations per count for the curve")
    ap.add_argument("--job", type=int, default=3000, help="the budget whose whole job to run (0: none)")
    ap.add_argument("--inputs", type=Path, help="folder for the photo and its traces (kept; default temporary)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--refined", type=int, default=0,
                    help="also time the curve's iterations on the N-path trace as an earlier --job N refined "
                         "it (coffee_N.refined.svg in --inputs): the end of a run, where outlines have grown")
    ap.add_argument("--budgets", default="", help="boundary budgets to compare, e.g. 0,1 (default: the configured one)")
    ap.add_argument("--set", action="append", default=[], help="a config override, KEY=VALUE")
    args = ap.parse_args()
    overrides = parse_sets(args.set)
    overrides.setdefault("optimize", {}).update(threads=args.threads)
    counts = [int(c) for c in args.counts.split(",") if c]
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.inputs or Path(tmp)
        target, svgs = make_inputs(folder, sorted(set(counts + ([args.job] if args.job else []))))
        budgets = [float(b) for b in args.budgets.split(",") if b] or [None]
        chosen = {n: svgs[n] for n in counts}
        refined = folder / f"coffee_{args.refined}.refined.svg"
        if args.refined and refined.exists():
            chosen[f"{args.refined} refined"] = refined
        if chosen:
            curve(target, chosen, args.iterations, overrides, Path(tmp), budgets)
        for budget in budgets if args.job else []:
            job(target, svgs[args.job], *with_budget(overrides, budget), folder)


if __name__ == "__main__":
    main()

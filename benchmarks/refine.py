"""Refining Adobe Illustrator's Image Trace of kitty and peppers with the default settings
(the paper's Table 2 experiment), scored at full size both by vecfit's own render and by
resvg rendering the written SVG. Also where an iteration's time goes, at the start (first
10% of the iterations) and the end (last 10%) of each run, and PSNR against wall time.
Times are also given in R, the machine unit measured at the start (benchmarks/machine.py).

Usage: python benchmarks/refine.py [--iterations N] [--threads T] [--images kitty,peppers]
       [--set optimize.mode=analytic ...]
"""
from __future__ import annotations

import argparse
import math
import statistics
import tempfile
import warnings
from pathlib import Path

from common import SHARED, parse_sets, resvg_rgb
from machine import in_r, machine_unit

from vecfit.io.colors import parse_background
from vecfit.jobs.config import resolve
from vecfit.fitting.metrics import compare, to_rgb
from vecfit.jobs.fit import load_target
from vecfit.jobs.protocol import Inputs, Outputs
from vecfit.jobs.refine import run as refine
from vecfit.renderer.stopwatch import Stopwatch

PHOTOS = SHARED / "data" / "photos"
TARGETS = {"kitty": "kitty.jpg", "peppers": "peppers.png"}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--iterations", type=int)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--images", default="kitty,peppers")
    ap.add_argument("--set", action="append", default=[], help="a config override, KEY=VALUE")
    args = ap.parse_args()
    overrides = parse_sets(args.set)
    overrides.setdefault("optimize", {}).update(threads=args.threads)
    if args.iterations is not None:
        overrides["optimize"]["iterations"] = args.iterations
    config = resolve("refine", overrides=overrides)
    opt = config["optimize"]
    unit = machine_unit()
    print(f"machine unit R = {unit:.4f} s (benchmarks/machine.py)")
    print(f"refine defaults: {opt['iterations']} iterations, {opt['mode']} {opt['samples']}x{opt['samples']}, "
          f"loss {opt['loss']}, max size {opt['max_size']}, lr {opt['lr']}, {args.threads} threads")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.images.split(","):
            target_path, svg_path = PHOTOS / TARGETS[name], PHOTOS / f"{name}.svg"
            outputs = Outputs.beside(Path(tmp) / TARGETS[name])
            with warnings.catch_warnings(), Stopwatch() as watch:
                warnings.simplefilter("ignore")
                report = refine(Inputs(image=target_path, svg=svg_path), config, outputs)
            target = load_target(target_path)
            bg = parse_background(report["background"])
            goal = to_rgb(target, bg)
            before = compare(resvg_rgb(svg_path, target.shape[1], bg), goal)
            after = compare(resvg_rgb(outputs.svg, target.shape[1], bg), goal)
            rows.append((name, report, before, after, watch.laps))

    print()
    print("| image | size | shapes | parameters | iterations | time | per iteration | PSNR before -> after (vecfit) "
          "| PSNR before -> after (resvg) | gain (resvg) | MSE before -> after (resvg) | MSE ratio | SSIM (resvg) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, rep, before, after, _ in rows:
        w, h = rep["size"]
        ow, oh = rep["optimized_size"]
        print(f"| {name} | {w}x{h} (opt. {ow}x{oh}) | {rep['shapes']} | {rep['parameters']['total']} "
              f"| {rep['iterations']} | {in_r(rep['seconds']['total'], unit)} "
              f"| {in_r(rep['seconds']['per_iteration'], unit)} "
              f"| {rep['initial']['psnr']:.2f} -> {rep['optimized']['psnr']:.2f} "
              f"| {before['psnr']:.2f} -> {after['psnr']:.2f} | {after['psnr'] - before['psnr']:+.2f} dB "
              f"| {before['mse']:.5f} -> {after['mse']:.5f} | {before['mse'] / after['mse']:.2f}x "
              f"| {before['ssim']:.4f} -> {after['ssim']:.4f} |")
    for name, rep, _, _, laps in rows:
        print_breakdown(name, laps, rep["coarse_iterations"])
        print_progress(name, rep)


# The core's passes (kernels) first, then everything around them.
KERNELS = ("forward pixels", "backward interior", "backward boundary")
PHASES = KERNELS + ("pack", "core prepare", "core plan", "bindings", "pack autograd", "loss", "adam", "other")


def split(lap: dict) -> dict:
    """One iteration's phases. The loop's forward is packing + the core's forward call +
    the loss; its backward the core's backward call + autograd through the packing and the
    loss. A core call is preparing the scene, planning (tile binning, boundary pieces),
    the per-pixel or per-boundary-sample work, and the bindings' array conversions."""
    g = lambda k: lap.get(k, 0.0)  # noqa: E731
    out = {"forward pixels": g("core forward"), "backward interior": g("core backward interior"),
           "backward boundary": g("core backward boundary"), "pack": g("pack"),
           "core prepare": g("core prepare"), "core plan": g("core plan"), "adam": g("adam")}
    inside = sum(out[k] for k in KERNELS) + out["core prepare"] + out["core plan"]
    out["bindings"] = g("call forward") + g("call backward") - inside
    out["loss"] = g("forward") - out["pack"] - g("call forward")
    out["pack autograd"] = g("backward") - g("call backward")
    out["other"] = lap["iteration"] - sum(out.values())
    out["iteration"] = lap["iteration"]
    return out


def print_breakdown(name: str, laps: list, coarse: int) -> None:
    """Median seconds per phase over the first 10% of the iterations (at half size when the
    run starts coarse), the first 10% at full size and the last 10%; "flat" compares the
    last with the first at full size."""
    n = max(1, len(laps) // 10)
    spans = {"start": laps[:n], "full size from": laps[coarse:coarse + n], "end": laps[-n:]}
    if coarse == 0:
        del spans["full size from"]
    print(f"\n{name}: seconds per iteration (median of {n} iterations; {coarse} coarse iterations)\n")
    print("| phase | " + " | ".join(spans) + " | flat (end / full-size start) |")
    print("|---|" + "---|" * (len(spans) + 1))
    parts = {k: [split(lap) for lap in v] for k, v in spans.items()}
    first = "full size from" if coarse else "start"
    for phase in PHASES + ("iteration",):
        values = {k: statistics.median(p[phase] for p in part) for k, part in parts.items()}
        ratio = f"{values['end'] / values[first]:.2f}x" if values[first] > 0 else ""
        print(f"| {phase} | " + " | ".join(f"{v:.4f}" for v in values.values()) + f" | {ratio} |")
    for label, part in parts.items():
        total = statistics.median(p["iteration"] for p in part)
        outside = sum(statistics.median(p[k] for p in part) for k in PHASES if k not in KERNELS)
        print(f"outside the core's passes ({label}): {outside / total:.0%}")


def print_progress(name: str, rep: dict) -> None:
    """PSNR of the render (from the loss curve) against wall time; the coarse iterations'
    PSNR is against the target at half size, so it is higher than the full size's."""
    times, curve = rep["seconds"]["iterations"], rep["loss_curve"]
    marks = sorted({min(len(curve) - 1, round(f * (len(curve) - 1))) for f in (0, .1, .2, .4, .6, .8, 1)})
    print(f"\n{name}: PSNR (from the L2 loss, at the optimised size) against the loop's wall time\n")
    print("| iteration | seconds | PSNR |")
    print("|---|---|---|")
    for i in marks:
        psnr = 10 * math.log10(1 / curve[i]) if curve[i] > 0 else math.inf
        print(f"| {i + 1} | {sum(times[:i + 1]):.1f} | {psnr:.2f} |")


if __name__ == "__main__":
    main()

"""Refining Adobe Illustrator's Image Trace of kitty and peppers with the default settings
(the paper's Table 2 experiment), scored at full size both by vecfit's own render and by
resvg rendering the written SVG.

Usage: python benchmarks/refine.py [--iterations N] [--threads T] [--images kitty,peppers]
       [--set optimize.mode=analytic ...]
"""
from __future__ import annotations

import argparse
import tempfile
import warnings
from pathlib import Path

from common import SHARED, resvg_rgb

from vecfit.io.colors import parse_background
from vecfit.jobs.config import resolve
from vecfit.fitting.metrics import compare, to_rgb
from vecfit.jobs.fit import Outputs, load_target
from vecfit.jobs.refine import run as refine

PHOTOS = SHARED / "data" / "photos"
TARGETS = {"kitty": "kitty.jpg", "peppers": "peppers.png"}


def parse_sets(items) -> dict:
    """--set optimize.mode=analytic -> {"optimize": {"mode": "analytic"}}"""
    out: dict = {}
    for item in items:
        key, _, value = item.partition("=")
        *path, last = key.split(".")
        d = out
        for p in path:
            d = d.setdefault(p, {})
        try:
            d[last] = int(value)
        except ValueError:
            try:
                d[last] = float(value)
            except ValueError:
                d[last] = value
    return out


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
    print(f"refine defaults: {opt['iterations']} iterations, {opt['mode']} {opt['samples']}x{opt['samples']}, "
          f"loss {opt['loss']}, max size {opt['max_size']}, lr {opt['lr']}, {args.threads} threads")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.images.split(","):
            target_path, svg_path = PHOTOS / TARGETS[name], PHOTOS / f"{name}.svg"
            outputs = Outputs.beside(Path(tmp) / TARGETS[name])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                report = refine(target_path, svg_path, config, outputs)
            target = load_target(target_path)
            bg = parse_background(report["background"])
            goal = to_rgb(target, bg)
            before = compare(resvg_rgb(svg_path, target.shape[1], bg), goal)
            after = compare(resvg_rgb(outputs.svg, target.shape[1], bg), goal)
            rows.append((name, report, before, after))

    print()
    print("| image | size | shapes | parameters | iterations | time | s/iter | PSNR before -> after (vecfit) "
          "| PSNR before -> after (resvg) | gain (resvg) | MSE before -> after (resvg) | MSE ratio | SSIM (resvg) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, rep, before, after in rows:
        w, h = rep["size"]
        ow, oh = rep["optimized_size"]
        print(f"| {name} | {w}x{h} (opt. {ow}x{oh}) | {rep['shapes']} | {rep['parameters']['total']} "
              f"| {rep['iterations']} | {rep['seconds']['total']:.1f} s | {rep['seconds']['per_iteration']:.3f} "
              f"| {rep['initial']['psnr']:.2f} -> {rep['optimized']['psnr']:.2f} "
              f"| {before['psnr']:.2f} -> {after['psnr']:.2f} | {after['psnr'] - before['psnr']:+.2f} dB "
              f"| {before['mse']:.5f} -> {after['mse']:.5f} | {before['mse'] / after['mse']:.2f}x "
              f"| {before['ssim']:.4f} -> {after['ssim']:.4f} |")


if __name__ == "__main__":
    main()

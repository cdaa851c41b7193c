"""`vecfit retarget` on Adobe Illustrator's cat and ice_cream (../shared/data/scenes),
narrowed to 70% of their width. Checked with resvg: the output's width and height, every
element kept, and how much a salient part is squeezed, against plain scaling.

Squeeze: the bounding box of a distinctive colour (the cat's eye whites, #F9F4EA: the
face's width from eye to eye; the ice-cream truck's blue side, #1CA8E0) in resvg's render
of the input and of the output; its width ratio (output / input) is 1.0 when the part is
not squeezed and 0.70 under plain scaling (measured on the input's render resized).

--squeeze-init: each round starts from the points squeezed uniformly to the round's width
(plain scaling) instead of carried through its seams, to measure what that start is worth.

Usage: python benchmarks/retarget.py [--threads T] [--scenes cat,ice_cream] [--width 70%]
       [--work-size N] [--squeeze-init]
"""
from __future__ import annotations

from common import SCENES  # first: it sets the process up before torch loads

import argparse
import io
import tempfile
import time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import cv2
import numpy as np
from PIL import Image

from vecfit.jobs.config import resolve
from vecfit.jobs.protocol import Inputs, Outputs
from vecfit.jobs.retarget import run as retarget

SALIENT = {"cat": (0xF9, 0xF4, 0xEA), "ice_cream": (0x1C, 0xA8, 0xE0)}


def resvg_rgba(svg) -> np.ndarray:
    import resvg_py
    png = bytes(resvg_py.svg_to_bytes(svg_path=str(svg)))
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float64) / 255


def box(rgba, colour) -> tuple[int, int]:
    """Width and height of the bounding box of opaque pixels within 0.06 of ``colour``."""
    near = (np.abs(rgba[..., :3] - np.asarray(colour) / 255).max(axis=2) < 0.06) & (rgba[..., 3] > 0.9)
    ys, xs = np.nonzero(near)
    return int(xs.max() - xs.min() + 1), int(ys.max() - ys.min() + 1)


def elements(svg) -> int:
    return sum(1 for _ in ET.parse(svg).getroot().iter())


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--scenes", default="cat,ice_cream")
    ap.add_argument("--width", default="70%")
    ap.add_argument("--work-size", type=int)
    ap.add_argument("--squeeze-init", action="store_true")
    args = ap.parse_args()
    overrides = {"optimize": {"threads": args.threads}}
    if args.work_size is not None:
        overrides["retarget"] = {"work_size": args.work_size}
    config = resolve("retarget", overrides=overrides)
    if args.squeeze_init:
        import vecfit.jobs.retarget as job
        from vecfit.editing.points import point_tensors
        from vecfit.scene.placement import shape_matrices

        def squeeze(scene, seams, width, height, axis=0):
            """Plain scaling of the points about the canvas origin, in pixels."""
            import torch
            factor = (width if axis == 0 else height) - len(seams)
            factor /= width if axis == 0 else height
            with torch.no_grad():
                for shape, m in zip(scene.shapes, shape_matrices(scene, width, height).double()):
                    inverse = torch.linalg.inv(m)
                    for t in point_tensors(shape):
                        p = t.detach().double().reshape(-1, 2)
                        px = p @ m[:2, :2].T + m[:2, 2]
                        px[:, axis] *= factor
                        t.copy_((px @ inverse[:2, :2].T + inverse[:2, 2]).reshape(t.shape).to(t.dtype))
        job.carve_points = squeeze
    print(f"retarget: {config['retarget']}, {args.threads} threads, --width {args.width}, "
          f"start of each round: {'squeezed' if args.squeeze_init else 'carried through the seams'}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes.split(","):
            src = SCENES / f"{name}.svg"
            outputs = Outputs.beside(Path(tmp) / f"{name}.svg")
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                report = retarget(Inputs(svg=src), {**config, "retarget": {**config["retarget"], "width": args.width}},
                                  outputs)
            seconds = time.perf_counter() - start
            before, after = resvg_rgba(src), resvg_rgba(outputs.svg)
            h, w = before.shape[:2]
            scaled = cv2.resize(before.astype(np.float32), (after.shape[1], h), interpolation=cv2.INTER_AREA)
            (bw, bh), (aw, ah), (sw, sh) = (box(i, SALIENT[name]) for i in (before, after, scaled))
            rows.append((name, (w, h), after.shape[1::-1], report, elements(src) == elements(outputs.svg),
                         aw / bw, sw / bw, ah / bh, seconds))
    print()
    print("| scene | input | output (resvg) | seams | fit PSNR | elements kept | salient width: retarget | "
          "plain scaling | salient height ratio | s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, (w, h), (ow, oh), r, kept, ratio, plain, hratio, seconds in rows:
        print(f"| {name} | {w}x{h} | {ow}x{oh} | {r['seams']['vertical']} | {r['optimized']['psnr']:.2f} | "
              f"{'yes' if kept else 'NO'} | {ratio:.2f} | {plain:.2f} | {hratio:.2f} | {seconds:.0f} |")


if __name__ == "__main__":
    main()

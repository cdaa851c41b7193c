"""`vecfit edit` against the issue's bar: an SVG whose fills of a few elements were changed
and one element moved by a few pixels is rendered by resvg (EDITED.png); `vecfit edit`
brings that edit into the unedited SVG, and resvg's render of the result must match
EDITED.png at >= 33 dB and at least 8 dB better than the unedited SVG does, with the
same elements and ids.

Usage: python benchmarks/edit.py [--threads T] [--scenes cat,ice_cream,tiger]
       [--set edit.anchor=0.1 ...]
"""
from __future__ import annotations

from common import ROOT, SCENES, parse_sets, resvg_rgb  # first: it sets the process up before torch loads

import argparse
import math
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from PIL import Image

from vecfit.fitting.metrics import compare
from vecfit.jobs.config import resolve
from vecfit.jobs.edit import run as edit
from vecfit.jobs.protocol import Inputs, Outputs

sys.path.insert(0, str(ROOT / "tests"))
from editing_cases import edited_svg, structure  # noqa: E402  (shared with the tests)

# scene -> (render width, indices of the drawn elements recoloured, index moved, dx, dy in
# user units)
# (the move is 3 px right and 2 px down at the render's size)
CASES = {
    "cat": (368, [(5, "#3b7dd8"), (20, "#e8c33a"), (33, "#45a35b")], 12, 1.5, 1.0),
    "ice_cream": (700, [(10, "#8a2be2"), (40, "#ff7f50"), (90, "#2e8b57")], 60, 6.0, 4.0),
    "tiger": (495, [(30, "#2060c0"), (120, "#30a050"), (200, "#c03070")], 150, 3.0, 2.0),
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--scenes", default="cat,ice_cream,tiger")
    ap.add_argument("--set", action="append", default=[], help="a config override, KEY=VALUE")
    args = ap.parse_args()
    overrides = parse_sets(args.set)
    overrides.setdefault("optimize", {}).update(threads=args.threads)
    config = resolve("edit", overrides=overrides)
    print(f"edit defaults: {config['optimize']['iterations']} iterations, {config['edit']}, "
          f"{args.threads} threads")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name in args.scenes.split(","):
            width, recolour, moved, dx, dy = CASES[name]
            src = SCENES / f"{name}.svg"
            edited = tmp / f"{name}.edited.svg"
            edited.write_text(edited_svg(src.read_text(encoding="utf-8"), recolour, moved, dx, dy),
                              encoding="utf-8")
            png = tmp / f"{name}.edited.png"
            import resvg_py
            png.write_bytes(bytes(resvg_py.svg_to_bytes(svg_path=str(edited), width=width)))
            with Image.open(png) as im:
                rgba = np.asarray(im.convert("RGBA"), np.float64) / 255
            goal = rgba[..., :3] * rgba[..., 3:] + (1 - rgba[..., 3:])  # over white
            outputs = Outputs.beside(png)
            start = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                report = edit(Inputs(image=png, svg=src), config, outputs)
            seconds = time.perf_counter() - start
            before = compare(resvg_rgb(src, width), goal)["psnr"]
            after = compare(resvg_rgb(outputs.svg, width), goal)["psnr"]
            same = structure(src) == structure(outputs.svg)
            rows.append((name, width, report, before, after, same, seconds))

    print()
    print("| scene | size | changed px | resvg PSNR before | after | gain | inside before -> after | "
          "outside before -> after | elements changed | structure kept | s | bar |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, width, r, before, after, same, seconds in rows:
        ok = after >= 33 and after - before >= 8 and same
        f = lambda v: "inf" if v is None or (isinstance(v, float) and math.isinf(v)) else f"{v:.2f}"
        print(f"| {name} | {r['size'][0]}x{r['size'][1]} | {r['changed_region']['pixels']} | {before:.2f} | "
              f"{after:.2f} | {after - before:+.2f} | {f(r['psnr_inside']['before'])} -> "
              f"{f(r['psnr_inside']['after'])} | {f(r['psnr_outside']['before'])} -> "
              f"{f(r['psnr_outside']['after'])} | {len(r['elements']['changed'])}/{r['elements']['total']} | "
              f"{'yes' if same else 'NO'} | {seconds:.1f} | {'met' if ok else 'MISSED'} |")


if __name__ == "__main__":
    main()

"""Forward rendering speed: vecfit against resvg on the benchmark scenes.

    python benchmarks/render.py [--threads 2] [--repeats 5]

Prints the median time of each configuration and its ratio to resvg measured in the same
run (the steadier figure on a shared machine). vecfit's time covers packing the scene
and rendering (scene preparation and binning included), not parsing the SVG; resvg's
covers parsing, rendering and PNG encoding (resvg-py has no render-only call).
"""
from __future__ import annotations

import argparse
import warnings

from common import SCENES, median_time

SCENE_NAMES = ["tiger", "mcseem2", "boston"]
CONFIGS = [("MC 2x2", "mc", 2), ("MC 4x4", "mc", 4), ("analytic 1x1", "analytic", 1)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()

    import resvg_py

    import vecfit

    rows = []
    for name in SCENE_NAMES:
        path = SCENES / f"{name}.svg"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = vecfit.load_svg(path)
        w, h = round(scene.width), round(scene.height)
        t_resvg = median_time(lambda: resvg_py.svg_to_bytes(svg_path=str(path), width=w, height=h),
                              args.repeats)
        t_load = median_time(lambda: vecfit.load_svg(path), 3)
        row = {"scene": f"{name} {w}x{h}", "resvg": t_resvg, "load": t_load}
        for label, mode, n in CONFIGS:
            row[label] = median_time(lambda: vecfit.render(scene, w, h, samples=n, mode=mode,
                                                           threads=args.threads), args.repeats)
        rows.append(row)

    head = f"{'scene':22s} {'resvg':>8s}" + "".join(f" {label:>22s}" for label, _, _ in CONFIGS) + f" {'svg load':>9s}"
    print(f"threads={args.threads}, median of {args.repeats}; time in s (ratio to resvg)")
    print(head)
    print("-" * len(head))
    for r in rows:
        cells = "".join(f" {r[label]:>11.3f} ({r[label] / r['resvg']:5.1f}x)  " for label, _, _ in CONFIGS)
        print(f"{r['scene']:22s} {r['resvg']:8.3f}{cells} {r['load']:9.3f}")


if __name__ == "__main__":
    main()

"""Tracing quality and speed: skimage's photographs traced at several path budgets.

    python benchmarks/trace.py [--budgets 250,500,1000,2000] [--images astronaut,...]
                               [--overlap-check]

For each image and path budget: the paths and segments written, the trace time, and the
PSNR of the trace rendered by vecfit (MC 2x2, box filter, over white) against the image
(skimage.metrics.peak_signal_noise_ratio on float RGB, data_range 1); then the mean PSNR
per budget. --overlap-check also traces at the default budget with shapes not reaching
under their neighbours (overlap 0), which shows the seams that overlap closes.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time

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


def measure(image: np.ndarray, settings) -> dict:
    from skimage.metrics import peak_signal_noise_ratio

    from vecfit.trace import trace_image

    start = time.perf_counter()
    result = trace_image(image, settings)
    seconds = time.perf_counter() - start
    h, w = image.shape[:2]
    psnr = peak_signal_noise_ratio(image[..., :3], render_svg(result.svg, w, h), data_range=1)
    return {"paths": result.paths, "segments": result.segments, "colors": result.colors,
            "seconds": seconds, "psnr": psnr}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--budgets", default=",".join(map(str, BUDGETS)))
    ap.add_argument("--images", default=",".join(IMAGES))
    ap.add_argument("--overlap-check", action="store_true")
    args = ap.parse_args()
    budgets = [int(b) for b in args.budgets.split(",")]
    images = args.images.split(",")

    from vecfit.trace import TraceSettings

    defaults = TraceSettings()
    print(f"defaults: colors={defaults.colors} min_area={defaults.min_area} "
          f"tolerance={defaults.tolerance} corner_angle={defaults.corner_angle} "
          f"blur={defaults.blur} overlap={defaults.overlap} smoothing={defaults.smoothing}")
    head = (f"{'image':16s} {'budget':>6s} {'paths':>6s} {'segments':>8s} {'seg/path':>8s} "
            f"{'trace s':>8s} {'PSNR dB':>8s}")
    print(head)
    print("-" * len(head))
    psnr = {b: [] for b in budgets}
    for name in images:
        image = load(name)
        label = f"{name} {image.shape[1]}x{image.shape[0]}"
        for b in budgets:
            r = measure(image, TraceSettings(paths=b))
            psnr[b].append(r["psnr"])
            print(f"{label:16s} {b:6d} {r['paths']:6d} {r['segments']:8d} "
                  f"{r['segments'] / r['paths']:8.1f} {r['seconds']:8.2f} {r['psnr']:8.2f}", flush=True)
    print("-" * len(head))
    for b in budgets:
        print(f"{'mean':16s} {b:6d} {'':6s} {'':8s} {'':8s} {'':8s} {np.mean(psnr[b]):8.2f}")

    if args.overlap_check:
        b = defaults.paths
        print(f"\nseams: PSNR at {b} paths with overlap 0 (shapes meet edge to edge) "
              f"and {defaults.overlap} (the default)")
        rows = []
        for name in images:
            image = load(name)
            r0 = measure(image, TraceSettings(paths=b, overlap=0))
            r1 = measure(image, TraceSettings(paths=b))
            rows.append((r0["psnr"], r1["psnr"]))
            print(f"{name:16s} {r0['psnr']:8.2f} {r1['psnr']:8.2f}", flush=True)
        print(f"{'mean':16s} {np.mean([r[0] for r in rows]):8.2f} {np.mean([r[1] for r in rows]):8.2f}")


if __name__ == "__main__":
    main()

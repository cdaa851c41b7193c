"""Shared helpers for the benchmark scripts: data paths and robust timing."""
from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# ../shared beside the repository, or where VECFIT_SHARED points (as for the tests)
SHARED = Path(os.environ.get("VECFIT_SHARED") or ROOT.parent / "shared")
SCENES = SHARED / "data" / "scenes"


def median_time(fn, repeats: int = 5, warmup: int = 1) -> float:
    """Median wall time of fn() over `repeats` runs after `warmup` runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def resvg_rgb(svg, width: int, background=(1.0, 1.0, 1.0)):
    """The SVG file rendered by resvg at ``width`` pixels, as float RGB over background."""
    import io

    import numpy as np
    import resvg_py
    from PIL import Image

    from vecfit.metrics import to_rgb
    png = bytes(resvg_py.svg_to_bytes(svg_path=str(svg), width=width))
    rgba = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float64) / 255
    return to_rgb(rgba, background)

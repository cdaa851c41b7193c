"""Shared helpers for the benchmark scripts: data paths and robust timing."""
from __future__ import annotations

import compileall
import os
import statistics
import time
import warnings
from pathlib import Path

# Before torch loads (import this module first): idle OpenMP threads sleep, as the vecfit
# command sets it (see vecfit/__init__.py); spinning they distort every timing here.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

ROOT = Path(__file__).resolve().parents[1]
# ../shared beside the repository, or where VECFIT_SHARED points (as for the tests)
SHARED = Path(os.environ.get("VECFIT_SHARED") or ROOT.parent / "shared")
SCENES = SHARED / "data" / "scenes"


def user_environment() -> dict:
    """The environment for timing vecfit as a command the way a user's install runs it:
    byte-compiled (pip compiles the modules when it installs them). A shell with
    PYTHONDONTWRITEBYTECODE set would otherwise compile some sixty modules from source on
    every start (0.07 s of `vecfit trace --no-refine`). The package is compiled here once."""
    import vecfit
    compileall.compile_dir(str(Path(vecfit.__file__).parent), quiet=1)
    cli = ROOT / "cli"
    if cli.is_dir():  # an editable install's command-line package
        compileall.compile_dir(str(cli), quiet=1)
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


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

    from vecfit.fitting.metrics import to_rgb
    png = bytes(resvg_py.svg_to_bytes(svg_path=str(svg), width=width))
    rgba = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float64) / 255
    return to_rgb(rgba, background)


def timed(fn, repeats):
    """Medians of each of the values fn() returns, over `repeats` runs after one warm-up."""
    fn()
    out = []
    for _ in range(repeats):
        out.append(fn())
    return [statistics.median(x) for x in zip(*out)]


def scene_workload(name, mode, samples, threads, repeats, device="cpu"):
    """Median (forward, backward) seconds of one benchmark scene, loss = sum of the squared
    image, gradients of the path points; both times taken in the same run."""
    import vecfit
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(SCENES / f"{name}.svg")
    params = [s.geometry.points for s in scene.shapes if hasattr(s.geometry, "points")]
    for p in params:
        p.requires_grad_(True)

    def run():
        t0 = time.perf_counter()
        img = vecfit.render(scene, samples=samples, mode=mode, threads=threads, device=device)
        t1 = time.perf_counter()
        (img ** 2).sum().backward()
        t2 = time.perf_counter()
        for p in params:
            p.grad = None
        return t1 - t0, t2 - t1
    return timed(run, repeats)


def parse_sets(items) -> dict:
    """--set optimize.mode=analytic -> {"optimize": {"mode": "analytic"}}"""
    out: dict = {}
    for item in items:
        key, _, value = item.partition("=")
        *path, last = key.split(".")
        d = out
        for p in path:
            d = d.setdefault(p, {})
        if value in ("true", "false"):
            d[last] = value == "true"
            continue
        try:
            d[last] = int(value)
        except ValueError:
            try:
                d[last] = float(value)
            except ValueError:
                d[last] = value
    return out

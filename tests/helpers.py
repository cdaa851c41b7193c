"""Small helpers the test modules share: the CLI runner, quiet SVG loading, skipping when
shared data is missing, skimage photos as small PNG targets, a shape tangent to the
canvas's edges, the core's test switches, and a sweep's split into fast and slow."""
from __future__ import annotations

import contextlib
import warnings
from pathlib import Path

import pytest
from click.testing import CliRunner

import vecfit
from vecfit import _core
from vecfit.cli.commands import main


def run(*args):
    """`vecfit ARGS...` in this process; exceptions propagate (a traceback is a failure)."""
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def quiet_load(path):
    """An SVG file as a Scene, its warnings about skipped content silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return vecfit.load_svg(path)


@contextlib.contextmanager
def brute_force():
    """Renders in this block test every draw at every sample (the core's test switch): the
    plain loop that the tiles are checked against."""
    old = _core.brute_force(True)
    try:
        yield
    finally:
        _core.brute_force(old)


@contextlib.contextmanager
def gpu_lists():
    """Backward passes in this block run the CPU lanes with a GPU thread's list sizes first
    (the core's test switch), as a GPU run would, falling back where they overflow."""
    old = _core.emulate_gpu_lists(True)
    try:
        yield
    finally:
        _core.emulate_gpu_lists(old)


def slow_unless(values, fast) -> list:
    """A sweep's parameters for ``pytest.mark.parametrize``: those in ``fast`` run in `make
    test-fast`, the others are marked slow (`make test` runs them all; ids are unchanged)."""
    fast = list(fast)
    missing = [v for v in fast if v not in values]
    assert not missing, f"not among the parameters: {missing}"
    return [v if v in fast else pytest.param(*(v if isinstance(v, tuple) else (v,)), marks=pytest.mark.slow)
            for v in values]


def need(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"shared data not found: {path}")
    return path


def photo_png(tmp_path_factory, name: str, size: tuple[int, int]) -> Path:
    """skimage.data.NAME resized to (width, height) and saved as a PNG."""
    import skimage.data
    from PIL import Image
    folder = tmp_path_factory.mktemp(name)
    Image.fromarray(getattr(skimage.data, name)()).resize(size, Image.LANCZOS).save(folder / f"{name}.png")
    return folder / f"{name}.png"


def rounded_diamond(x, y, size=128, half=40.0, radius=24.0):
    """Signed distance (px) to a square standing on its corner (its corners ``half`` from
    the centre) rounded by ``radius``: at half + radius = size / 2 it touches the four
    sides of a size x size canvas at their middles, as logos-005 does."""
    import numpy as np

    u, v = np.abs(x - size / 2), np.abs(y - size / 2)
    t = np.clip((half - u + v) / (2 * half), 0, 1)
    dist = np.hypot(u - half * (1 - t), v - half * t)
    return np.where(u + v <= half, -dist, dist) - radius


def two_shapes_png(path: Path):
    """A 48 x 36 PNG of a red disc and a blue square on off-white, saved at ``path``: a
    small target the jobs trace and refine in a few iterations. Returns the PIL image."""
    from PIL import Image, ImageDraw

    image = Image.new("RGB", (48, 36), (240, 240, 235))
    draw = ImageDraw.Draw(image)
    draw.ellipse((6, 5, 30, 29), fill=(200, 60, 40))
    draw.rectangle((26, 14, 44, 32), fill=(40, 90, 180))
    image.save(path)
    return image

"""Small helpers the test modules share: the CLI runner, quiet SVG loading, skipping when
shared data is missing, skimage photos as small PNG targets, and the core's test switches."""
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

"""Small helpers the test modules share: the CLI runner, quiet SVG loading, skipping when
shared data is missing, and skimage photos as small PNG targets."""
from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from click.testing import CliRunner

import vecfit
from vecfit.cli.commands import main


def run(*args):
    """`vecfit ARGS...` in this process; exceptions propagate (a traceback is a failure)."""
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def quiet_load(path):
    """An SVG file as a Scene, its warnings about skipped content silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return vecfit.load_svg(path)


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

"""The core exports its array layout (_core.layout(), from csrc/scene/scene.h), and
vecfit/renderer/layout.py exposes it under the names the packer uses (pack.py imports
them instead of keeping copies): the values are the contract written out here, every
table the bindings read is listed with its row width, and the bindings refuse a table
whose rows have another width."""
from __future__ import annotations

import numpy as np
import pytest

from vecfit import _core
from vecfit.renderer import layout

# The contract, as pack.py copied it before the core exported it.
PACK_LITERALS = {
    "SHAPE_PATH": 0, "SHAPE_ELLIPSE": 1,
    "DRAW_FILL": 0, "DRAW_STROKE": 1,
    "FILL_RULES": {"nonzero": 0, "evenodd": 1},
    "CAPS": {"butt": 0, "round": 1, "square": 2},
    "JOINS": {"miter": 0, "round": 1, "bevel": 2},
    "PAINT_SOLID": 0, "PAINT_LINEAR": 1, "PAINT_RADIAL": 2,
}
PACK_COLUMNS = {"points": 2, "point_widths": 1, "segments": 5, "subpaths": 3, "shapes": 4, "ellipses": 6,
                "draws": 8, "draw_params": 6, "paints": 3, "paint_params": 11, "stop_offsets": 1,
                "stop_colors": 4, "layer_parents": 1, "layer_opacity": 1}
INT_TABLES = {"segments", "subpaths", "shapes", "draws", "paints", "layer_parents"}


@pytest.mark.parametrize("name", sorted(PACK_LITERALS))
def test_constants_are_the_literals_pack_uses(name):
    assert getattr(layout, name) == PACK_LITERALS[name]


def test_columns_are_the_widths_pack_uses():
    assert layout.COLUMNS == PACK_COLUMNS


def test_core_layout_keys():
    assert set(_core.layout()) == {"shape_kinds", "draw_kinds", "fill_rules", "caps", "joins", "paint_kinds",
                                   "columns"}


def empty_scene() -> dict:
    """A scene with nothing to draw, every table empty with rows of its width (layer 0,
    the root, is required)."""
    scene = {key: np.zeros((0, cols) if cols > 1 else (0,), dtype=np.int32 if key in INT_TABLES else np.float32)
             for key, cols in layout.COLUMNS.items()}
    scene["layer_parents"] = np.array([-1], dtype=np.int32)
    scene["layer_opacity"] = np.array([1.0], dtype=np.float32)
    return scene


def render(scene: dict) -> np.ndarray:
    return _core.render(scene, _core.RenderOptions(width=4, height=3, samples=1, threads=1))


def test_the_listed_tables_make_a_scene():
    image = render(empty_scene())
    assert image.shape == (3, 4, 4) and not image.any()


@pytest.mark.parametrize("key", sorted(PACK_COLUMNS))
@pytest.mark.parametrize("rows", [1, 3])
def test_a_table_with_the_wrong_width_is_refused(key, rows):
    cols = layout.COLUMNS[key]
    scene = empty_scene()
    # rows x (cols + 1) values: with 3 rows of a 1- or 2-wide table the total is a whole
    # number of rows, so only the width itself tells it apart
    scene[key] = np.zeros((rows, cols + 1), dtype=scene[key].dtype)
    with pytest.raises(ValueError, match=f"{key} has the wrong shape"):
        render(scene)


def test_a_flat_table_must_hold_whole_rows():
    scene = empty_scene()
    scene["draws"] = np.zeros(layout.COLUMNS["draws"] + 1, dtype=np.int32)
    with pytest.raises(ValueError, match="draws has the wrong shape"):
        render(scene)

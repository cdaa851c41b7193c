"""The tracer's path data (svgtext.path_data): closed subpaths of cubics, each closed by a
Z after its last cubic, two decimals, relative after each subpath's M (the SVG writer's
format_relative_path_data)."""
from __future__ import annotations

import numpy as np
import pytest

from vecfit.errors import VecfitError
from vecfit.initial.tracer.svgtext import path_data
from vecfit.svg.pathdata import parse_path_data, to_arrays


def test_a_square_of_cubics():
    square = np.array([[[0, 0], [1, 0], [2, 0], [3, 0]], [[3, 0], [3, 1], [3, 2], [0, 0]]], float)
    assert path_data([square]) == "M0 0c1 0 2 0 3 0 0 1 0 2-3 0z"


def test_empty_subpaths_are_left_out():
    assert path_data([]) == ""
    assert path_data([np.zeros((0, 4, 2))]) == ""


def test_many_subpaths_read_back_to_hundredths():
    rng = np.random.default_rng(0)
    subpaths = [rng.uniform(-20, 600, (int(rng.integers(1, 7)), 4, 2)) for _ in range(40)]
    for segs in subpaths:
        segs[1:, 0] = segs[:-1, 3]  # each cubic starts where the one before ends
    text = path_data(subpaths)
    assert "-0 " not in text and "-0-" not in text and text.count("z") == 40
    points, degrees, table = to_arrays(parse_path_data(text))
    written = np.concatenate([np.concatenate([s[:1, 0], s[:, 1:].reshape(-1, 2)]) for s in subpaths])
    assert np.abs(points - np.round(written, 2)).max() < 1e-9
    assert [closed for _, _, closed in table] == [True] * 40


def test_non_finite_numbers_are_refused():
    with pytest.raises(VecfitError, match="non-finite"):
        path_data([np.full((1, 4, 2), np.nan)])

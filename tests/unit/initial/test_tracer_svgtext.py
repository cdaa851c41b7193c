"""The tracer's path data (svgtext.path_data_many) is what vecfit's path-data writer
(vecfit.svg.pathdata.format_path_data) writes for the same closed cubic subpaths, and
its numbers (format_hundredths) are fmt_many's."""
from __future__ import annotations

import numpy as np
import pytest

from vecfit.errors import VecfitError
from vecfit.initial.tracer.svgtext import DECIMALS, format_hundredths, path_data_many
from vecfit.svg.numbers import fmt_many
from vecfit.svg.pathdata import format_path_data


def written(subpaths) -> str:
    """format_path_data of closed subpaths of cubics (each closed by a line back to its start)."""
    points, degrees, spans = [], [], []
    for segs in subpaths:
        if len(segs) == 0:
            continue
        spans.append((len(degrees), len(segs) + 1, True))
        points += [segs[:1, 0], segs[:, 1:].reshape(-1, 2)]
        degrees += [3] * len(segs) + [1]
    if not spans:
        return ""
    return format_path_data(np.concatenate(points), degrees, spans, decimals=DECIMALS, compact=True)


def test_path_data_is_the_writers():
    rng = np.random.default_rng(0)
    shapes = []
    for _ in range(60):
        shape = []
        for _ in range(int(rng.integers(0, 4))):
            segs = rng.uniform(-20, 600, (int(rng.integers(0, 7)), 4, 2))
            # numbers that round to zero from below, halves of a hundredth, whole numbers
            segs[rng.random(segs.shape) < 0.1] = -0.001
            segs[rng.random(segs.shape) < 0.1] = 2.675
            segs[rng.random(segs.shape) < 0.1] = np.round(segs[rng.random(segs.shape) < 0.1].sum())
            shape.append(segs)
        shapes.append(shape)
    got = path_data_many(shapes)
    assert got == [written(shape) for shape in shapes]
    assert sum(map(len, got)) > 5_000 and "" in got
    assert "-0 " not in " ".join(got)


def test_no_shapes_and_empty_shapes():
    assert path_data_many([]) == []
    assert path_data_many([[], [np.zeros((0, 4, 2))]]) == ["", ""]
    square = np.array([[[0, 0], [1, 0], [2, 0], [3, 0]], [[3, 0], [3, 1], [3, 2], [0, 0]]], float)
    assert path_data_many([[square]]) == ["M0 0C1 0 2 0 3 0C3 1 3 2 0 0Z"]


def test_non_finite_numbers_are_refused():
    with pytest.raises(VecfitError, match="non-finite"):
        path_data_many([[np.full((1, 4, 2), np.nan)]])


def test_hundredths_are_fmt_manys():
    rng = np.random.default_rng(1)
    values = np.concatenate([
        rng.uniform(-1000, 1000, 100_000),
        np.round(rng.uniform(-1000, 1000, 20_000), 3),          # many half hundredths: ties
        np.round(rng.uniform(-50, 50, 20_000), 2),              # whole hundredths
        np.arange(-2000, 2000) * 0.005,                         # every half hundredth near 0
        [0.0, -0.0, 1e-9, -1e-9, 0.004999, -0.004999, 0.005, -0.005, 0.015, 2.675, 1.005, 99.995,
         -99.995, 1e9, -1e9, 123456789.125, 1e15, -3e17, 5e-324]])
    got = format_hundredths(values)
    assert got == fmt_many(values, 2)
    assert "-0" not in got and "0" in got
    with pytest.raises(VecfitError, match="non-finite"):
        format_hundredths([1.0, np.inf])

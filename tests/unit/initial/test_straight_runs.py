"""A traced centerline's straight runs through crossings as one line
(vecfit/initial/tracer/straight_runs.py): drawn cubics whose answer is known."""
from __future__ import annotations

import numpy as np

from vecfit.initial.tracer.straight_runs import straight_runs

WIDTH = 12.0


def line(p, q) -> np.ndarray:
    p, q = np.asarray(p, float), np.asarray(q, float)
    return np.stack([p, p + (q - p) / 3, p + 2 * (q - p) / 3, q])


# a line along y = 50 from x = 10 to 110 whose skeleton wobbles 3 px at a crossing at x = 60
WOBBLY = np.stack([line((10, 50), (50, 50)), line((50, 50), (60, 53)), line((60, 53), (70, 50)),
                   line((70, 50), (110, 50))])
CROSSING = np.array([[60.0, 50.0, 6.0]])  # centre, half width: the wobble is within 2 half widths


def test_a_line_wobbling_through_a_crossing_is_one_line():
    out = straight_runs(WOBBLY, CROSSING, WIDTH)
    assert out.shape == (1, 4, 2)
    assert np.allclose(out[0, 0], (10, 50), atol=0.3) and np.allclose(out[0, -1], (110, 50), atol=0.3)
    assert np.abs(out[0, :, 1] - 50).max() < 0.3  # on the line, not on the wobble


def test_without_a_crossing_the_wobble_stays():
    out = straight_runs(WOBBLY, np.zeros((0, 3)), WIDTH)
    assert np.array_equal(out, WOBBLY)


def test_a_wobble_wider_than_half_the_stroke_is_no_line():
    deep = WOBBLY.copy()
    deep[1] = line((50, 50), (60, 58))  # 8 px off: beyond the half width (6), a feature, not thinning's
    deep[2] = line((60, 58), (70, 50))
    assert len(straight_runs(deep, CROSSING, WIDTH)) > 1


def test_a_corner_at_a_crossing_stays_a_corner():
    corner = np.stack([line((10, 50), (60, 50)), line((60, 50), (60, 100))])
    out = straight_runs(corner, np.array([[60.0, 50.0, 6.0]]), WIDTH)
    assert np.array_equal(out, corner)


def test_a_curve_clear_of_crossings_stays_a_curve_and_one_on_a_crossing_joins():
    # a cubic 1.4 px off its chord between two lines: within 1 px of their least-squares
    # line, but not a line on its own (primitives.line_like at 1 px): a rounded corner
    # drawn tight comes back so, and must stay a curve
    curve = np.array([[50, 50], [56, 51.4], [64, 51.4], [70, 50]], float)
    segs = np.stack([line((10, 50), (50, 50)), curve, line((70, 50), (110, 50))])
    assert np.array_equal(straight_runs(segs, np.zeros((0, 3)), WIDTH, tolerance=1.0), segs)
    assert len(straight_runs(segs, CROSSING, WIDTH, tolerance=1.0)) == 1


def test_a_closed_runs_ends_stay_together_and_its_neighbours_follow():
    # a rectangle traced from a point on its top side, the top's other part wobbling
    # through a crossing at (40, 10)
    segs = np.stack([line((80, 10), (100, 10)), line((100, 10), (100, 50)), line((100, 50), (0, 50)),
                     line((0, 50), (0, 10)), line((0, 10), (40, 12)), line((40, 12), (80, 10))])
    out = straight_runs(segs, np.array([[40.0, 10.0, 5.0]]), WIDTH, closed=True)
    assert len(out) == 5
    assert np.allclose(out[-1, -1], out[0, 0])  # still closed
    assert np.abs(out[-1, :, 1] - out[-1, 0, 1]).max() < 0.5  # the run is straight
    assert np.allclose(out[3, -1], out[4, 0]) and np.allclose(out[:4, -1], out[1:, 0])  # joined up

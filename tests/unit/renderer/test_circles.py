"""Circles take a closed form for their closest point (csrc/common/ellipse.h): the same
picture as an ellipse a hair from round, which takes the general bisection."""
from __future__ import annotations

import numpy as np
import pytest

import vecfit


def picture(tmp_path, element: str, mode: str) -> np.ndarray:
    path = tmp_path / "c.svg"
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="96" height="96">{element}</svg>')
    return vecfit.render(vecfit.load_svg(path), 96, 96, samples=4, mode=mode, seed=1).numpy()


@pytest.mark.parametrize("mode", ["mc", "analytic"])
@pytest.mark.parametrize("paint", ['fill="#c33"', 'fill="none" stroke="#139" stroke-width="7"',
                                   'fill="#fc2" stroke="#000" stroke-width="3"'])
def test_a_circle_draws_as_the_ellipse_next_to_it(tmp_path, mode, paint):
    circle = picture(tmp_path, f'<circle cx="47.3" cy="50.1" r="33.7" {paint}/>', mode)
    ellipse = picture(tmp_path, f'<ellipse cx="47.3" cy="50.1" rx="33.7" ry="33.70001" {paint}/>', mode)
    assert circle[..., 3].sum() > 500  # something drawn
    assert np.abs(circle - ellipse).max() < 2e-3

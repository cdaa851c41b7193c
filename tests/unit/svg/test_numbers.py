"""fmt_many: the fast path (NumPy rounding and a table of fractions, up to 4 decimals)
writes exactly what printf writes, ties, signed zeros and huge values included."""
from __future__ import annotations

import numpy as np
import pytest

from vecfit.errors import VecfitError
from vecfit.svg.numbers import _printf_many, fmt, fmt_many

from helpers import slow_unless

VALUES = np.concatenate([
    np.random.default_rng(1).uniform(-1000, 1000, 100_000),
    np.round(np.random.default_rng(2).uniform(-1000, 1000, 20_000), 3),   # many half hundredths: ties
    np.round(np.random.default_rng(3).uniform(-1000, 1000, 20_000), 5),   # ties at 4 decimals
    np.round(np.random.default_rng(4).uniform(-50, 50, 20_000), 2),       # whole hundredths
    np.arange(-2000, 2000) * 0.005,                                       # every half hundredth near 0
    [0.0, -0.0, 1e-9, -1e-9, 0.004999, -0.004999, 0.005, -0.005, 0.015, 2.675, 1.005, 99.995,
     -99.995, 1e9, -1e9, 123456789.125, 1e15, -3e17, 5e-324, 12345678.12345, 1e7 + 5e-5]])


@pytest.mark.parametrize("decimals", slow_unless([0, 1, 2, 3, 4, 6], [0, 3]))
def test_fmt_many_is_printf(decimals):
    got = fmt_many(VALUES, decimals)
    assert got == _printf_many(VALUES, decimals)
    assert "-0" not in got and "0" in got


def test_fmt_many_is_fmt_and_refuses_non_finite():
    assert fmt_many([2.675, -0.004, 1.5, 100.0], 2) == [fmt(v, 2) for v in (2.675, -0.004, 1.5, 100.0)]
    assert fmt_many([2.675, -0.004, 1.5, 100.0], 2) == ["2.67", "0", "1.5", "100"]
    with pytest.raises(VecfitError, match="non-finite"):
        fmt_many([1.0, np.inf], 2)

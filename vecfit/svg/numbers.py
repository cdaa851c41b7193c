"""Numbers and colours as SVG text: compact, and never NaN or infinity (a non-finite value
is an error, not a broken file). Shared by the SVG writer, the tracer and the reports."""
from __future__ import annotations

import functools
import math
import operator

import numpy as np

from vecfit.errors import VecfitError
from vecfit.scene.arrays import is_tensor


def fmt(value, decimals: int = 4) -> str:
    """A finite number, compact: at most ``decimals`` decimals, no trailing zeros."""
    v = float(value)
    if not math.isfinite(v):
        raise VecfitError(f"cannot write a non-finite value ({v}) to SVG")
    s = f"{v:.{decimals}f}"
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s == "-0" or not s else s


def fmt_many(values, decimals: int = 4) -> list[str]:
    """``fmt`` of every number in ``values`` (a trace writes 50,000, a refined dense trace
    150,000: one check of finiteness for all, then the formatting without a call per
    number). Up to FAST_DECIMALS decimals, numbers well away from a rounding tie are
    rounded in NumPy and written as an integer part and a looked-up fraction, 1.4x as
    fast as printf and the same text: v * 10^decimals is within 1e-5 of its exact value
    below FAST_LIMIT, far inside the margin. The others go through printf."""
    a = np.asarray(values, float).ravel()
    if not np.isfinite(a).all():
        fmt(a[~np.isfinite(a)][0])  # raises, naming the value
    if not 0 < decimals <= FAST_DECIMALS:
        return _printf_many(a, decimals)
    scaled = a * 10.0 ** decimals
    k = np.rint(scaled)
    unsure = ~(np.abs(scaled - k) < 0.499) | ~(np.abs(scaled) < FAST_LIMIT)
    units = 10 ** decimals
    whole = np.abs(np.where(unsure, 0, k)).astype(np.int64)
    out = list(map(operator.add, map(str, (whole // units).tolist()),
                   map(_fractions(decimals).__getitem__, (whole % units).tolist())))
    for i in np.flatnonzero(k < 0).tolist():
        out[i] = "-" + out[i]
    where = np.flatnonzero(unsure)
    for i, text in zip(where.tolist(), _printf_many(a[where], decimals)):
        out[i] = text
    return out


FAST_DECIMALS = 4    # fmt_many's table of fractions: 10^4 strings at most
FAST_LIMIT = 1e11    # |v| * 10^decimals below which a float's rounding error stays under 1e-5


@functools.lru_cache(maxsize=None)
def _fractions(decimals: int) -> list[str]:
    """'', '.0001', ..., '.9999' (trailing zeros dropped): the fraction of k / 10^decimals."""
    return [""] + [f".{f:0{decimals}d}".rstrip("0") for f in range(1, 10 ** decimals)]


def _printf_many(a: np.ndarray, decimals: int) -> list[str]:
    """fmt of finite numbers by printf, compact."""
    pattern = f"%.{decimals}f"
    out = [pattern % v for v in a.tolist()]
    if decimals > 0:
        out = [t.rstrip("0").rstrip(".") for t in out]
    return ["0" if t == "-0" or not t else t for t in out]


def hex_color(rgba) -> str:
    r, g, b = (min(max(float(c), 0.0), 1.0) for c in finite(rgba)[:3])
    return "#{:02x}{:02x}{:02x}".format(*(int(round(c * 255)) for c in (r, g, b)))


def matrix(m) -> str:
    a = finite(m)
    return "matrix({})".format(" ".join(fmt(v, 6) for v in
                                        (a[0, 0], a[1, 0], a[0, 1], a[1, 1], a[0, 2], a[1, 2])))


def finite(t) -> np.ndarray:
    a = t.detach().cpu().double().numpy() if is_tensor(t) else np.asarray(t, float)
    if not np.isfinite(a).all():
        raise VecfitError("cannot write non-finite values (NaN or infinity) to SVG")
    return a

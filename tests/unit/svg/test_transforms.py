"""Transform lists: matrix, translate and scale lists are multiplied by the reader itself,
as svgelements multiplies them (so that no scene moves by a bit), and svgelements, a
tenth of `vecfit render`'s imports, reads only the lists with a rotation or a skew."""
from __future__ import annotations

import random
import subprocess
import sys

import numpy as np
import pytest

from vecfit.svg.units import _product, _transform_items, parse_transform

svgelements = pytest.importorskip("svgelements")

NUMBERS = ["0", "-0", "1", "-1", "2.5", ".5", "-.5", "1e3", "1E-3", "+3", "1e308", "-1e308", "0.000001",
           "123456.789", "-0.0", "3.3.3", "1e400", "5.", "5.e3"]


def _svgelements(text):
    """parse_transform as it was: svgelements' matrix of every valid list."""
    if _transform_items(text) is None:
        return None
    try:
        m = svgelements.Matrix(text)
    except Exception:  # (svgelements' assorted errors on lists it cannot read: no transform)
        return None
    out = np.array([[m.a, m.c, m.e], [m.b, m.d, m.f], [0.0, 0.0, 1.0]])
    return out if np.isfinite(out).all() else None


def _lists(count: int) -> list[str]:
    rng = random.Random(7)
    out = []
    for _ in range(count):
        items = []
        for _ in range(rng.randint(1, 4)):
            name = rng.choice(["matrix", "translate", "scale", "scale", "translate", "rotate", "skewX"])
            n = rng.choice({"matrix": (6,), "translate": (1, 2), "scale": (1, 2), "rotate": (1, 3),
                            "skewX": (1,)}[name])
            args = [rng.choice(NUMBERS) if rng.random() < 0.3 else repr(rng.uniform(-1e3, 1e3)) for _ in range(n)]
            items.append(f"{name}(" + rng.choice([",", " ", ", "]).join(args) + ")")
        out.append(rng.choice([" ", ",", ""]).join(items))
    return out


def test_lists_read_as_svgelements_reads_them_to_the_bit():
    texts = _lists(3000) + ["scale(1,-1) translate(0,-510) ", "matrix(-0 0 0 -0 -0 0)", "translate(5.e3)",
                            "scale(1e200) scale(1e200)", "rotate(30 5 5) scale(2)"]
    fast = 0
    for text in texts:
        ours, theirs = parse_transform(text), _svgelements(text)
        assert (ours is None) == (theirs is None), text
        if ours is not None:
            assert ours.tobytes() == theirs.tobytes(), text  # (-0.0 and 0.0 told apart)
        fast += _product(_transform_items(text) or []) is not None and _transform_items(text) is not None
    assert fast > 1000  # most of them multiplied here, not by svgelements


def test_rotations_and_skews_and_other_spellings_are_svgelements():
    assert _product(_transform_items("rotate(30)")) is None
    assert _product(_transform_items("translate(1) skewX(5)")) is None
    assert _product(_transform_items("translate(5.e3)")) is None  # (svgelements reads 5 and 3)
    assert _product(_transform_items("scale(1,-1) translate(0,-510)")) == (1.0, 0.0, 0.0, -1.0, 0.0, 510.0)


def test_reading_tiger_imports_no_svgelements():
    code = ("import sys, vecfit\nfrom vecfit.scene.arrays import numpy_arrays\n"
            "with numpy_arrays():\n    s = vecfit.load_svg('examples/tiger.svg')\n"
            "print(len(s.shapes), 'svgelements' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.split() == ["303", "False"], out.stdout + out.stderr

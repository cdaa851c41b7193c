"""A Scene read into NumPy arrays (vecfit.scene.arrays, what `vecfit info` reads) holds the
same values as one read into tensors, and is summarised alike."""
from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest
import torch

from vecfit.scene.arrays import numpy_arrays
from vecfit.scene.summary import summarize
from vecfit.svg.read import load_svg

ROOT = Path(__file__).resolve().parents[3]
SVGS = sorted((ROOT / "tests" / "oracles" / "golden").glob("*.svg")) + [ROOT / "examples" / "tiger.svg"]
DASHED = ('<svg xmlns="http://www.w3.org/2000/svg" width="50" height="40">'
          '<rect x="5" y="5" width="30" height="20" stroke="black" stroke-dasharray="3 2"/>'
          '<path d="M0 30 C10 20 30 40 50 30" stroke="red" stroke-dasharray="1e-6" fill="none"/>'
          '<g transform="matrix(0 0 0 0 1 1)"><circle r="3"/></g></svg>')


def _read(path, numpy: bool):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if numpy:
            with numpy_arrays():
                return load_svg(path)
        return load_svg(path)


def _floats(value, out: list) -> list:
    """Every float array or tensor in a Scene, in order, as float64 NumPy arrays."""
    if isinstance(value, torch.Tensor):
        out.append(value.detach().double().numpy())
    elif isinstance(value, np.ndarray) and value.dtype == np.float32:
        out.append(value.astype(np.float64))
    elif isinstance(value, (list, tuple)):
        for v in value:
            _floats(v, out)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            _floats(getattr(value, f.name), out)
    return out


@pytest.mark.parametrize("path", SVGS + ["dashed"], ids=lambda p: getattr(p, "name", p))
def test_numpy_reading_equals_tensor_reading(path, tmp_path):
    if path == "dashed":  # dashes counted against the limit; a singular group transform
        path = tmp_path / "dashed.svg"
        path.write_text(DASHED)
    tensors, arrays = _read(path, numpy=False), _read(path, numpy=True)
    a, b = _floats(tensors, []), _floats(arrays, [])
    assert len(a) == len(b) > 0
    assert all(x.shape == y.shape and np.array_equal(x, y) for x, y in zip(a, b))
    assert not any(isinstance(v, torch.Tensor) for v in _tensors(arrays))
    assert summarize(arrays) == summarize(tensors)


def _tensors(value):
    if isinstance(value, (list, tuple)):
        for v in value:
            yield from _tensors(v)
    elif dataclasses.is_dataclass(value) and not isinstance(value, type):
        for f in dataclasses.fields(value):
            yield from _tensors(getattr(value, f.name))
    else:
        yield value

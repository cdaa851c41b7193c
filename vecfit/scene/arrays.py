"""Where the Scene's floats are made: torch tensors, or NumPy arrays for a reading that
only looks at the Scene.

Importing torch takes over a second, more than `vecfit info` needs for the whole file.
So the Scene's floats are made here, by functions that give float32 torch tensors
(torch imported on the first one) unless the caller asked for NumPy with
``numpy_arrays()``: then they give float32 NumPy arrays of the same values, and nothing
imports torch. A Scene of NumPy arrays is for counting and reading values (vecfit info);
the renderer, the writer and the optimiser take Scenes of tensors.
"""
from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import sys

import numpy as np

_NUMPY = contextvars.ContextVar("vecfit_numpy_arrays", default=False)


@contextlib.contextmanager
def numpy_arrays():
    """Within this block, Scenes are made of float32 NumPy arrays instead of tensors."""
    token = _NUMPY.set(True)
    try:
        yield
    finally:
        _NUMPY.reset(token)


def making_numpy() -> bool:
    return _NUMPY.get()


def floats(values):
    """A float32 copy of ``values`` (numbers, nested lists, arrays or tensors)."""
    if _NUMPY.get():
        return np.array(to_numpy(values), dtype=np.float32)
    import torch
    return torch.as_tensor(values, dtype=torch.float32).clone()


def scalar(value: float):
    """A float32 0-d tensor (or array) holding ``value``."""
    return floats(float(value))


def zeros(n: int):
    return floats(np.zeros(n))


_EYE32 = np.eye(3, dtype=np.float32)


def identity():
    """The 3x3 identity matrix."""
    if _NUMPY.get():
        return _EYE32.copy()  # (the reader makes one per shape)
    return floats(np.eye(3))


def is_tensor(value) -> bool:
    """Whether ``value`` is a torch tensor (without importing torch: none exists before)."""
    torch = sys.modules.get("torch")
    return torch is not None and isinstance(value, torch.Tensor)


def to_numpy(value):
    """A tensor's values as a NumPy array (detached, on the CPU); anything else as it is."""
    if is_tensor(value):
        return value.detach().cpu().numpy()
    return value


def as_torch(geometry):
    """A geometry (a dataclass of arrays) with its NumPy arrays made tensors, for the
    code that computes with it in torch."""
    changes = {f.name: floats_torch(v) for f in dataclasses.fields(geometry)
               if isinstance((v := getattr(geometry, f.name)), np.ndarray) and v.dtype == np.float32}
    return dataclasses.replace(geometry, **changes) if changes else geometry


def floats_torch(values):
    import torch
    return torch.as_tensor(np.asarray(values), dtype=torch.float32).clone()

"""The few array operations that placement, geometry and packing use, on either kind of
Scene array: torch tensors (differentiable, for the renderer's autograd) or the float32
NumPy arrays of ``arrays.numpy_arrays()`` (a render that needs no torch, e.g. a trace
written as it is). One code path works on both: it asks ``ops_for(array)`` for the
operations of that array's kind. Both follow torch's float32 arithmetic.
"""
from __future__ import annotations

import numpy as np

from .arrays import is_tensor


class NumpyOps:
    """torch's operations, as the packing code calls them, on float32 NumPy arrays."""

    @staticmethod
    def f32(a):
        return np.asarray(a, dtype=np.float32)

    @staticmethod
    def index(values):
        return np.asarray(values, dtype=np.int64)

    @staticmethod
    def zeros(shape):
        return np.zeros(shape, dtype=np.float32)

    @staticmethod
    def full(shape, fill):
        return np.full(shape, fill, dtype=np.float32)

    @staticmethod
    def eye(n, m=None):
        return np.eye(n, m, dtype=np.float32)

    cat = staticmethod(lambda arrays, dim=0: np.concatenate(arrays, axis=dim))
    stack = staticmethod(lambda arrays, dim=0: np.stack(arrays, axis=dim))
    diag = staticmethod(np.diag)
    einsum = staticmethod(np.einsum)
    sqrt = staticmethod(np.sqrt)
    abs = staticmethod(np.abs)
    where = staticmethod(np.where)
    det = staticmethod(np.linalg.det)
    inv = staticmethod(np.linalg.inv)

    @staticmethod
    def expand(a, *shape):
        return np.broadcast_to(a, shape)

    @staticmethod
    def prod(a, dim):
        return np.prod(a, axis=dim, dtype=np.float32)

    @staticmethod
    def put_rows(a, rows, values):
        out = a.copy()
        out[rows] = values
        return out

    @staticmethod
    def numpy(a):
        return a

    @staticmethod
    def from_numpy(a):
        return a


class TorchOps:
    """The same operations on torch tensors (differentiable where torch's are)."""

    def __init__(self):
        import torch
        self.torch = torch
        self.cat, self.stack, self.diag, self.einsum = torch.cat, torch.stack, torch.diag, torch.einsum
        self.sqrt, self.abs, self.where = torch.sqrt, torch.abs, torch.where
        self.det, self.inv, self.from_numpy = torch.linalg.det, torch.linalg.inv, torch.from_numpy

    def f32(self, a):
        return a.float() if is_tensor(a) else self.torch.as_tensor(a, dtype=self.torch.float32)

    def index(self, values):
        return self.torch.as_tensor(values, dtype=self.torch.int64)

    def zeros(self, shape):
        return self.torch.zeros(shape)

    def full(self, shape, fill):
        return self.torch.full(shape, fill)

    def eye(self, n, m=None):
        return self.torch.eye(n, n if m is None else m)

    @staticmethod
    def expand(a, *shape):
        return a.expand(*shape)

    @staticmethod
    def prod(a, dim):
        return a.prod(dim=dim)

    @staticmethod
    def put_rows(a, rows, values):
        return a.index_put((rows,), values)

    @staticmethod
    def numpy(a):
        return a.detach().numpy()


_NUMPY_OPS = NumpyOps()
_torch_ops = None


def ops_for(array):
    """The operations of ``array``'s kind (a torch tensor's, else NumPy's)."""
    global _torch_ops
    if not is_tensor(array):
        return _NUMPY_OPS
    if _torch_ops is None:
        _torch_ops = TorchOps()
    return _torch_ops

"""Where pydiffvg renders: diffvg's device switches.

``set_use_gpu(True)`` shades on a GPU when vecfit's core was built with CUDA and one is
present (otherwise it renders on the CPU, as a CPU-only vecfit must). ``get_device()`` is
the torch device that callers put their tensors on: CUDA only where torch itself has it.
"""
from __future__ import annotations

import torch

from vecfit.renderer.device import cuda_device_count, has_cuda

_use_gpu = False
_device = torch.device("cpu")


def set_use_gpu(use: bool) -> None:
    global _use_gpu, _device
    _use_gpu = bool(use)
    _device = torch.device("cuda") if _use_gpu and torch.cuda.is_available() else torch.device("cpu")


def get_use_gpu() -> bool:
    return _use_gpu


def set_device(device) -> None:
    global _use_gpu, _device
    _device = torch.device(device)
    _use_gpu = _device.type == "cuda"


def get_device() -> torch.device:
    return _device


def render_device() -> str:
    """The device vecfit.render is asked for: a GPU when one is wanted and can be had."""
    if _use_gpu and has_cuda() and cuda_device_count() > 0:
        return f"cuda:{_device.index}" if _device.type == "cuda" and _device.index is not None else "cuda"
    return "cpu"

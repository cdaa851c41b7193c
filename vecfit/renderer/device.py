"""Which device renders: the CPU, or a CUDA GPU when the core was built with VECFIT_CUDA=1.

The core prepares and bins the scene on the host either way; on a GPU the per-pixel work
runs there (the same functions as on the CPU, compiled for both).
"""
from __future__ import annotations

import sys

from vecfit import _core
from vecfit.errors import VecfitError

CHOICES = ("auto", "cpu", "cuda")
CPU = -1  # the core's device index for "no GPU"


def has_cuda() -> bool:
    """Whether this build of the core has the CUDA kernels."""
    return bool(_core.has_cuda())


def cuda_device_count() -> int:
    """CUDA devices the core can use now (0 when it was built without CUDA)."""
    return int(_core.cuda_device_count())


def resolve(device) -> int:
    """The core's device index for `device`: "auto" (the first GPU if there is one), "cpu",
    "cuda", "cuda:N" or a torch.device. Raises VecfitError when a GPU is asked for and
    cannot be had."""
    torch = sys.modules.get("torch")  # (a torch.device exists only once torch is imported:
    if torch is not None and isinstance(device, torch.device):  # --version needs no torch)
        device = str(device)
    if not isinstance(device, str):
        raise VecfitError(f"device must be one of {', '.join(CHOICES)} or cuda:N, not {device!r}")
    if device == "cpu":
        return CPU
    if device == "auto":
        return 0 if has_cuda() and cuda_device_count() > 0 else CPU
    kind, _, index = device.partition(":")
    if kind != "cuda" or (index and not index.isdigit()):
        raise VecfitError(f"device must be one of {', '.join(CHOICES)} or cuda:N, not {device!r}")
    if not has_cuda():
        raise VecfitError("this vecfit was built without CUDA: reinstall it with VECFIT_CUDA=1 "
                          "(needs nvcc), or use --device cpu")
    n, count = int(index or 0), cuda_device_count()
    if n >= count:
        raise VecfitError(f"no CUDA device {n}: this machine has {count}")
    return n


def device_name(index: int) -> str:
    return "cpu" if index == CPU else f"cuda:{index}"


def core_build() -> str:
    """The compiled core in a few words, e.g. "CPU, gcc 12.2.0" or "CPU + CUDA 80-real
    90-real, gcc 12.2.0" (`vecfit --version`)."""
    info = _core.build_info()
    kinds = f"CPU + CUDA {info['cuda_archs']}" if info["cuda_archs"] else "CPU"
    return f"{kinds}, {info['compiler']}"


def build_summary() -> str:
    """What this build of the core has, one fact a line (`vecfit info --build`)."""
    from vecfit import __version__
    info = _core.build_info()
    return "\n".join([
        f"vecfit {__version__}",
        f"core compiled by: {info['compiler']}",
        f"CPU threads: {info['hardware_threads']}",
        info["cuda"],
        f"device auto resolves to: {device_name(resolve('auto'))}",
        "clip paths, masks, filters, blend modes: each layer's passes on the chosen device; "
        "layers composited, filtered and blended on the CPU (torch)",
    ])

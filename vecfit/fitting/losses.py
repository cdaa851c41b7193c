"""Image losses for optimisation: images are [H, W, C] float tensors in [0, 1]."""
from __future__ import annotations

import torch
import torch.nn.functional as F

from vecfit.errors import VecfitError

from .settings import LOSSES  # noqa: F401  (the names, known without torch)


def l2(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    return F.mse_loss(a, b)  # (one fused pass each way, where (a - b) ** 2 and its mean took four)


def l1(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    return torch.mean(torch.abs(a - b))


def _gaussian_window(size: int = 11, sigma: float = 1.5) -> torch.Tensor:
    x = torch.arange(size, dtype=torch.float32) - (size - 1) / 2
    g = torch.exp(-x ** 2 / (2 * sigma ** 2))
    return g / g.sum()


def _blur(x: torch.Tensor, window: torch.Tensor) -> torch.Tensor:
    """Separable Gaussian blur of [1, C, H, W] per channel, valid region only."""
    c = x.shape[1]
    k = window.to(x.dtype)
    x = F.conv2d(x, k.view(1, 1, 1, -1).expand(c, 1, 1, -1), groups=c)
    return F.conv2d(x, k.view(1, 1, -1, 1).expand(c, 1, -1, 1), groups=c)


def ssim(a: torch.Tensor, b: torch.Tensor) -> torch.Tensor:
    """Mean SSIM (Wang et al. 2004: 11-tap Gaussian window, sigma 1.5, K1 0.01, K2 0.03,
    data range 1), as scikit-image computes it with gaussian_weights=True."""
    window = _gaussian_window()
    if min(a.shape[0], a.shape[1]) < window.numel():
        raise VecfitError("the SSIM loss needs images of at least 11 x 11 pixels")
    x = a.permute(2, 0, 1)[None]
    y = b.permute(2, 0, 1)[None]
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    mx, my = _blur(x, window), _blur(y, window)
    # scikit-image uses the unbiased (sample) covariance: N / (N - 1) over the window
    n = window.numel() ** 2
    cov = n / (n - 1)
    sxx = cov * (_blur(x * x, window) - mx * mx)
    syy = cov * (_blur(y * y, window) - my * my)
    sxy = cov * (_blur(x * y, window) - mx * my)
    s = ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    return s.mean()


def ssim_loss(a, b):
    return 1 - ssim(a, b)


def pyramid(a: torch.Tensor, b: torch.Tensor, levels: int = 4) -> torch.Tensor:
    """L2 summed over a Gaussian-ish image pyramid (2x2 average pooling): coarse levels
    give strokes far from where they belong a signal to move."""
    x = a.permute(2, 0, 1)[None]
    y = b.permute(2, 0, 1)[None]
    total = torch.mean((x - y) ** 2)
    for _ in range(levels - 1):
        if min(x.shape[-2:]) < 2:
            break
        x, y = F.avg_pool2d(x, 2), F.avg_pool2d(y, 2)
        total = total + torch.mean((x - y) ** 2)
    return total


def weighted_l2(a: torch.Tensor, b: torch.Tensor, weight: torch.Tensor) -> torch.Tensor:
    """L2 with a per-pixel weight ([H, W]): the mean of weight x squared difference."""
    return torch.mean(weight[..., None] * (a - b) ** 2)


def weighted_l1(a: torch.Tensor, b: torch.Tensor, weight: torch.Tensor) -> torch.Tensor:
    return torch.mean(weight[..., None] * torch.abs(a - b))


def weighted_pyramid(a: torch.Tensor, b: torch.Tensor, weight: torch.Tensor, levels: int = 4) -> torch.Tensor:
    """``pyramid`` with a per-pixel weight, pooled with the images level by level."""
    x = a.permute(2, 0, 1)[None]
    y = b.permute(2, 0, 1)[None]
    w = weight[None, None]
    total = torch.mean(w * (x - y) ** 2)
    for _ in range(levels - 1):
        if min(x.shape[-2:]) < 2:
            break
        x, y, w = F.avg_pool2d(x, 2), F.avg_pool2d(y, 2), F.avg_pool2d(w, 2)
        total = total + torch.mean(w * (x - y) ** 2)
    return total


# The losses by name: names.LOSSES, which the configs and the command line offer
# (tests/unit/test_names.py holds the two together), and those that take a per-pixel weight.
FUNCTIONS = {"l2": l2, "l1": l1, "ssim": ssim_loss, "pyramid": pyramid}
WEIGHTED = {"l2": weighted_l2, "l1": weighted_l1, "pyramid": weighted_pyramid}


def weighted(name: str):
    """The loss ``name`` with a per-pixel weight: l2, l1 and pyramid (a weight has no
    plain meaning for SSIM's windows)."""
    if name not in WEIGHTED:
        get(name)  # an unknown name is refused as such
        *most, last = WEIGHTED
        raise VecfitError(f"loss {name!r} takes no per-pixel weight; use {', '.join(most)} or {last}")
    return WEIGHTED[name]


def get(name: str):
    if name not in FUNCTIONS:
        raise VecfitError(f"loss must be one of {', '.join(LOSSES)}, not {name!r}")
    return FUNCTIONS[name]

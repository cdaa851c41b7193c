"""Straight RGBA over a background, the one formula for NumPy arrays and torch tensors:
RGB over an opaque background (its alpha ignored); without one (None), premultiplied
RGBA, which is what a transparent picture shows. (The core composites its renders over
a background in the same arithmetic.)"""
from __future__ import annotations

import numpy as np


def composite(rgba: np.ndarray, background) -> np.ndarray:
    """[H, W, 4] straight RGBA -> [H, W, 3] over ``background``, or [H, W, 4] premultiplied."""
    a = rgba[..., 3:]
    if background is not None:
        return rgba[..., :3] * a + np.asarray(background[:3], dtype=rgba.dtype) * (1 - a)
    return np.concatenate([rgba[..., :3] * a, a], axis=-1)


def composite_torch(rgba: torch.Tensor, background) -> torch.Tensor:
    """``composite`` for tensors (differentiable)."""
    import torch
    a = rgba[..., 3:]
    if background is not None:
        return rgba[..., :3] * a + torch.tensor(background[:3], dtype=rgba.dtype) * (1 - a)
    return torch.cat([rgba[..., :3] * a, a], dim=-1)

"""Adam over flat parameter kinds: each kind (points, colours, ...) aliases the Scene's
tensors into one flat leaf tensor, so a step, the bounds, the NaN checks and the
best-so-far snapshot are a few vector operations per kind however many shapes there are."""
from __future__ import annotations

import math

import torch


class ParameterKind:
    """One parameter kind: the Scene's tensors as views of one flat leaf tensor."""

    def __init__(self, name: str, tensors: list, scales: list, lr: float):
        self.name, self.lr = name, lr
        self.tensors = tensors
        self.flat = torch.cat([t.detach().reshape(-1).float() for t in tensors]).contiguous()
        self.scale = torch.cat([torch.full((t.numel(),), s, dtype=torch.float32)
                                for t, s in zip(tensors, scales)])
        self.offsets: dict[int, int] = {}  # id(tensor) -> its first element in flat
        offset = 0
        for t in tensors:
            n = t.numel()
            self.offsets[id(t)] = offset
            t.data = self.flat[offset:offset + n].view(t.shape)  # alias: steps update the Scene
            t.requires_grad_(True)
            t.grad = None
            offset += n
        self.m = torch.zeros_like(self.flat)
        self.v = torch.zeros_like(self.flat)
        self.steps = torch.zeros_like(self.flat)

    def gradient(self, leaf: torch.Tensor | None = None) -> torch.Tensor:
        """The kind's gradient: that of ``leaf`` (the flat tensor as a leaf, when the
        renderer read the values from it) plus those of the Scene's tensors."""
        out = leaf.grad if leaf is not None and leaf.grad is not None else None
        if any(t.grad is not None for t in self.tensors):
            own = torch.cat([(t.grad if t.grad is not None else torch.zeros_like(t)).reshape(-1)
                             for t in self.tensors])
            out = own if out is None else out + own
        return out if out is not None else torch.zeros_like(self.flat)

    def zero_grad(self) -> None:
        for t in self.tensors:
            t.grad = None

    def release(self) -> None:
        for t in self.tensors:
            t.requires_grad_(False)
            t.grad = None

    def project(self) -> None:
        """Keep values where they mean something: colours and opacities in [0, 1], widths
        and radii >= 0, stop offsets in [0, 1] and non-decreasing."""
        f = self.flat
        if self.name in ("colors", "opacities"):
            f.clamp_(0.0, 1.0)
        elif self.name in ("stroke_widths", "radii", "gradient_radii"):
            f.clamp_(min=0.0)
        elif self.name == "stop_offsets":
            f.clamp_(0.0, 1.0)
            for t in self.tensors:
                if t.numel() > 1:
                    t.data.copy_(torch.cummax(t.data.reshape(-1), 0).values.view(t.shape))


class Adam:
    """Adam (Kingma & Ba) over the flat kinds, with a per-element scale of the learning
    rate (lengths in each tensor's own units) and a cosine fall of the rates."""

    def __init__(self, kinds: list[ParameterKind], iterations: int, decay: float, warmup: int = 0,
                 betas=(0.9, 0.999), eps: float = 1e-8):
        self.kinds, self.iterations, self.decay, self.warmup = kinds, max(iterations, 1), decay, warmup
        self.b1, self.b2, self.eps = betas[0], betas[1], eps
        self.t = 0
        self.rate = 1.0  # lowered after a step that produced non-finite values

    def factor(self) -> float:
        """Linear warm-up, then a cosine fall to ``decay``. The warm-up matters: Adam's
        first steps move every coordinate by the full rate whatever its gradient, which
        throws a good initial trace out of place before the moments have settled."""
        frac = min(self.t / self.iterations, 1.0)
        warm = min(1.0, (self.t + 1) / self.warmup) if self.warmup > 0 else 1.0
        return self.rate * warm * (self.decay + (1 - self.decay) * 0.5 * (1 + math.cos(math.pi * frac)))

    def step(self, grads: list[torch.Tensor]) -> None:
        factor = self.factor()
        self.t += 1
        for kind, g in zip(self.kinds, grads):
            kind.steps += 1  # per element: a re-seeded element starts its bias correction anew
            c1, c2 = 1 - self.b1 ** kind.steps, 1 - self.b2 ** kind.steps
            kind.m.mul_(self.b1).add_(g, alpha=1 - self.b1)
            kind.v.mul_(self.b2).addcmul_(g, g, value=1 - self.b2)
            step = (kind.m / c1) / (torch.sqrt(kind.v / c2) + self.eps)
            kind.flat.sub_(step * kind.scale, alpha=kind.lr * factor)
            kind.project()

"""Fit a Scene to a target image: Adam with one learning rate per parameter kind.

This is the loop that `vecfit refine`, `vecfit trace` and `vecfit paint` share; they
differ only in where the initial Scene comes from.

Each parameter kind's tensors are aliased into one flat tensor (the Scene's tensors
become views of its storage), so the Adam step, the bounds, the NaN checks and the
best-so-far snapshot are a few vector operations per kind however many shapes there are.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, fields
from typing import Callable, Optional

import torch

from . import device as devices
from . import losses
from .errors import NonFiniteScene, VecfitError
from .pack import local_bbox_size, shape_pixel_scales
from .render import MODES, render
from .scene import LinearGradient, RadialGradient, Scene

KINDS = ("points", "colors", "stroke_widths", "opacities", "radii", "gradient_points",
         "gradient_radii", "stop_offsets", "transforms")
# Kinds measured in lengths: their learning rates are given in pixels of the optimised
# image and converted into each tensor's own units.
LENGTH_KINDS = ("points", "stroke_widths", "radii", "gradient_points", "gradient_radii")


def _default_rates() -> dict:
    return {"points": 2.0, "colors": 0.02, "stroke_widths": 0.1, "opacities": 0.0, "radii": 1.0,
            "gradient_points": 2.0, "gradient_radii": 1.0, "stop_offsets": 0.005, "transforms": 0.0}


@dataclass
class Settings:
    """The loop's settings. The defaults are those of configs/refine.toml's [optimize]
    table (a test holds them equal), so the Python API and the CLI start alike."""
    iterations: int = 250
    loss: str = "l2"
    mode: str = "mc"
    samples: int = 2
    boundary_samples: float = 2.0
    seed: int = 0
    threads: int = 0
    device: str = "auto"
    lr_decay: float = 0.1
    lr_warmup: int = 20
    fixed_alpha: bool = False
    lr: dict = field(default_factory=_default_rates)

    @classmethod
    def from_config(cls, table: dict) -> "Settings":
        """From the [optimize] table; its other keys (max_size, background, ...) belong
        to the job around the loop."""
        names = {f.name for f in fields(cls)}
        s = cls(**{k: v for k, v in table.items() if k in names and k != "lr"},
                lr=dict(table.get("lr", {})))
        s.check()
        return s

    def check(self) -> None:
        if self.iterations < 0:
            raise VecfitError("iterations must be 0 or more")
        losses.get(self.loss)
        if self.mode not in MODES:
            raise VecfitError(f"mode must be one of {', '.join(MODES)}, not {self.mode!r}")
        if self.samples < 1:
            raise VecfitError("samples must be at least 1")
        if not 0 < self.lr_decay <= 1:
            raise VecfitError("lr_decay must be in (0, 1]")
        if self.lr_warmup < 0:
            raise VecfitError("lr_warmup must be 0 or more")
        devices.resolve(self.device)
        for kind, value in self.lr.items():
            if kind not in KINDS:
                raise VecfitError(f"unknown parameter kind {kind!r} (known: {', '.join(KINDS)})")
            if not (math.isfinite(value) and value >= 0):
                raise VecfitError(f"learning rate of {kind} must be a number >= 0, not {value}")


@dataclass
class Target:
    """What the render is compared with: [H, W, 4] straight RGBA in [0, 1] at the size
    rendered, and the background to render over (None when the target is transparent)."""
    image: torch.Tensor
    background: Optional[tuple] = None

    @property
    def opaque(self) -> bool:
        return self.background is not None

    def compared(self, rgba: torch.Tensor) -> torch.Tensor:
        """The channels the loss sees: RGB over the opaque background (a render is already
        over it; a target with transparent parts is put over it here), else premultiplied
        RGBA."""
        alpha = rgba[..., 3:]
        if self.opaque:
            bg = torch.tensor(self.background[:3], dtype=rgba.dtype)
            return rgba[..., :3] * alpha + bg * (1 - alpha)
        return torch.cat([rgba[..., :3] * alpha, alpha], dim=-1)


@dataclass
class Progress:
    iteration: int
    iterations: int
    loss: float
    best_loss: float
    seconds: float


@dataclass
class Step:
    """What an iteration hook sees after an Adam step: the image rendered for this
    iteration's loss (detached, [H, W, 4] at the optimised size), the Scene (already
    stepped), and ``reset(tensor)``, which clears Adam's memory of a tensor that the hook
    re-initialised. Hooks change the Scene's tensors in place, under no_grad."""
    iteration: int
    image: torch.Tensor
    scene: Scene
    target: "Target"
    reset: Callable[[torch.Tensor], None]


@dataclass
class Result:
    losses: list            # loss of each iteration (before its step)
    best_loss: float
    iterations: int         # steps taken
    seconds: float
    interrupted: bool = False
    skipped_steps: int = 0  # steps refused for a non-finite loss, gradient or parameter
    parameters: dict = field(default_factory=dict)  # kind -> number of floats optimised


class _Kind:
    """One parameter kind: the Scene's tensors as views of one flat leaf tensor."""

    def __init__(self, name: str, tensors: list, scales: list, lr: float):
        self.name, self.lr = name, lr
        self.tensors = tensors
        self.flat = torch.cat([t.detach().reshape(-1).float() for t in tensors]).contiguous()
        self.scale = torch.cat([torch.full((t.numel(),), s, dtype=torch.float32)
                                for t, s in zip(tensors, scales)])
        offset = 0
        for t in tensors:
            n = t.numel()
            t.data = self.flat[offset:offset + n].view(t.shape)  # alias: steps update the Scene
            t.requires_grad_(True)
            t.grad = None
            offset += n
        self.m = torch.zeros_like(self.flat)
        self.v = torch.zeros_like(self.flat)
        self.steps = torch.zeros_like(self.flat)

    def gradient(self) -> torch.Tensor:
        return torch.cat([(t.grad if t.grad is not None else torch.zeros_like(t)).reshape(-1)
                          for t in self.tensors])

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

    def __init__(self, kinds: list[_Kind], iterations: int, decay: float, warmup: int = 0,
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


def _learning_rate_scales(scene: Scene, width: int, height: int) -> dict[int, float]:
    """Units of each length tensor per pixel of the rendered image, keyed by id(tensor)."""
    pixels_per_unit = shape_pixel_scales(scene, width, height)
    out: dict[int, float] = {}

    def put(t, ppu):
        if t is not None and id(t) not in out and ppu > 0 and math.isfinite(ppu):
            out[id(t)] = 1.0 / ppu

    for shape, ppu in zip(scene.shapes, pixels_per_unit):
        g = shape.geometry
        for name in ("points", "widths", "center", "radius", "radii", "p_min", "p_max", "corner_radii"):
            put(getattr(g, name, None), ppu)
        put(shape.stroke_width, ppu)
        for paint in (shape.fill, shape.stroke):
            if isinstance(paint, (LinearGradient, RadialGradient)):
                gppu = ppu * math.sqrt(abs(float(torch.linalg.det(paint.transform[:2, :2].double()))))
                if paint.units == "objectBoundingBox":
                    gppu *= local_bbox_size(g) or 0.0
                for name in ("start", "end", "center", "focal", "radius"):
                    put(getattr(paint, name, None), gppu)
    return out


def _kinds(scene: Scene, lr: dict, width: int, height: int, fixed_alpha: bool = False,
           keep_alpha=()) -> list[_Kind]:
    scales = _learning_rate_scales(scene, width, height)
    kinds = []
    for name, tensors in scene.parameters().items():
        rate = float(lr.get(name, 0.0))
        if rate <= 0 or not tensors:
            continue
        per_tensor = []
        for t in tensors:
            if name in LENGTH_KINDS:
                per_tensor.append(scales.get(id(t), 1.0))
            else:
                per_tensor.append(1.0)
        kind = _Kind(name, tensors, per_tensor, rate)
        if name == "transforms":  # the last row of an affine matrix stays 0 0 1
            kind.scale.view(-1, 3, 3)[:, 2, :] = 0.0
        if name == "colors":  # colours are RGBA rows: keep the A of all, or of some
            if fixed_alpha:
                kind.scale.view(-1, 4)[:, 3] = 0.0
            kept = {id(t) for t in keep_alpha}
            offset = 0
            for t in tensors:
                if id(t) in kept:
                    kind.scale[offset:offset + t.numel()].view(-1, 4)[:, 3] = 0.0
                offset += t.numel()
        kinds.append(kind)
    return kinds


def optimize(scene: Scene, target: Target, settings: Settings,
             progress: Callable[[Progress], None] | None = None,
             hooks: tuple[Callable[[Step], None], ...] = (), keep_alpha=()) -> Result:
    """Fit ``scene`` to ``target`` in place; returns the loss curve and counts. The Scene
    ends at the best parameters seen. Ctrl-C stops early (``Result.interrupted``).
    ``hooks`` run after every iteration (see Step): re-seeding, saving frames.
    ``keep_alpha``: colour tensors whose alpha must not change (e.g. a backdrop that
    has to keep the canvas covered)."""
    settings.check()
    loss_fn = losses.get(settings.loss)
    height, width = target.image.shape[:2]
    goal = target.compared(target.image.float())
    device = devices.describe(devices.resolve(settings.device))  # "auto" settled once
    kinds = _kinds(scene, settings.lr, width, height, settings.fixed_alpha, keep_alpha)
    if not kinds:
        raise VecfitError("nothing to optimise: the scene has no parameters with a learning rate above 0")
    adam = Adam(kinds, settings.iterations, settings.lr_decay, settings.lr_warmup)
    best = [k.flat.clone() for k in kinds]
    best_loss = math.inf
    curve: list[float] = []
    skipped = 0
    interrupted = False
    start = time.perf_counter()

    frame = {}

    def evaluate(iteration: int, grad: bool):
        with torch.set_grad_enabled(grad):
            image = render(scene, width, height, samples=settings.samples, mode=settings.mode,
                           seed=settings.seed + iteration, background=target.background,
                           threads=settings.threads, boundary_samples=settings.boundary_samples,
                           device=device)
            frame["image"] = image.detach()
            return loss_fn(target.compared(image), goal)

    where = {}
    for i, k in enumerate(kinds):
        offset = 0
        for t in k.tensors:
            where[id(t)] = (i, offset, t.numel())
            offset += t.numel()

    def reset(tensor: torch.Tensor) -> None:
        if id(tensor) in where:
            i, offset, n = where[id(tensor)]
            for state in (kinds[i].m, kinds[i].v, kinds[i].steps):
                state[offset:offset + n] = 0

    def restore_best():
        for k, b in zip(kinds, best):
            k.flat.copy_(b)

    try:
        for it in range(settings.iterations):
            try:
                loss = evaluate(it, grad=True)
            except NonFiniteScene:
                loss = None  # treated like a NaN loss
            value = float(loss.detach()) if loss is not None else math.nan
            curve.append(value)
            grads = None
            if math.isfinite(value):
                if value < best_loss:
                    best_loss = value
                    for b, k in zip(best, kinds):
                        b.copy_(k.flat)
                if loss.requires_grad:
                    loss.backward()
                # else nothing drawn depends on the parameters any more (e.g. every shape
                # shrank to nothing): zero gradients, Adam's momentum still moves them
                grads = [k.gradient() for k in kinds]
                if not all(torch.isfinite(g).all() for g in grads):
                    grads = None
            for k in kinds:
                k.zero_grad()
            if grads is None:
                # A non-finite loss or gradient: go back to the best parameters and try
                # again with smaller steps rather than let NaN into the Scene.
                skipped += 1
                restore_best()
                adam.rate *= 0.5
                if adam.rate < 1e-4:
                    break
            else:
                with torch.no_grad():
                    adam.step(grads)
                if not all(torch.isfinite(k.flat).all() for k in kinds):
                    skipped += 1
                    restore_best()
                    adam.rate *= 0.5
            if hooks and "image" in frame:
                with torch.no_grad():
                    for hook in hooks:
                        hook(Step(it, frame["image"], scene, target, reset))
                    for k in kinds:
                        k.project()
            if progress is not None:
                progress(Progress(it + 1, settings.iterations, value, best_loss,
                                  time.perf_counter() - start))
        # The last step's result has not been measured yet.
        if settings.iterations > 0:
            final = evaluate(settings.iterations, grad=False)
            value = float(final)
            if math.isfinite(value) and value < best_loss:
                best_loss = value
                for b, k in zip(best, kinds):
                    b.copy_(k.flat)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        with torch.no_grad():
            restore_best()
        for k in kinds:
            k.release()
    return Result(losses=curve, best_loss=best_loss, iterations=len(curve),
                  seconds=time.perf_counter() - start, interrupted=interrupted, skipped_steps=skipped,
                  parameters={k.name: int(k.flat.numel()) for k in kinds})

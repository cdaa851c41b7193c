"""Fit a Scene to a target image: Adam with one learning rate per parameter kind.

This is the loop that `vecfit refine`, `vecfit trace` and `vecfit paint` share; they
differ only in where the initial Scene comes from.

Each parameter kind's tensors are aliased into one flat tensor (adam.py), with its
learning rate in pixels (rates.py); this module runs the iterations: render, loss,
gradient, step, the checks for non-finite values, the best-so-far snapshot, hooks.
"""
from __future__ import annotations

import contextlib
import functools
import gc
import math
import time
import warnings
from dataclasses import dataclass
from typing import Callable, Optional

import torch

from vecfit.errors import NonFiniteScene, VecfitError, VecfitWarning
from vecfit.io.compositing import composite_torch
from vecfit.io.images import downscaled, downscaled_weight
from vecfit.renderer.persistent import PersistentPack
from vecfit.renderer.raster import render
from vecfit.renderer.stopwatch import lap, phase
from vecfit.scene import Scene

from . import losses
from .result import Result
from .settings import PARAMETER_KINDS, Settings  # noqa: F401  (re-exported: the loop's settings)
from .adam import Adam
from .blur import gaussian_blur
from .outline import OutlineCost
from .opacity import colors_kept_opaque, translucency_wanted
from .rates import boundary_length_density, dense_point_rate, held_boundary_budget, outline_density, parameter_kinds

# The coarse level must leave each shape some pixels (8 x 8 on average), or its small shapes
# get no useful gradient there: the 128-px peppers trace (705 shapes) lost 1 dB coarse.
MIN_COARSE_PIXELS_PER_SHAPE = 64
MIN_COARSE_SIDE = 32  # and a target this small at half size is cheap enough at full size
# Pack the scene once per size and refresh only its floats (renderer/persistent.py); off
# packs it on every iteration (tests compare the two).
PERSISTENT_PACK = True

@dataclass
class Target:
    """What the render is compared with: [H, W, 4] straight RGBA in [0, 1] at the size
    rendered, and the background to render over (None when the target is transparent).
    ``weight`` ([H, W], optional): how much each pixel counts in the loss (`vecfit edit`
    weights the edited region); l2, l1 and pyramid only."""
    image: torch.Tensor
    background: Optional[tuple] = None
    weight: Optional[torch.Tensor] = None

    def loss(self, loss_fn, name: str, compared: torch.Tensor, goal: torch.Tensor) -> torch.Tensor:
        if self.weight is None:
            return loss_fn(compared, goal)
        return losses.weighted(name)(compared, goal, self.weight)

    @property
    def opaque(self) -> bool:
        return self.background is not None

    @functools.cached_property
    def wants_translucency(self) -> bool:
        """Whether optimize.alpha = "auto" lets every colour's alpha change here
        (opacity.translucency_wanted: translucent areas, or a photograph)."""
        return translucency_wanted(self.image.numpy(), self.opaque)

    def compared(self, rgba: torch.Tensor) -> torch.Tensor:
        """The channels the loss sees: RGB over the opaque background (a render is already
        over it; a target with transparent parts is put over it here), else premultiplied
        RGBA."""
        return composite_torch(rgba, self.background if self.opaque else None)

    def rendered(self, image: torch.Tensor) -> torch.Tensor:
        """compared() of a render made over this target's background: the core has
        composited it, so over an opaque one its alpha is 1 and its RGB is what the loss
        sees (compared() would multiply by that 1 and add 0 times the background: the same
        numbers, and 5-10 ms a full-size iteration of elementwise work and its autograd;
        the alpha channel's gradient it would send is one the core's backward pass drops
        over an opaque background)."""
        if self.opaque and (len(self.background) < 4 or self.background[3] >= 1):
            return image[..., :3]
        return self.compared(image)


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
    re-initialised. Hooks change the Scene's tensors in place, under no_grad, and call
    ``reset`` for each tensor they change (the loop then packs the Scene anew)."""
    iteration: int
    image: torch.Tensor
    scene: Scene
    target: "Target"
    reset: Callable[[torch.Tensor], None]


def _levels(target: Target, settings: Settings, shapes: int):
    """Coarse to fine: the first ``coarse`` share of the iterations fits the target at half
    its size (a quarter of the pixels, the boundaries half as long), where the large moves
    happen; the rest, and at least the last iteration, at full size. Returns the first
    full-size iteration and, for coarse and fine, (Target, the loss's view of its image)."""
    fine = (target, target.compared(target.image.float()))
    height, width = target.image.shape[:2]
    fine_from = min(int(round(settings.coarse * settings.iterations)), max(settings.iterations - 1, 0))
    too_small = min(height, width) // 2 < MIN_COARSE_SIDE
    too_dense = (height // 2) * (width // 2) < MIN_COARSE_PIXELS_PER_SHAPE * max(shapes, 1)
    if fine_from == 0 or too_small or too_dense:
        return 0, (fine, fine)
    half = torch.from_numpy(downscaled(target.image.numpy(), max(height, width) // 2))
    weight = None
    if target.weight is not None:
        weight = torch.from_numpy(downscaled_weight(target.weight.numpy(), half.shape[:2]))
    coarse = Target(half, target.background, weight)
    return fine_from, ((coarse, coarse.compared(half.float())), fine)


@contextlib.contextmanager
def _collecting_new_objects_only():
    """Each iteration makes thousands of short-lived objects (packing, autograd), and
    every so many of them Python's cycle collector walks all objects alive, torch's
    and numpy's modules included: 3-4% of the demo's job (perf). Objects that exist
    before the loop are set aside from collection while it runs (gc.freeze); cycles
    made in the loop are still collected."""
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def optimize(scene: Scene, target: Target, settings: Settings,
             progress: Callable[[Progress], None] | None = None,
             hooks: tuple[Callable[[Step], None], ...] = (), keep_alpha=(),
             penalty: Callable[[], torch.Tensor] | None = None) -> Result:
    """Fit ``scene`` to ``target`` in place; returns the loss curve and counts. The Scene
    ends at the best parameters seen. Ctrl-C stops early (``Result.interrupted``).
    ``hooks`` run after every iteration (see Step): re-seeding, saving frames.
    ``keep_alpha``: colour tensors whose alpha must not change (e.g. a backdrop that
    has to keep the canvas covered), beside those ``settings.alpha`` keeps (opacity.py). ``penalty``: a term added to every iteration's loss,
    computed from the Scene's tensors (its gradient reaches them with the image's), e.g.
    `vecfit edit`'s cost of moving what the edit did not touch. ``settings`` are taken as
    made (Settings.from_config and defaults check them and resolve the device)."""
    if target.weight is not None:
        losses.weighted(settings.loss)  # refuses a loss that takes no weight, before any work
    return _Fit(scene, target, settings, hooks, keep_alpha, penalty).run(progress)


class _Fit:
    """One run of the loop: its parameter kinds, Adam, the best parameters so far, the
    packs per image size, and the iterations."""

    def __init__(self, scene, target, settings, hooks, keep_alpha, penalty):
        self.scene, self.target, self.settings = scene, target, settings
        self.hooks, self.penalty = hooks, penalty
        self.loss_fn = losses.get(settings.loss)
        self.blur = settings.blur_px
        height, width = target.image.shape[:2]
        self.fine_from, self.levels = _levels(target, settings, len(scene.shapes))
        self.density = outline_density(scene, width, height)
        lr = dict(settings.lr)
        if "points" in lr:
            lr["points"] = dense_point_rate(float(lr["points"]), self.density, settings.dense_outline,
                                            settings.dense_points)
        self.point_rate = lr.get("points")
        self.boundary_budget = settings.boundary_budget  # held at the first full-size iteration (hold_boundary)
        translucent = settings.alpha == "auto" and target.wants_translucency
        keep_alpha = [*keep_alpha, *colors_kept_opaque(scene, settings.alpha, translucent)]
        self.kinds = kinds = parameter_kinds(scene, lr, width, height, keep_alpha)
        if not kinds:
            raise VecfitError("nothing to optimise: the scene has no parameters with a learning rate above 0")
        self.adam = Adam(kinds, settings.iterations, settings.lr_decay, settings.lr_warmup)
        self.best = [k.flat.clone() for k in kinds]
        self.best_loss = math.inf
        self.points = next((i for i, k in enumerate(kinds) if k.name == "points"), None)
        self.outline = None
        if settings.outline > 0 and self.points is not None:
            self.outline = OutlineCost(scene, kinds[self.points], width, height, settings.outline) or None
        self.image = None  # the last render, detached (for hooks)
        self.packs: dict = {}  # (width, height) -> PersistentPack, or None where it does not apply
        self.declined = False  # whether the run has said that it packs on every iteration
        self.leaves: list = []  # this iteration's kinds' flat tensors as autograd leaves
        self.where = {id(t): (i, k.offsets[id(t)], t.numel()) for i, k in enumerate(kinds) for t in k.tensors}
        self.skipped = 0  # steps refused for a non-finite loss, gradient or parameter

    # ------------------------------------------------------------- one evaluation

    def level(self, iteration: int) -> tuple[Target, torch.Tensor]:
        return self.levels[iteration >= self.fine_from]

    def packed(self, w: int, h: int):
        if not PERSISTENT_PACK:
            return None
        pack = self.packs.get((w, h), False)
        if pack is False or (pack is not None and not pack.still_valid([k.flat for k in self.kinds])):
            with phase("pack"):
                pack = PersistentPack.attempt(self.scene, w, h, self.kinds)
            if isinstance(pack, str):
                self.say_declined(pack)
                pack = None
            self.packs[(w, h)] = pack
        return pack.arrays(self.leaves) if pack is not None else None

    def say_declined(self, reason: str) -> None:
        """A warning, once a run (each image size asks for its own pack): every iteration
        packs the scene anew, the same fit at some cost in time."""
        if not self.declined:
            self.declined = True
            warnings.warn(f"the scene is packed on every iteration, which is slower: {reason}", VecfitWarning,
                          stacklevel=2)

    def evaluate(self, iteration: int, grad: bool):
        settings = self.settings
        at, goal = self.level(iteration)
        h, w = at.image.shape[:2]
        self.leaves[:] = [k.flat.detach().requires_grad_(grad) for k in self.kinds]
        with torch.set_grad_enabled(grad):
            image = render(self.scene, w, h, samples=settings.samples, mode=settings.mode,
                           seed=settings.seed + iteration, background=self.target.background,
                           threads=settings.threads, boundary_samples=settings.boundary_samples,
                           interior_samples=settings.interior_samples, boundary_budget=self.boundary_budget,
                           device=settings.device,
                           packed=self.packed(w, h))
            self.image = image.detach()
            compared = at.rendered(image)
            if self.blur > 0:  # a scan's blur, put on the render (fitting/blur.py), at this level's scale
                compared = gaussian_blur(compared, self.blur * w / self.target.image.shape[1])
            loss = at.loss(self.loss_fn, settings.loss, compared, goal)
            return loss if self.penalty is None else loss + self.penalty()

    def regularised(self, loss: torch.Tensor) -> torch.Tensor:
        """What the step minimises: the loss and the outline cost (the loss curve and the
        best-so-far follow the loss alone: the best image)."""
        return loss + self.outline(self.leaves[self.points]) if self.outline is not None else loss

    # ------------------------------------------------------------ the parameters

    def keep_if_best(self, value: float) -> None:
        if value < self.best_loss:
            self.best_loss = value
            for b, k in zip(self.best, self.kinds):
                b.copy_(k.flat)

    def restore_best(self) -> None:
        for k, b in zip(self.kinds, self.best):
            k.flat.copy_(b)

    def reset(self, tensor: torch.Tensor) -> None:
        """A hook changed ``tensor``: Adam forgets it, and the Scene is packed anew."""
        self.packs.clear()
        if id(tensor) in self.where:
            i, offset, n = self.where[id(tensor)]
            for state in (self.kinds[i].m, self.kinds[i].v, self.kinds[i].steps):
                state[offset:offset + n] = 0

    def gradients(self, loss, value: float) -> list | None:
        """The kinds' gradients of this iteration's loss (``value``: its float); None where
        the loss or a gradient is not finite."""
        grads = None
        if math.isfinite(value):
            self.keep_if_best(value)
            if loss.requires_grad:
                with phase("backward"):
                    self.regularised(loss).backward()
            # else nothing drawn depends on the parameters any more (e.g. every shape
            # shrank to nothing): zero gradients, Adam's momentum still moves them
            grads = [k.gradient(leaf) for k, leaf in zip(self.kinds, self.leaves)]
            if not all(torch.isfinite(g).all() for g in grads):
                grads = None
        for k in self.kinds:
            k.zero_grad()
        self.leaves.clear()
        return grads

    # ------------------------------------------------------------------ the run

    def iteration(self, it: int) -> tuple[float, bool]:
        """One iteration: its loss, and whether to go on (False once a refused step has
        halved the rate below 1e-4). ``skipped`` counts the refused steps."""
        if it == self.fine_from:
            if it > 0:
                self.best_loss = math.inf  # losses at the coarse size do not compare with these
            self.hold_boundary()
        try:
            with phase("forward"):
                loss = self.evaluate(it, grad=True)
        except NonFiniteScene:
            loss = None  # treated like a NaN loss
        value = float(loss.detach()) if loss is not None else math.nan
        grads = self.gradients(loss, value)
        if grads is None:
            # A non-finite loss or gradient: go back to the best parameters and try again
            # with smaller steps rather than let NaN into the Scene.
            self.refuse_step()
            return value, self.adam.rate >= 1e-4
        with torch.no_grad(), phase("adam"):
            self.adam.step(grads)
        if not all(torch.isfinite(k.flat).all() for k in self.kinds):
            self.refuse_step()
        return value, True

    def hold_boundary(self) -> None:
        """A dense scene's boundary samples (its outlines past settings.dense_outline at the
        start, as the point rate has it) may grow to settings.boundary_growth times what
        this first full-size iteration asks, and no further (rates.held_boundary_budget)."""
        s = self.settings
        if s.mode != "mc" or s.boundary_growth <= 0 or not (0 < s.dense_outline < self.density):
            return
        h, w = self.target.image.shape[:2]
        self.boundary_budget = held_boundary_budget(s.boundary_budget, s.boundary_growth, s.boundary_samples,
                                                    boundary_length_density(self.scene, w, h))

    def refuse_step(self) -> None:
        self.skipped += 1
        self.restore_best()
        self.adam.rate *= 0.5

    def run_hooks(self, it: int) -> None:
        if self.hooks and self.image is not None:
            with torch.no_grad(), phase("hooks"):
                for hook in self.hooks:
                    hook(Step(it, self.image, self.scene, self.level(it)[0], self.reset))
                for k in self.kinds:
                    k.project()

    def run(self, progress) -> Result:
        settings, kinds = self.settings, self.kinds
        curve: list[float] = []
        times: list[float] = []
        interrupted = False
        start = time.perf_counter()
        try:
            with _collecting_new_objects_only():
                for it in range(settings.iterations):
                    began = time.perf_counter()
                    value, go_on = self.iteration(it)
                    curve.append(value)
                    if not go_on:
                        break
                    self.run_hooks(it)
                    times.append(time.perf_counter() - began)
                    lap(times[-1])
                    if progress is not None:
                        progress(Progress(it + 1, settings.iterations, value, self.best_loss,
                                          time.perf_counter() - start))
            # The last step's result has not been measured yet.
            if settings.iterations > 0:
                value = float(self.evaluate(settings.iterations, grad=False))
                if math.isfinite(value):
                    self.keep_if_best(value)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            with torch.no_grad():
                self.restore_best()
            for k in kinds:
                k.release()
        return Result(losses=curve, best_loss=self.best_loss, iterations=len(curve),
                      seconds=time.perf_counter() - start, interrupted=interrupted, skipped_steps=self.skipped,
                      parameters={k.name: int(k.flat.numel()) for k in kinds}, iteration_seconds=times,
                      coarse_iterations=min(self.fine_from, len(curve)), outline_density=self.density,
                      point_rate=self.point_rate)

"""Settings of `vecfit edit` ([edit] in configs/edit.toml) and `vecfit retarget`
([retarget] in configs/retarget.toml)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from vecfit.errors import VecfitError
from vecfit.io.configs import defaults


@dataclass
class EditSettings:
    changed_weight: float      # loss weight of a changed pixel (an unchanged one: 1)
    anchor: float              # penalty on changing what acts only outside the changed region
    anchor_free: float         # ... and lengths acting inside it (see vecfit.fitting.anchor)
    anchor_free_colors: float  # ... and colours acting inside it
    threshold: float           # a pixel changed where a channel differs by more than this
    min_area: int              # changed specks smaller than this (pixels) are no edit
    grow: int                  # the changed region grown by this many pixels
    reach: int                 # elements acting this close to the changed region are free

    @classmethod
    def defaults(cls, **changes) -> "EditSettings":
        """The defaults of configs/edit.toml ([edit]), with ``changes``."""
        table = defaults("edit", "edit")
        return cls(**{**table, **changes})

    def check(self) -> None:
        for name in ("changed_weight", "anchor", "anchor_free", "anchor_free_colors", "threshold"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise VecfitError(f"edit.{name} must be a number >= 0, not {value}")
        if self.changed_weight < 1:
            raise VecfitError(f"edit.changed_weight must be at least 1, not {self.changed_weight}")
        if self.threshold >= 1:
            raise VecfitError(f"edit.threshold must be below 1, not {self.threshold}")
        for name in ("min_area", "grow", "reach"):
            if getattr(self, name) < 0:
                raise VecfitError(f"edit.{name} must be 0 or more, not {getattr(self, name)}")


@dataclass
class RetargetSettings:
    width: str                # new width: pixels or a percentage ("": unchanged)
    height: str               # new height, likewise
    steps: int                # carve-and-fit rounds
    iterations_per_step: int  # Adam iterations fitting each round's carved image
    final_iterations: int     # more at the end, against the last carved image
    iterations: int           # > 0: the whole run's iterations, divided as the two above
    work_size: int            # carve and fit at this longest side (0: the SVG's size)
    foreground: float         # seam energy added per pixel unlike the bare canvas

    @classmethod
    def defaults(cls, **changes) -> "RetargetSettings":
        """The defaults of configs/retarget.toml ([retarget]), with ``changes``."""
        table = defaults("retarget", "retarget")
        return cls(**{**table, **changes})

    def check(self) -> None:
        if self.steps < 1:
            raise VecfitError(f"retarget.steps must be at least 1, not {self.steps}")
        for name in ("iterations_per_step", "final_iterations", "iterations", "work_size"):
            if getattr(self, name) < 0:
                raise VecfitError(f"retarget.{name} must be 0 or more, not {getattr(self, name)}")
        if not (math.isfinite(self.foreground) and self.foreground >= 0):
            raise VecfitError(f"retarget.foreground must be a number >= 0, not {self.foreground}")
        if 0 < self.work_size < 32:
            raise VecfitError(f"retarget.work_size must be 0 or at least 32, not {self.work_size}")

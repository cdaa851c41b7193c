"""The fitting loop's settings (vecfit.fitting.loop.Settings), checked without torch: a
job that will not optimise (`trace --no-refine`) still refuses a bad [optimize] table, and
never imports torch to do so."""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

from vecfit.errors import VecfitError
from vecfit.io.colors import fitting_background
from vecfit.io.configs import defaults
from vecfit.fitting.blur import MAX_BLUR
from vecfit.renderer import device as devices
from vecfit.names import LOSSES, MODES
ALPHA_MODES = ("auto", "free", "fixed")  # which colours' opacity may change (opacity.py)

PARAMETER_KINDS = ("points", "colors", "stroke_widths", "opacities", "radii", "gradient_points",
                   "gradient_radii", "stop_offsets", "transforms")


@dataclass
class Settings:
    """The loop's settings. Their defaults are configs/refine.toml's [optimize] table
    (``defaults()``), so the Python API and the CLI start alike."""
    iterations: int
    loss: str
    mode: str
    samples: int
    boundary_samples: float
    interior_samples: int  # of the N x N samples per pixel, those the backward revisits (0: all)
    seed: int
    threads: int
    device: str  # resolved (Settings.of_checked): cpu or cuda:N
    lr_decay: float
    lr_warmup: int
    alpha: str  # ALPHA_MODES: auto (only where the target or the colour is translucent) | free | fixed
    coarse: float  # fraction of the iterations run at half the size (coarse to fine)
    outline: float  # weight of the cost on outlines growing (outline.py), per px of growth per px
    boundary_budget: float  # Monte Carlo boundary samples per image pixel at most (0: no bound)
    boundary_growth: float  # a dense scene's boundary samples: at most this many times the first full-size iteration's (0: free)
    dense_outline: float  # control polygon px per image px past which the point rate falls (rates.py)
    dense_points: float  # ... to this rate (px a step) at twice that density
    max_size: int  # the target downscaled to this longest side to optimise on (0: never)
    background: str  # auto (the target's corners) | none | a colour (io.colors.fitting_background)
    eval_samples: int  # N x N samples of the reported metrics and the comparison image
    palette: str  # the colours written ("" free; vecfit/jobs/palette.py reads it)
    simplify: float  # after the fit, nodes dropped while the picture loses at most this many dB (0: never)
    simplify_iterations: int  # the brief refinement after those joins (vecfit/fitting/simplify.py)
    simplify_samples: int  # N x N samples of the renders that judge the joins (0: eval_samples')
    target_blur: object  # "auto" | px: the render blurred alike before the loss (fitting/blur.py); the loop reads "auto" as 0
    lr: dict

    @property
    def blur_px(self) -> float:
        """target_blur in pixels: "auto" (which the trace job resolves for line art) is 0."""
        return 0.0 if self.target_blur == "auto" else float(self.target_blur)

    @classmethod
    def defaults(cls, **changes) -> "Settings":
        """configs/refine.toml's [optimize] settings, with ``changes`` (``lr`` replaces the
        whole table of rates)."""
        return cls.from_config({**defaults("refine", "optimize"), **changes}, source="Settings.defaults")

    @classmethod
    def from_config(cls, table: dict, source: str = "configs/refine.toml") -> "Settings":
        """From the whole [optimize] table, checked: every key is a field here, and a key
        that is not (or a field left out) is an error naming ``source`` (the file) and the
        key; a value out of range is refused. The one check of these settings:
        vecfit.jobs.config.resolve makes it for every command, before any work."""
        s = cls.of_checked(table, source)
        s.check()
        return s

    @classmethod
    def of_checked(cls, table: dict, source: str = "configs/refine.toml") -> "Settings":
        """From an [optimize] table whose values were checked (by vecfit.jobs.config.resolve:
        a job's settings), its values not checked again. The device is resolved here,
        "auto" settled to "cpu" or "cuda:N": the loop, the renders a job scores and its
        report all take this one name."""
        known = {f.name for f in fields(cls)}
        unknown, missing = sorted(set(table) - known), sorted(known - set(table) - {"lr"})
        if unknown or missing:
            problem = (f"unknown setting 'optimize.{unknown[0]}' (known here: {', '.join(sorted(known))})"
                       if unknown else f"missing setting 'optimize.{missing[0]}'")
            raise VecfitError(f"{source}: {problem}")
        device = devices.device_name(devices.resolve(table["device"]))
        return cls(**{k: v for k, v in table.items() if k not in ("lr", "device")}, device=device,
                   lr=dict(table.get("lr", {})))

    def check(self) -> None:
        if self.iterations < 0:
            raise VecfitError("iterations must be 0 or more")
        if self.loss not in LOSSES:
            raise VecfitError(f"loss must be one of {', '.join(LOSSES)}, not {self.loss!r}")
        if self.alpha not in ALPHA_MODES:
            raise VecfitError(f"alpha must be one of {', '.join(ALPHA_MODES)}, not {self.alpha!r}")
        if self.mode not in MODES:
            raise VecfitError(f"mode must be one of {', '.join(MODES)}, not {self.mode!r}")
        if self.samples < 1:
            raise VecfitError("samples must be at least 1")
        if not 0 < self.lr_decay <= 1:
            raise VecfitError("lr_decay must be in (0, 1]")
        if self.lr_warmup < 0:
            raise VecfitError("lr_warmup must be 0 or more")
        if not 0 <= self.coarse < 1:  # the last iterations must be at full size
            raise VecfitError(f"coarse must be at least 0 and below 1, not {self.coarse}")
        for name in ("outline", "boundary_budget", "boundary_growth", "dense_outline", "dense_points"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise VecfitError(f"{name} must be a number >= 0, not {value}")
        if self.max_size < 0:
            raise VecfitError(f"max_size must be 0 (never downscale) or more, not {self.max_size}")
        if self.eval_samples < 1:
            raise VecfitError(f"eval_samples must be at least 1, not {self.eval_samples}")
        if not (isinstance(self.simplify, (int, float)) and math.isfinite(self.simplify) and self.simplify >= 0):
            raise VecfitError(f"simplify must be a number of dB >= 0, not {self.simplify}")
        if self.simplify_samples < 0:
            raise VecfitError(f"simplify_samples must be 0 or more, not {self.simplify_samples}")
        if self.simplify_iterations < 0:
            raise VecfitError(f"simplify_iterations must be 0 or more, not {self.simplify_iterations}")
        blur = self.target_blur
        if not (blur == "auto" or (isinstance(blur, (int, float)) and not isinstance(blur, bool)
                                   and math.isfinite(blur) and 0 <= blur <= MAX_BLUR)):
            raise VecfitError(f'target_blur must be "auto" or a number of pixels from 0 to {MAX_BLUR:g}, not {blur!r}')
        if self.background.strip().lower() != "auto":
            fitting_background(self.background)
        for kind, value in self.lr.items():
            if kind not in PARAMETER_KINDS:
                raise VecfitError(f"unknown parameter kind {kind!r} (known: {', '.join(PARAMETER_KINDS)})")
            if not (math.isfinite(value) and value >= 0):
                raise VecfitError(f"learning rate of {kind} must be a number >= 0, not {value}")

"""What a run of the fitting loop reports (vecfit.fitting.loop.optimize returns it). Kept
apart from the loop, which needs torch: a job that does not optimise (`trace
--no-refine`) reports the same fields for its 0 iterations without importing it."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional


@dataclass
class Result:
    losses: list = field(default_factory=list)  # loss of each iteration (before its step)
    best_loss: float = math.inf
    iterations: int = 0     # steps taken
    seconds: float = 0.0
    interrupted: bool = False
    skipped_steps: int = 0  # steps refused for a non-finite loss, gradient or parameter
    parameters: dict = field(default_factory=dict)  # kind -> number of floats optimised
    iteration_seconds: list = field(default_factory=list)  # wall time of each iteration
    coarse_iterations: int = 0  # the first ones, fitted at half the size
    outline_density: Optional[float] = None  # control polygon px per image px at the start (rates.py)
    point_rate: Optional[float] = None  # the point rate used, px a step (after the density rule)

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


def joined(runs: list[Result]) -> Result:
    """Runs of the loop made one after another on one Scene (retarget's rounds) as one:
    their curves, counts and times added up; the parameters and rates the last one used
    (every run optimises the same tensors)."""
    last = runs[-1] if runs else Result()
    return Result(losses=[v for r in runs for v in r.losses],
                  best_loss=last.best_loss,
                  iterations=sum(r.iterations for r in runs),
                  seconds=sum(r.seconds for r in runs),
                  interrupted=any(r.interrupted for r in runs),
                  skipped_steps=sum(r.skipped_steps for r in runs),
                  parameters=dict(last.parameters),
                  iteration_seconds=[t for r in runs for t in r.iteration_seconds],
                  coarse_iterations=sum(r.coarse_iterations for r in runs),
                  outline_density=last.outline_density,
                  point_rate=last.point_rate)

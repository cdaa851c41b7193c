"""Wall time by phase (packing, the core's passes, the loop's steps) for benchmarks.

Off unless a Stopwatch is running, and then one clock read per phase: the renderer and the
fitting loop mark their phases with ``phase(name)``, and the loop closes a lap per
iteration, so a benchmark can show where an iteration's time goes at the start and the
end of a run (benchmarks/refine.py).
"""
from __future__ import annotations

import time
from collections import defaultdict
from contextlib import contextmanager

_running: "Stopwatch | None" = None


class Stopwatch:
    """``with Stopwatch() as sw: ...``; then ``sw.laps``: one {phase: seconds} per lap."""

    def __init__(self):
        self.laps: list[dict[str, float]] = []
        self._current: dict[str, float] = defaultdict(float)

    def __enter__(self) -> "Stopwatch":
        global _running
        from vecfit import _core
        _core.phase_seconds()  # the core's clocks start from zero
        self._outer, _running = _running, self
        return self

    def __exit__(self, *exc) -> None:
        global _running
        _running = self._outer


@contextmanager
def phase(name: str):
    """Adds the time spent inside to ``name`` in the running Stopwatch's current lap."""
    if _running is None:
        yield
        return
    watch, began = _running, time.perf_counter()
    try:
        yield
    finally:
        watch._current[name] += time.perf_counter() - began


def add_core_phases() -> None:
    """Adds the core's own phase clocks (prepare, plan, the passes) since they were last
    read, each as ``core NAME``; call it after each call into the core."""
    if _running is not None:
        from vecfit import _core
        for name, seconds in _core.phase_seconds().items():
            _running._current[f"core {name}"] += seconds


def lap(seconds: float) -> None:
    """Closes the current lap (an iteration of ``seconds`` wall time), if one is running."""
    if _running is not None:
        _running._current["iteration"] = seconds
        _running.laps.append(dict(_running._current))
        _running._current = defaultdict(float)

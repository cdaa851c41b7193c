"""The machine unit R: how long resvg takes to render examples/tiger.svg 1,000 px wide on
one thread, the median of 20 renders. A time divided by R, measured in the same run, can
be compared across machines and across runs on a shared machine, where seconds cannot.

    python benchmarks/machine.py [--repeats 20]

Other benchmarks import ``machine_unit`` and print their times as ``in_r(seconds, R)``:
"12.3 s (56 R)". resvg is the resvg_py package; a render is what its svg_to_bytes does
(parse, render, encode the PNG), without loading the system's fonts (tiger has no text,
and scanning font folders would measure the machine's fonts). It renders on the calling
thread: the script counts the process's threads while it renders, and
RAYON_NUM_THREADS=1 is set before resvg_py is imported, for a build that would use rayon.
"""
from __future__ import annotations

import argparse
import math
import os
import threading
import time
from importlib.metadata import version
from pathlib import Path

from common import median_time

os.environ["RAYON_NUM_THREADS"] = "1"  # (before resvg_py is imported)

TIGER = Path(__file__).resolve().parents[1] / "examples" / "tiger.svg"
WIDTH = 1000


def _render() -> None:
    import resvg_py
    resvg_py.svg_to_bytes(svg_path=str(TIGER), width=WIDTH, skip_system_fonts=True)


def machine_unit(repeats: int = 20) -> float:
    """R in seconds: the median wall time of ``repeats`` renders, after one not timed."""
    return median_time(_render, repeats=repeats, warmup=1)


def _significant(value: float, digits: int) -> str:
    """``value`` with ``digits`` significant digits, without an exponent (1234.5 -> "1235")."""
    if value == 0 or not math.isfinite(value):
        return f"{value:g}"
    decimals = max(0, digits - 1 - math.floor(math.log10(abs(value))))
    return f"{value:.{decimals}f}"


def in_r(seconds: float, unit: float) -> str:
    """A time in seconds and in R: "12.3 s (56 R)"."""
    return f"{_significant(seconds, 3)} s ({_significant(seconds / unit, 2)} R)"


def _threads() -> int | None:
    """The process's threads (Linux), Rust's included, which Python's threading does not see."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return None


def _threads_while_rendering(renders: int = 5) -> int | None:
    """The most threads the process had during a few renders, less the one counting them."""
    if _threads() is None:
        return None
    most, done = [0], threading.Event()

    def count():
        while not done.is_set():
            most[0] = max(most[0], _threads())
            time.sleep(0.0005)

    watcher = threading.Thread(target=count)
    watcher.start()
    for _ in range(renders):
        _render()
    done.set()
    watcher.join()
    return most[0] - 1


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=20)
    args = ap.parse_args()
    unit = machine_unit(args.repeats)
    threads = _threads_while_rendering()
    print(f"R = {unit:.4f} s: resvg_py {version('resvg_py')} rendering {TIGER.name} {WIDTH} px wide, "
          f"median of {args.repeats}; threads while rendering: {threads if threads is not None else 'unknown'}")


if __name__ == "__main__":
    main()

"""The document model's costs: how often each job parses its SVG, and the time from the
start of a refine job to its first iteration (reading, the Scene as read, the target,
the first renders) on tiger and on a dense trace (3,000 paths of skimage's coffee).

    python benchmarks/document.py [--repeats 5] [--paths 3000]

Prints a table; medians of --repeats runs on 2 threads.
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
import warnings
from pathlib import Path

import common  # noqa: F401  (before torch: OpenMP threads sleep)

import numpy as np
from PIL import Image

from vecfit.jobs.config import resolve
from vecfit.jobs.protocol import Inputs, Outputs, Progress, job_function
from vecfit.svg.document import SvgDocument
from vecfit.svg.read import read_svg


class _FirstIteration(Progress):
    def __init__(self):
        self.at = None

    def __call__(self, step):
        if self.at is None:
            self.at = time.perf_counter()


def _counting_parses():
    counts = []
    original = SvgDocument.parse.__func__
    SvgDocument.parse = classmethod(lambda cls, *a, **k: counts.append(1) or original(cls, *a, **k))
    return counts


def _dense_trace(folder: Path, paths: int) -> tuple[Path, Path]:
    from skimage import data

    from vecfit.initial.tracer import TraceSettings, trace_image
    image = data.coffee()
    target = folder / "coffee.png"
    Image.fromarray(image).save(target)
    rgba = np.concatenate([image / 255.0, np.ones(image.shape[:2] + (1,))], axis=2).astype(np.float32)
    traced = trace_image(rgba, TraceSettings.defaults(paths=paths))
    svg = folder / f"coffee_{traced.paths}.svg"
    svg.write_text(traced.svg)
    return target, svg


def _tiger(folder: Path) -> tuple[Path, Path]:
    import vecfit
    svg = common.SCENES / "tiger.svg"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(svg)
    image = vecfit.render(scene, int(scene.width), int(scene.height), samples=2, background=[1, 1, 1, 1])
    target = folder / "tiger.png"
    Image.fromarray((image[..., :3].numpy() * 255 + 0.5).astype(np.uint8)).save(target)
    return target, svg


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--paths", type=int, default=3000)
    args = parser.parse_args()
    counts = _counting_parses()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        cases = {"tiger": _tiger(folder), f"coffee trace": _dense_trace(folder, args.paths)}
        print("| SVG | shapes | parses per refine | read_svg s | start to first iteration s |")
        print("|---|---|---|---|---|")
        for name, (target, svg) in cases.items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                scene, _ = read_svg(svg)
                reads, firsts, parses = [], [], []
                for _ in range(args.repeats):
                    start = time.perf_counter()
                    read_svg(svg)
                    reads.append(time.perf_counter() - start)
                    config = resolve("refine", overrides={"optimize": {"iterations": 1, "threads": 2}})
                    listener = _FirstIteration()
                    before = len(counts)
                    start = time.perf_counter()
                    job_function("refine")(Inputs(image=target, svg=svg), config,
                                           Outputs.beside(folder / "out.png"), progress=listener)
                    firsts.append(listener.at - start)
                    parses.append(len(counts) - before)
            print(f"| {name} | {len(scene.shapes)} | {max(parses)} | {statistics.median(reads):.3f} "
                  f"| {statistics.median(firsts):.3f} |")


if __name__ == "__main__":
    main()

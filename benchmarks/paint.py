"""Painterly rendering: 256 random strokes fitted to skimage's astronaut and chelsea at
256 and 512 pixels (the longer side) with the defaults of configs/paint.toml; PSNR and
seconds per iteration, the PSNR curve, and the same runs without re-seeding.

Usage: python benchmarks/paint.py [--iterations N] [--sizes 256,512] [--images astronaut,chelsea]
       [--compare-sizes 256]   (sizes also run without re-seeding)
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from vecfit.jobs.config import resolve
from vecfit.jobs.paint import run as paint
from vecfit.jobs.protocol import Inputs, Outputs

CHECKPOINTS = (0, 50, 100, 200, 300, 400, 500)


def target_file(name: str, size: int, folder: Path) -> Path:
    import skimage.data
    image = Image.fromarray(getattr(skimage.data, name)())
    scale = size / max(image.size)
    image = image.resize((round(image.width * scale), round(image.height * scale)), Image.LANCZOS)
    path = folder / f"{name}_{size}.png"
    image.save(path)
    return path


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--iterations", type=int, default=500)
    ap.add_argument("--sizes", default="256,512")
    ap.add_argument("--images", default="astronaut,chelsea")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--compare-sizes", default="256",
                    help="sizes at which to run without re-seeding too ('' for none)")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name in args.images.split(","):
            for size in (int(s) for s in args.sizes.split(",")):
                target = target_file(name, size, tmp)
                compare_at = {int(c) for c in args.compare_sizes.split(",") if c}
                for reseed in ([50, 0] if size in compare_at else [50]):
                    config = resolve("paint", overrides={
                        "optimize": {"iterations": args.iterations, "threads": args.threads},
                        "paint": {"reseed_every": reseed}})
                    out = Outputs.beside(target, tmp / f"{name}_{size}_{reseed}.svg")
                    report = paint(Inputs(image=target), config, out)
                    rows.append((name, size, reseed, report))
                    print(f"{name} {size} reseed={reseed}: PSNR {report['optimized']['psnr']:.2f} dB, "
                          f"{report['seconds']['per_iteration']:.3f} s/iter, "
                          f"re-seeded {report['paint']['reseeded']}", flush=True)

    print()
    print("| image | size | re-seeding | PSNR before -> after | s / iteration | total s | re-seeded |")
    print("|---|---|---|---|---|---|---|")
    for name, size, reseed, rep in rows:
        w, h = rep["size"]
        print(f"| {name} | {w}x{h} | {'every ' + str(reseed) if reseed else 'off'} "
              f"| {rep['initial']['psnr']:.2f} -> {rep['optimized']['psnr']:.2f} "
              f"| {rep['seconds']['per_iteration']:.3f} | {rep['seconds']['total']:.1f} "
              f"| {rep['paint']['reseeded']} |")
    print()
    marks = [c for c in CHECKPOINTS if c < args.iterations] + [args.iterations - 1]
    print("PSNR (dB, from the loss: the MC 2x2 render at that iteration) against iterations:")
    print("| image | size | re-seeding | " + " | ".join(str(m + 1) for m in marks) + " |")
    print("|---|---|---|" + "---|" * len(marks))
    for name, size, reseed, rep in rows:
        curve = rep["loss_curve"]
        cells = [f"{10 * np.log10(1 / curve[m]):.2f}" if m < len(curve) and curve[m] > 0 else "" for m in marks]
        print(f"| {name} | {size} | {'on' if reseed else 'off'} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()

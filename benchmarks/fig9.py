"""Fig. 9 of Li et al. 2020 on the benchmark scenes: every geometry point moved right by
delta; d/d delta of sum(W * image), W a smooth random weighting vanishing within 4 px of
the border; autograd against central differences (delta = +-step) of the same renderer,
same seed both sides. Prints the relative error per scene, mode and weighting.

    python benchmarks/fig9.py [--scenes tiger mcseem2] [--seeds 4] [--step 0.5] [--size 0]

--size 0 renders at the native size. MC rows are the mean over seeds of both sides.
"""
from __future__ import annotations

import argparse
import warnings

import numpy as np

from common import SCENES

import vecfit
from vecfit.renderer.fig9 import fig9, mean_derivative, weighting


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", nargs="+", default=["tiger", "mcseem2"])
    ap.add_argument("--modes", nargs="+", default=["mc", "analytic"])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--step", type=float, default=0.5)
    ap.add_argument("--size", type=int, default=0)
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--small-step", type=float, default=0.01, help="analytical: a second check at this step")
    ap.add_argument("--points", type=int, default=16,
                    help="analytical: the +-step difference against the mean autograd derivative at this many points")
    args = ap.parse_args()
    print(f"| scene, mode | weighting 0 | weighting 1 |  (step {args.step} px)")
    print("|---|---|---|")
    for name in args.scenes:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            scene = vecfit.load_svg(SCENES / f"{name}.svg")
        w = args.size or round(scene.width)
        h = round(scene.height * w / scene.width)
        weights = [weighting(k, h, w) for k in range(2)]
        for mode in args.modes:
            seeds = range(args.seeds) if mode == "mc" else [0]
            samples = 4 if mode == "mc" else 1
            runs = np.array([fig9(scene, w, h, weights, step=args.step, mode=mode, samples=samples, seed=s,
                                  threads=args.threads) for s in seeds])  # [seed, weighting, (ad, fd)]
            # MC: the means over the first 1, 4, 16 ... seeds (an unbiased error falls like
            # 1 / sqrt(seeds))
            counts = [n for n in (1, 4, 16, 64) if n < len(seeds)] + [len(seeds)]
            for n in counts:
                ad, fd = runs[:n].mean(axis=0).T
                rel = np.abs(ad - fd) / np.abs(fd)
                cells = " | ".join(f"{100 * r:.1f}% ({a:.4g} vs {f:.4g})" for r, a, f in zip(rel, ad, fd))
                label = f"MC {samples}x{samples}, {n} seeds" if mode == "mc" else "analytical 1x1"
                print(f"| {name} {w}x{h}, {label} | {cells} |", flush=True)
            if mode == "analytic":
                # The analytical image curves within +-0.5 px (the kernel's support is one
                # pixel wide): the derivative at 0 against a small step, and the wide
                # step against the mean derivative over it.
                small = np.array(fig9(scene, w, h, weights, step=args.small_step, mode=mode, samples=1,
                                      threads=args.threads))
                ad, fd = small.T
                rel = np.abs(ad - fd) / np.abs(fd)
                cells = " | ".join(f"{100 * r:.1f}% ({a:.4g} vs {f:.4g})" for r, a, f in zip(rel, ad, fd))
                print(f"| {name} {w}x{h}, analytical 1x1, step {args.small_step} | {cells} |", flush=True)
                if args.points:
                    mean = np.array(mean_derivative(scene, w, h, weights, step=args.step, points=args.points,
                                                    mode=mode, samples=1, threads=args.threads))
                    fd = runs[0, :, 1]
                    rel = np.abs(mean - fd) / np.abs(fd)
                    cells = " | ".join(f"{100 * r:.1f}% ({a:.4g} vs {f:.4g})" for r, a, f in zip(rel, mean, fd))
                    print(f"| {name} {w}x{h}, analytical 1x1, mean autograd over +-{args.step} "
                          f"({args.points} points) | {cells} |", flush=True)


if __name__ == "__main__":
    main()

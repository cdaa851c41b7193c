"""GPU speed: forward and backward on a CUDA device against the CPU, and against the
paper's Table 1 (diffvg on a 2020 GPU).

    python benchmarks/gpu.py [--repeats 5] [--threads 0] [--device cuda]

Needs a core built with VECFIT_CUDA=1 and a GPU; says so and stops otherwise. Times are
medians after a warm-up and include everything render() does per call: packing, scene
preparation and tile binning on the host, the uploads, the kernels and the copies back
(loss = sum of the squared image, gradients of the path points, as in
benchmarks/gradients.py; forward and backward timed in the same runs). "CPU redo" counts
the GPU backward passes that were redone on the CPU because a sample needed longer lists
than a GPU thread holds (their time is then the CPU's): it should read 0.
"""
from __future__ import annotations

import argparse
import sys

from common import scene_workload

# Li et al. 2020, Table 1 (forward / backward seconds on their GPU).
PAPER = {("tiger", "mc"): (0.060, 0.222), ("boston", "mc"): (0.074, 0.266),
         ("tiger", "analytic"): (0.098, 0.099)}
CONFIGS = [("tiger", "mc", 2), ("tiger", "analytic", 1), ("mcseem2", "mc", 2), ("boston", "mc", 2),
           ("boston", "analytic", 1)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--threads", type=int, default=0, help="CPU threads (0: all cores)")
    ap.add_argument("--device", default="cuda")
    args = ap.parse_args()

    import vecfit
    from vecfit.renderer.device import build_summary
    from vecfit.renderer.raster import backward_fallbacks
    print(build_summary())
    if not vecfit.has_cuda() or vecfit.cuda_device_count() == 0:
        sys.exit("no CUDA build or no GPU here: nothing to measure")

    head = (f"{'workload':22s} {'CPU fwd':>8s} {'CPU bwd':>8s} {'GPU fwd':>8s} {'GPU bwd':>8s} "
            f"{'paper fwd/bwd':>14s} {'vs paper':>12s} {'CPU redo':>8s}")
    print(f"median of {args.repeats}, seconds")
    print(head)
    print("-" * len(head))
    for name, mode, samples in CONFIGS:
        cpu = scene_workload(name, mode, samples, args.threads, args.repeats, device="cpu")
        redone = backward_fallbacks()
        gpu = scene_workload(name, mode, samples, args.threads, args.repeats, device=args.device)
        redone = backward_fallbacks() - redone
        paper = PAPER.get((name, mode))
        ref = f"{paper[0]:.3f}/{paper[1]:.3f}" if paper else "-"
        speed = f"{paper[0] / gpu[0]:.1f}x/{paper[1] / gpu[1]:.1f}x" if paper else "-"
        label = f"{name} {mode} {samples}x{samples}"
        print(f"{label:22s} {cpu[0]:8.3f} {cpu[1]:8.3f} {gpu[0]:8.3f} {gpu[1]:8.3f} {ref:>14s} {speed:>12s} {redone:8d}")


if __name__ == "__main__":
    main()

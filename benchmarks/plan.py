"""Where a fitting iteration's core time goes (the core's phase clocks), for peppers and
kitty at the fitting loop's settings (MC, 2x2 samples, 2 boundary samples per pixel,
1 interior sample, 2 threads): medians over the iterations of render + L2 backward.
With --hash it prints instead hashes of the image and the gradients per scene, mode and
thread count (peppers, kitty, tiger), to check that a change of the core leaves them bit
for bit.

Usage: python benchmarks/plan.py [--iterations N] [--threads T] [--core PATH] [--hash]
--core loads another build of vecfit._core (a copy of the .so), to compare builds
interleaved in separate processes.
"""
from __future__ import annotations

import argparse
import hashlib
import importlib.util
import statistics
import sys
import time
import warnings

from common import SHARED

SCENES = {"peppers": SHARED / "data" / "photos" / "peppers.svg",
          "kitty": SHARED / "data" / "photos" / "kitty.svg",
          "tiger": SHARED / "data" / "scenes" / "tiger.svg"}


def use_core(path: str) -> None:
    spec = importlib.util.spec_from_file_location("vecfit._core", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules["vecfit._core"] = module


def load(name):
    from vecfit import load_svg
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = load_svg(SCENES[name])
    params = [t for ts in scene.parameters().values() for t in ts]
    for t in params:
        t.requires_grad_(True)
    return scene, params


def iteration(scene, params, seed, threads, mode="mc", target=None):
    import torch
    from vecfit.renderer.raster import render
    w, h = int(round(scene.width)), int(round(scene.height))
    for t in params:
        t.grad = None
    image = render(scene, w, h, samples=2, mode=mode, seed=seed, threads=threads, boundary_samples=2.0,
                   interior_samples=1)
    if target is None:
        target = torch.full_like(image, 0.5)
    ((image - target) ** 2).sum().backward()
    return image


def timings(args) -> None:
    from vecfit import _core
    for name in args.images.split(","):
        scene, params = load(name)
        iteration(scene, params, 0, args.threads)  # warm up
        _core.phase_seconds()
        rows = []
        for i in range(args.iterations):
            began = time.perf_counter()
            iteration(scene, params, i + 1, args.threads)
            wall = time.perf_counter() - began
            rows.append({**_core.phase_seconds(), "wall": wall})
        med = {k: statistics.median(r[k] for r in rows) * 1e3 for k in rows[0]}
        print(name, " ".join(f"{k.replace(' ', '_')}={v:.2f}" for k, v in med.items()))


def hashes(args) -> None:
    """Hashes of the core's image and gradient arrays (what the core returns), and of the
    Scene tensors' gradients (after torch's packing backward, which is not always
    bit-reproducible on its own: an occasional run differs there with the core's output
    the same)."""
    import vecfit.renderer.raster as raster
    core = raster._core
    got = []

    class Recording:  # the core as raster calls it, hashing what it returns
        def __getattr__(self, name):
            return getattr(core, name)

        def render_keeping(self, *a, **k):
            image, kept = core.render_keeping(*a, **k)
            got.append(hashlib.sha256(image.tobytes()).hexdigest()[:16])
            return image, kept

        def render_grad(self, *a):
            grads = core.render_grad(*a)
            h = hashlib.sha256()
            for name in sorted(grads):
                h.update(grads[name].tobytes())
            got.append(h.hexdigest()[:16])
            return grads

    raster._core = Recording()
    for name in ("peppers", "kitty", "tiger"):
        scene, params = load(name)
        for mode in ("mc", "analytic"):
            for threads in (1, 2):
                got.clear()
                iteration(scene, params, 3, threads, mode)
                h = hashlib.sha256()
                for t in params:
                    h.update(b"-" if t.grad is None else t.grad.numpy().tobytes())
                print(name, mode, threads, "image", got[0], "core grads", got[1], "scene grads", h.hexdigest()[:16])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--iterations", type=int, default=10)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--images", default="peppers,kitty")
    ap.add_argument("--core", help="path of a vecfit._core build to load instead of the installed one")
    ap.add_argument("--hash", action="store_true")
    args = ap.parse_args()
    if args.core:
        use_core(args.core)
    hashes(args) if args.hash else timings(args)


if __name__ == "__main__":
    main()

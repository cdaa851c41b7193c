"""Refine on emoji drawn through clip paths, beside one drawn without (the issue "Real SVG
files render as browsers draw them"): the target is resvg's render of the file; the
written SVG is scored by resvg too (PSNR over white).

Two starts per emoji: the file as it is (it already draws the target: refine must not
make it worse), and the file with every point jittered (clip paths' included) by a
normal deviation of --jitter pixels (refine should recover it as well with clips as
without).

    python benchmarks/clipped_refine.py [--iterations 250] [--jitter 1.5]
"""
from __future__ import annotations

import argparse
import io
import tempfile
import time
import warnings
from pathlib import Path

import common  # noqa: F401  (sets the OpenMP wait policy before torch loads)
import numpy as np
import torch

CASES = {"noto-emoji-018": "clipped (2 clip paths)", "noto-emoji-060": "no clip paths"}


def psnr(a, b) -> float:
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(1 / mse)


def jittered(svg: Path, sigma_px: float, seed: int = 0) -> str:
    """The SVG's text with every geometry point (clip paths' and masks' included) moved by
    a normal deviation of sigma_px canvas pixels at 256 px wide."""
    from vecfit.svg.read import read_svg
    from vecfit.svg.write import svg_bytes

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene, document = read_svg(svg)
    scale = 256 / scene.width * float(scene.view[0, 0])  # user units -> pixels at 256 wide
    g = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for t in scene.parameters()["points"]:
            t.add_(torch.randn(t.shape, generator=g) * sigma_px / scale)
    return svg_bytes(scene, document).decode()


def main(argv=None):
    import vecfit

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--iterations", type=int, default=250)
    p.add_argument("--jitter", type=float, default=1.5)
    args = p.parse_args(argv)
    corpus = common.SHARED / "realworld" / "cases"
    print(f"| emoji | start | resvg PSNR of the start | after refine ({args.iterations} it.) | time |")
    print("|---|---|---:|---:|---:|")
    for name, label in CASES.items():
        svg = corpus / f"{name}.svg"
        target_png = corpus / f"{name}.png"
        target = common.resvg_rgb(svg, 256)
        for start_name, text in (("the file", svg.read_text()), (f"jittered {args.jitter:g} px",
                                                                 jittered(svg, args.jitter))):
            with tempfile.TemporaryDirectory() as tmp:
                start_path = Path(tmp) / "start.svg"
                start_path.write_text(text)
                before = psnr(common.resvg_rgb(start_path, 256), target)
                t0 = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    out_text, _ = vecfit.refine(target_png, text, settings={
                        "optimize": {"iterations": args.iterations, "max_size": 256}})
                seconds = time.perf_counter() - t0
                out_path = Path(tmp) / "out.svg"
                out_path.write_text(out_text)
                after = psnr(common.resvg_rgb(out_path, 256), target)
            print(f"| {name} ({label}) | {start_name} | {before:.2f} dB | {after:.2f} dB | {seconds:.1f} s |")


if __name__ == "__main__":
    main()

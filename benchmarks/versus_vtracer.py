"""vecfit beside vtracer: the same images traced by vtracer at its defaults and by `vecfit
trace` without refinement and at each effort (quick, normal, best).

    python benchmarks/versus_vtracer.py [--rows vtracer,trace,quick,normal,best] [--emoji 8,4]
                                        [--photos astronaut,chelsea,coffee,rocket] [--repeats 3]
                                        [--command-rows vtracer,trace,quick] [--threads 2]

The images: Noto and fxemoji SVGs of the shared real-world corpus (../shared/realworld,
its manifest.tsv) rendered by resvg at 512 px wide (RGBA, made here, not kept), and
scikit-image's four photographs. vecfit traces emoji with 64 paths and photos with its
default budget (1,000). Columns: PSNR of the written SVG rendered by resvg over white
against the image over white (float RGB, data range 1); the shapes and the cubic segments
in it (as vecfit reads it); its size in bytes; the time in-process (vtracer's
``convert_raw_image_to_svg`` on the PNG's bytes, ``vecfit.trace`` on the same bytes) and as
a command in a fresh process (``vecfit trace in.png ...``; vtracer has no command of its
own in its Python package, so ``python -c`` calling ``convert_image_to_svg_py``; only for
--command-rows, as the slow rows' command time is their in-process time plus start-up),
each the median of --repeats runs for rows that take under 5 s, else one run. For vecfit's refining
rows, "refine s" is the report's time after tracing (the optimisation and its renders),
so a faster tracer's total can be read off as its trace time plus this. A row NAME@vt
runs NAME with vecfit's path budget lowered to the number of shapes vtracer wrote for that
image (where that is fewer than vecfit's budget), for the comparison at no more paths.
vtracer comes from the ``bench`` extra (pip install ".[bench]"); this script is not called
vtracer.py, which would shadow the package when run from benchmarks/.
"""
from __future__ import annotations

import argparse
import csv
import io
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from common import SHARED, resvg_rgb, user_environment

USER_ENV = user_environment()  # commands timed byte-compiled, as installed

PHOTOS = ["astronaut", "chelsea", "coffee", "rocket"]
ROWS = ["vtracer", "trace", "quick", "normal", "best"]
PHOTO_PATHS = 1000  # vecfit's default budget (configs/trace.toml)
EMOJI_PATHS = 64
EMOJI_WIDTH = 512
SLOW = 5.0  # seconds: rows slower than this are timed once


def emoji_cases(counts: dict[str, int]) -> list[tuple[str, Path]]:
    """(name, SVG) of the first ``counts[set]`` files of each emoji set in the manifest,
    spread over the set (every k-th file) so that one family of glyphs does not fill it."""
    manifest = SHARED / "realworld" / "manifest.tsv"
    with open(manifest, encoding="utf-8") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    out = []
    for prefix, n in counts.items():
        cases = [r for r in rows if r["name"].startswith(prefix + "-")]
        step = max(1, len(cases) // max(n, 1))
        out += [(r["name"], SHARED / "realworld" / r["svg"]) for r in cases[::step][:n]]
    return out


def emoji_png(svg: Path) -> bytes:
    """The emoji rendered by resvg at EMOJI_WIDTH px wide, as PNG bytes (RGBA)."""
    import resvg_py

    return bytes(resvg_py.svg_to_bytes(svg_path=str(svg), width=EMOJI_WIDTH))


def photo_png(name: str) -> bytes:
    import skimage.data
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(getattr(skimage.data, name)()).convert("RGB").save(buffer, format="PNG")
    return buffer.getvalue()


def over_white(png: bytes) -> np.ndarray:
    from PIL import Image

    from vecfit.fitting.metrics import to_rgb

    rgba = np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float64) / 255
    return to_rgb(rgba, (1.0, 1.0, 1.0))


def score(svg_text: str, target_rgb: np.ndarray, folder: Path) -> dict:
    """PSNR by resvg over white, shapes, cubic segments and bytes of an SVG."""
    import warnings

    import vecfit
    from vecfit.fitting.metrics import compare

    path = folder / "scored.svg"
    path.write_text(svg_text, encoding="utf-8")
    theirs = resvg_rgb(path, target_rgb.shape[1])
    if theirs.shape != target_rgb.shape:
        raise RuntimeError(f"resvg rendered {theirs.shape}, the target is {target_rgb.shape}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(path)
    cubics = sum(int((s.geometry.degrees == 3).sum()) for s in scene.shapes if hasattr(s.geometry, "degrees"))
    return {"psnr": compare(theirs, target_rgb)["psnr"], "shapes": len(scene.shapes), "cubics": cubics,
            "bytes": len(svg_text.encode("utf-8"))}


def vecfit_settings(row: str, paths: int | None, threads: int) -> tuple[dict, str | None]:
    settings = {"optimize": {"threads": threads}}
    if paths is not None:
        settings["trace"] = {"paths": paths}
    if row == "trace":
        settings["optimize"]["iterations"] = 0
        return settings, None
    return settings, row


def run_in_process(row: str, png: bytes, paths: int | None, threads: int) -> tuple[str, float, dict]:
    """(SVG text, seconds, extra) of one in-process run of ``row``."""
    if row == "vtracer":
        import vtracer

        start = time.perf_counter()
        svg = vtracer.convert_raw_image_to_svg(png, img_format="png")
        return svg, time.perf_counter() - start, {}
    import vecfit

    settings, effort = vecfit_settings(row, paths, threads)
    start = time.perf_counter()
    svg, report = vecfit.trace(png, settings=settings, effort=effort)
    seconds = time.perf_counter() - start
    return svg, seconds, {"trace_s": report["trace"]["seconds"],
                          "refine_s": report["seconds"]["total"] if report["iterations"] else 0.0,
                          "iterations": report["iterations"]}


def command_line(row: str, png_path: Path, out: Path, paths: int | None, threads: int) -> list[str]:
    if row == "vtracer":
        return [sys.executable, "-c", "import sys, vtracer; vtracer.convert_image_to_svg_py(sys.argv[1], sys.argv[2])",
                str(png_path), str(out)]
    vecfit = str(Path(sys.executable).with_name("vecfit"))
    args = [vecfit, "trace", str(png_path), "-o", str(out), "--threads", str(threads), "-q"]
    if paths is not None:
        args += ["--paths", str(paths)]
    args += ["--no-refine"] if row == "trace" else ["--effort", row]
    return args


def run_command(row: str, png_path: Path, paths: int | None, threads: int) -> float:
    out = png_path.with_name(f"{png_path.stem}.{row}.svg")
    start = time.perf_counter()
    subprocess.run(command_line(row, png_path, out, paths, threads), check=True, env=USER_ENV,
                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    return time.perf_counter() - start


def measure(row: str, png: bytes, png_path: Path, paths, threads: int, repeats: int, command: bool,
            folder: Path) -> dict:
    svg, seconds, extra = run_in_process(row, png, paths, threads)
    times = [seconds]
    if seconds < SLOW:
        times += [run_in_process(row, png, paths, threads)[1] for _ in range(repeats - 1)]
    result = {**score(svg, over_white(png), folder), **extra, "seconds": statistics.median(times)}
    if command:
        ctimes = [run_command(row, png_path, paths, threads)]
        if ctimes[0] < SLOW:
            ctimes += [run_command(row, png_path, paths, threads) for _ in range(repeats - 1)]
        result["command_s"] = statistics.median(ctimes)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", default=",".join(ROWS),
                    help=f"of {','.join(ROWS)}, each also as NAME@vt (vtracer's number of paths)")
    ap.add_argument("--emoji", default="8,4", help="Noto and fxemoji files (0,0: none)")
    ap.add_argument("--photos", default=",".join(PHOTOS), help="skimage.data photos ('': none)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--command-rows", default="vtracer,trace,quick",
                    help="rows also timed as a command ('': none)")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    rows = args.rows.split(",")
    noto, fx = (int(n) for n in args.emoji.split(","))
    images = [(name, emoji_png(svg), EMOJI_PATHS) for name, svg in emoji_cases({"noto-emoji": noto, "fxemoji": fx})]
    images += [(name, photo_png(name), None) for name in args.photos.split(",") if name]

    print("| image | row | PSNR dB | shapes | cubics | SVG bytes | in-process s | command s | trace s | refine s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    summary: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for name, png, paths in images:
            png_path = folder / f"{name}.png"
            png_path.write_bytes(png)
            kind = "photo" if paths is None else "emoji"
            vtracer_shapes = None
            for row in rows:
                budget = paths
                if row.endswith("@vt"):
                    if vtracer_shapes is None:
                        vtracer_shapes = score(run_in_process("vtracer", png, None, 1)[0], over_white(png),
                                               folder)["shapes"]
                    budget = min(paths or PHOTO_PATHS, vtracer_shapes)
                r = measure(row.removesuffix("@vt"), png, png_path, budget, args.threads, args.repeats,
                            row in args.command_rows.split(","), folder)
                summary.setdefault((kind, row), []).append(r)
                command_s = f"{r['command_s']:.2f}" if "command_s" in r else "-"
                trace_s = f"{r['trace_s']:.2f}" if "trace_s" in r else "-"
                refine_s = f"{r['refine_s']:.2f}" if "refine_s" in r else "-"
                print(f"| {name} | {row} | {r['psnr']:.2f} | {r['shapes']} | {r['cubics']} | {r['bytes']:,} "
                      f"| {r['seconds']:.2f} | {command_s} | {trace_s} | {refine_s} |", flush=True)
    print("\nper kind and row: PSNR min / median / max, median shapes, median in-process and command s")
    for (kind, row), rs in summary.items():
        p = [r["psnr"] for r in rs]
        cmd = [r["command_s"] for r in rs if "command_s" in r]
        print(f"{kind:6s} {row:8s} {min(p):6.2f} / {statistics.median(p):6.2f} / {max(p):6.2f} dB  "
              f"{statistics.median(r['shapes'] for r in rs):7.0f} shapes  "
              f"{statistics.median(r['seconds'] for r in rs):7.2f} s  "
              f"{statistics.median(cmd) if cmd else float('nan'):7.2f} s (command)")


if __name__ == "__main__":
    main()

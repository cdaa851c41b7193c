"""Line art round trip (issue 38): stroke-drawn icons traced with each --style, and as a scan.

    python benchmarks/lineart.py [--styles fills,strokes,mixed] [--effort quick]
                                 [--half tuned|held-out|all] [--limit N] [--no-vtracer]
                                 [--no-degraded] [--threads 2] [--out lineart.tsv] [--svgs DIR]

The icons: ../shared/lineart (or $VECFIT_SHARED/lineart): 120 Tabler icons, each the
designer's stroke-drawn SVG and its 256 px render over white (the target). The first 60 by
name are the half the strokes were tuned on ("tuned"), the other 60 are held out
("held-out"); --limit N takes the first N of the half. Each icon is traced by
``vecfit.trace`` in-process (after a warm-up trace, so torch's import is not counted) with
each style at --effort, and by vtracer at its defaults where it is importable (the
``bench`` extra). A "scan" row traces the icon degraded as a scan would be (Gaussian blur
sigma 1 px, noise sigma 0.03, JPEG quality 70; seeded) with --style strokes and scores it
against the clean render.

Each written SVG is rendered by resvg over white and scored against the target (PSNR on
RGB, dB); vecfit.svg.stats.design_stats gives its elements (paths, the background rect not
counted), segments and gzip bytes, compared with the designer's as multiples; the
designer's row is scored as vecfit renders it too (16 samples a pixel): what the
difference between the renderers costs the designer's own geometry (resvg's 1x
anti-aliasing: tests/oracles/test_lineart_render.py; no ceiling for a trace, which resvg
scores exactly where its geometry is the designer's). "filled" counts
the elements other than the background that have a fill (0: only strokes). Times are
in-process seconds and in R (benchmarks/machine.py). Prints medians per half and row;
--out writes a row per icon and row (TSV).
"""
from __future__ import annotations

import argparse
import csv
import io
import re
import statistics
import tempfile
import time
import zlib
from pathlib import Path

import numpy as np

from common import SHARED, resvg_rgb

TUNED = 60  # the first 60 icons by name: the strokes were tuned on these
STYLES = ("fills", "strokes", "mixed")
FILLED = re.compile(r'<(path|rect|circle|ellipse|polygon|polyline)\b(?![^>]*id="vecfit-background")'
                    r'(?![^>]*fill="none")[^>]*>')


def cases(half: str, limit: int | None) -> list[tuple[str, Path, Path]]:
    folder = SHARED / "lineart"
    with open(folder / "manifest.tsv", encoding="utf-8") as f:
        rows = sorted(csv.DictReader(f, delimiter="\t"), key=lambda r: r["name"])
    rows = {"tuned": rows[:TUNED], "held-out": rows[TUNED:], "all": rows}[half]
    return [(r["name"], folder / r["svg"], folder / r["png"]) for r in rows[:limit]]


def degraded(png: bytes, seed: int) -> bytes:
    """The render as a scan: Gaussian blur (sigma 1 px), noise (sigma 0.03), JPEG quality 70."""
    import cv2
    from PIL import Image

    rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), np.float32) / 255
    rgb = cv2.GaussianBlur(rgb, (0, 0), 1.0)
    rgb = rgb + np.random.default_rng(seed).normal(0, 0.03, rgb.shape).astype(np.float32)
    out = io.BytesIO()
    Image.fromarray(np.clip(rgb * 255 + 0.5, 0, 255).astype(np.uint8)).save(out, format="JPEG", quality=70)
    return out.getvalue()


def filled_elements(svg: str) -> int:
    """Elements drawn with a fill, the background rect not counted (0: strokes only)."""
    return len(FILLED.findall(svg))


def designer_in_vecfit(svg_path: Path, target: np.ndarray) -> float:
    """PSNR of the designer's file rendered by vecfit (16 samples a pixel) over white against
    the target: resvg's 1x anti-aliasing against vecfit's converged coverage."""
    import warnings

    import vecfit
    from vecfit.fitting.metrics import compare

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = vecfit.load_svg(svg_path)
    rgb = vecfit.render(scene, target.shape[1], target.shape[0], samples=16, background=(1, 1, 1, 1)).numpy()
    return compare(rgb[..., :3].astype(np.float64), target)["psnr"]


def measure(svg: str, target: np.ndarray, folder: Path, designer: dict) -> dict:
    from vecfit.fitting.metrics import compare
    from vecfit.svg.stats import design_stats

    path = folder / "written.svg"
    path.write_text(svg, encoding="utf-8")
    stats = design_stats(svg)
    return {"psnr": compare(resvg_rgb(path, target.shape[1]), target)["psnr"], "paths": stats["paths"],
            "segments": stats["segments"], "gzip_bytes": stats["gzip_bytes"],
            "segments_x": stats["segments"] / max(designer["segments"], 1),
            "gzip_x": stats["gzip_bytes"] / designer["gzip_bytes"], "filled": filled_elements(svg)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--styles", default="fills,strokes", help=f"of {','.join(STYLES)}")
    ap.add_argument("--effort", default="quick", choices=["quick", "normal", "best"])
    ap.add_argument("--half", default="all", choices=["tuned", "held-out", "all"])
    ap.add_argument("--limit", type=int, help="the first N icons of the half")
    ap.add_argument("--no-vtracer", action="store_true")
    ap.add_argument("--no-degraded", action="store_true", help="leave out the scan row")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", type=Path, help="a row per icon and row (TSV)")
    ap.add_argument("--svgs", type=Path, help="keep each written SVG in this folder (NAME.ROW.svg)")
    args = ap.parse_args()

    import vecfit
    from PIL import Image
    from machine import in_r, machine_unit
    from vecfit.svg.stats import design_stats

    styles = [s for s in args.styles.split(",") if s]
    rows = list(styles) + ([] if args.no_degraded else ["scan strokes"])
    if not args.no_vtracer:
        try:
            import vtracer
            rows.append("vtracer")
        except ImportError:
            print("vtracer is not installed (pip install vtracer==0.6.15): its row is left out")
    unit = machine_unit()
    print(f"machine unit R = {unit * 1000:.2f} ms; effort {args.effort}; threads {args.threads}; "
          f"resvg over white at 256 px")
    settings = {"optimize": {"threads": args.threads}}

    def trace(png: bytes, style: str) -> str:
        return vecfit.trace(png, settings=settings, effort=args.effort, style=style)[0]

    trace(degraded(cases("all", 1)[0][2].read_bytes(), 0), "strokes")  # warm-up (torch's import)
    records = []
    if args.svgs:
        args.svgs.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for half in (["tuned", "held-out"] if args.half == "all" else [args.half]):
            for name, svg_path, png_path in cases(half, args.limit):
                png = png_path.read_bytes()
                target = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), np.float64) / 255
                designer = design_stats(svg_path.read_text(encoding="utf-8"))
                records.append({"half": half, "name": name, "row": "designer", "psnr": float("inf"),
                                "paths": designer["paths"], "segments": designer["segments"],
                                "gzip_bytes": designer["gzip_bytes"], "segments_x": 1.0, "gzip_x": 1.0,
                                "filled": 0, "seconds": None})
                # the designer's own file in vecfit's renderer: resvg's 1x anti-aliasing, measured
                records.append({**records[-1], "row": "designer, vecfit's render",
                                "psnr": designer_in_vecfit(svg_path, target)})
                for row in rows:
                    start = time.perf_counter()
                    try:
                        if row == "vtracer":
                            written = vtracer.convert_raw_image_to_svg(png, img_format="png")
                        elif row == "scan strokes":
                            written = trace(degraded(png, zlib.crc32(name.encode())), "strokes")
                        else:
                            written = trace(png, row)
                        seconds = time.perf_counter() - start
                        r = {**measure(written, target, folder, designer), "seconds": seconds}
                        if args.svgs:
                            (args.svgs / f"{name}.{row.replace(' ', '-')}.svg").write_text(written, encoding="utf-8")
                    except Exception as e:  # one icon's failure is reported, not the end of the run
                        print(f"FAILED {name} {row}: {type(e).__name__}: {e}")
                        r = {"error": f"{type(e).__name__}: {e}"}
                    records.append({"half": half, "name": name, "row": row, **r})
                    if "error" not in r:
                        print(f"  {half} {name} {row}: {r['psnr']:.2f} dB, {r['segments']} segments "
                              f"({designer['segments']}), {r['gzip_bytes']} gzip ({designer['gzip_bytes']}), "
                              f"{r['filled']} filled, {r['seconds']:.2f} s", flush=True)
    print_tables(records, ["designer", "designer, vecfit's render"] + rows, unit, in_r)
    if args.out:
        keys = ["half", "name", "row", "psnr", "paths", "segments", "segments_x", "gzip_bytes", "gzip_x",
                "filled", "seconds", "error"]
        with open(args.out, "w", encoding="utf-8", newline="") as f:
            w = csv.DictWriter(f, keys, delimiter="\t", extrasaction="ignore")
            w.writeheader()
            w.writerows(records)


def print_tables(records, rows, unit, in_r) -> None:
    for half in dict.fromkeys(r["half"] for r in records):
        print(f"\n{half} ({len({r['name'] for r in records if r['half'] == half})} icons): medians")
        print("| row | PSNR dB | elements | segments | segments x | gzip bytes | gzip x | strokes only | time |")
        print("|---|---|---|---|---|---|---|---|---|")
        for row in rows:
            done = [r for r in records if r["half"] == half and r["row"] == row and "error" not in r]
            failed = sum(1 for r in records if r["half"] == half and r["row"] == row and "error" in r)
            if not done:
                continue

            def med(key):
                values = [r[key] for r in done if r.get(key) is not None]
                return statistics.median(values) if values else None
            seconds = med("seconds")
            only = sum(1 for r in done if r["filled"] == 0)
            print(f"| {row}{f' ({failed} failed)' if failed else ''} | "
                  f"{'exact' if row == 'designer' else format(med('psnr'), '.2f')} | {med('paths'):.0f} | "
                  f"{med('segments'):.0f} | {med('segments_x'):.2f} | {med('gzip_bytes'):.0f} | "
                  f"{med('gzip_x'):.2f} | {only}/{len(done)} | {'-' if seconds is None else in_r(seconds, unit)} |")


if __name__ == "__main__":
    main()

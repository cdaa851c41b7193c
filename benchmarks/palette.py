"""The user's colours (issue 39): palettes, background removal and alpha, measured.

    python benchmarks/palette.py [--sections own,photos,emoji,background,alpha] [--limit 6]
                                 [--width 512] [--effort quick|normal|best] [--threads 2]
                                 [--photo-paths 1000] [--names flags-002,logos-005] [--json out.json]

Sections (each a table; every PSNR is resvg's render of the written SVG against the target,
on RGB over white unless said):
- own: flat flags and logos of ../shared/realworld (no gradients, masks, filters, opacity
  or patterns; at most 8 colours), rendered by resvg --width px wide over white. Traced
  free, then with --palette set to the file's own colours (and white). Target: within
  0.5 dB of the free trace, every paint from the palette.
- photos: skimage's astronaut, chelsea, coffee and rocket at their own size, 1,000 paths:
  `--colors 8 --no-refine` (the floor: today's 8-colour trace, whose regions keep their own
  mean colours, so it writes more than 8), then --palette auto:8. Target: at most 8
  colours, 26 dB mean.
- emoji: Noto emoji over white, --palette auto:16. Target: 38 dB, at most 16 colours.
- background: flat logos whose render leaves a fifth of the canvas or more clear,
  rendered over a flat colour (#2a9d8f), traced with and without --remove-background;
  PSNR over that colour, and the largest alpha the removed trace draws on the pixels
  the logo leaves clear, 2 px in from their edge (0: no shape covers them). Target:
  within 0.5 dB.
- alpha: emoji and logos rendered with transparency (RGBA targets), traced free; PSNR of
  the render, alpha included, over white and over black. Target: 35 dB both.

--names keeps only the cases named (each section still picks its own kind: flat, with a
clear fifth, ...), in place of --limit's even spread. Times are in-process seconds of
vecfit.trace and in R (benchmarks/machine.py), measured in the same run.
"""
from __future__ import annotations

import argparse
import csv
import io
import json
import re
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from common import SHARED, resvg_rgb

SECTIONS = ["own", "photos", "emoji", "background", "alpha"]
PHOTOS = ["astronaut", "chelsea", "coffee", "rocket"]
PAGE = "#2a9d8f"
NOT_FLAT = re.compile(r"Gradient|<mask|<filter|<pattern|opacity|<image", re.I)
NAMES: set[str] = set()  # --names: only these cases


def cases(prefixes, limit: int, flat: bool = False) -> list[tuple[str, Path]]:
    folder = SHARED / "realworld"
    with open(folder / "manifest.tsv", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f, delimiter="\t") if r["name"].split("-")[0] in prefixes
                or any(r["name"].startswith(p + "-") for p in prefixes)]
    out = []
    for r in rows:
        svg = folder / r["svg"]
        if flat:
            from vecfit.jobs.palette import written_colours
            if NOT_FLAT.search(svg.read_text(encoding="utf-8")) or len(written_colours(svg.read_bytes())) > 8:
                continue
        out.append((r["name"], svg))
    if NAMES:
        return [c for c in out if c[0] in NAMES]
    step = max(1, len(out) // max(limit, 1))
    return out[::step][:limit]


def transparent_cases(prefixes, limit: int, width: int) -> list[tuple[str, Path]]:
    """Flat cases whose render leaves at least a fifth of the canvas clear (a logo that
    draws its own page has no background to remove)."""
    out = [(n, svg) for n, svg in cases(prefixes, 10 * limit, flat=True)
           if (rgba(render_png(svg, width, None))[..., 3] < 0.01).mean() >= 0.2]
    return out[:limit]


def render_png(svg: Path, width: int, background: str | None) -> bytes:
    import resvg_py
    kwargs = {"background": background} if background else {}
    return bytes(resvg_py.svg_to_bytes(svg_path=str(svg), width=width, **kwargs))


def rgba(png: bytes) -> np.ndarray:
    from PIL import Image
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"), np.float64) / 255


def over(image: np.ndarray, colour) -> np.ndarray:
    a = image[..., 3:4]
    return image[..., :3] * a + np.asarray(colour, np.float64)[:3] * (1 - a)


def hex_rgb(text: str) -> tuple:
    return tuple(int(text[i:i + 2], 16) / 255 for i in (1, 3, 5))


def trace(png: bytes, settings: dict, effort: str, threads: int) -> tuple[str, float]:
    import vecfit
    settings = {**settings, "optimize": {"threads": threads, **settings.get("optimize", {})}}
    refine = settings["optimize"].get("iterations", 1) != 0
    start = time.perf_counter()
    svg, _ = vecfit.trace(png, settings=settings, effort=effort if refine else None)
    return svg, time.perf_counter() - start


def measured(svg: str, target: np.ndarray, folder: Path, backgrounds=((1.0, 1.0, 1.0),)) -> dict:
    """PSNR of resvg's render over each background (alpha included) and design_stats."""
    from vecfit.fitting.metrics import compare
    from vecfit.svg.stats import design_stats

    path = folder / "written.svg"
    path.write_text(svg, encoding="utf-8")
    import resvg_py
    drawn = rgba(bytes(resvg_py.svg_to_bytes(svg_path=str(path), width=target.shape[1])))
    scores = [compare(over(drawn, b), over(target, b))["psnr"] for b in backgrounds]
    return {**design_stats(svg), "psnr": scores[0], "psnrs": scores, "drawn": drawn}


def row(section, name, variant, m, seconds, unit, **extra) -> dict:
    return {"section": section, "name": name, "variant": variant, "psnr": m["psnr"],
            "colours": m["colours"], "paths": m["paths"], "segments": m["segments"],
            "gzip_bytes": m["gzip_bytes"], "seconds": seconds, "R": seconds / unit, **extra}


def section_own(args, unit, folder):
    from vecfit.jobs.palette import written_colours
    out = []
    for name, svg in cases(["flags", "logos"], args.limit, flat=True):
        png = render_png(svg, args.width, "#ffffff")
        target = rgba(png)
        own = sorted(set(written_colours(svg.read_bytes())) | {"#ffffff"})
        free, t0 = trace(png, {}, args.effort, args.threads)
        m0 = measured(free, target, folder)
        pal, t1 = trace(png, {"optimize": {"palette": ",".join(own)}}, args.effort, args.threads)
        m1 = measured(pal, target, folder)
        on = set(written_colours(pal.encode())) <= set(own)
        out += [row("own", name, "free", m0, t0, unit),
                row("own", name, f"palette ({len(own)})", m1, t1, unit, on_palette=on,
                    gap_db=m1["psnr"] - m0["psnr"])]
    return out


def section_photos(args, unit, folder):
    import skimage.data
    from PIL import Image
    out = []
    for name in [n for n in PHOTOS if n in NAMES] if NAMES else PHOTOS[:args.limit]:
        buffer = io.BytesIO()
        Image.fromarray(getattr(skimage.data, name)()).convert("RGB").save(buffer, format="PNG")
        png = buffer.getvalue()
        target = rgba(png)
        base = {"trace": {"paths": args.photo_paths}}
        floor, t0 = trace(png, {"trace": {"paths": args.photo_paths, "colors": 8}, "optimize": {"iterations": 0}},
                          args.effort, args.threads)
        auto, t1 = trace(png, {**base, "optimize": {"palette": "auto:8"}}, args.effort, args.threads)
        out += [row("photos", name, "--colors 8 --no-refine", measured(floor, target, folder), t0, unit),
                row("photos", name, "auto:8", measured(auto, target, folder), t1, unit)]
    return out


def section_emoji(args, unit, folder):
    out = []
    for name, svg in cases(["noto"], args.limit):
        png = render_png(svg, args.width, "#ffffff")
        svg_text, t = trace(png, {"optimize": {"palette": "auto:16"}}, args.effort, args.threads)
        out.append(row("emoji", name, "auto:16", measured(svg_text, rgba(png), folder), t, unit))
    return out


def section_background(args, unit, folder):
    out = []
    page = hex_rgb(PAGE)
    for name, svg in transparent_cases(["logos"], args.limit, args.width):
        clear = rgba(render_png(svg, args.width, None))[..., 3] < 0.01
        png = render_png(svg, args.width, PAGE)
        target = rgba(png)
        kept, t0 = trace(png, {}, args.effort, args.threads)
        m0 = measured(kept, target, folder, (page,))
        gone, t1 = trace(png, {"trace": {"remove_background": True}}, args.effort, args.threads)
        m1 = measured(gone, target, folder, (page,))
        # the logo's clear pixels, 2 px away from anything it draws
        import cv2
        far = cv2.erode(clear.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0
        covered = float(m1["drawn"][..., 3][far].max()) if far.any() else 0.0
        out += [row("background", name, "kept", m0, t0, unit),
                row("background", name, "removed", m1, t1, unit, gap_db=m1["psnr"] - m0["psnr"],
                    alpha_on_page=covered)]
    return out


def section_alpha(args, unit, folder):
    out = []
    for name, svg in cases(["noto", "logos"], args.limit, flat=False)[:args.limit]:
        png = render_png(svg, args.width, None)
        target = rgba(png)
        if target[..., 3].min() > 0.99:
            continue
        svg_text, t = trace(png, {}, args.effort, args.threads)
        m = measured(svg_text, target, folder, ((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)))
        out.append(row("alpha", name, "free", m, t, unit, psnr_black=m["psnrs"][1]))
    return out


def fmt(v, spec):
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "yes" if v else "NO"
    return format(v, spec)


def print_table(rows):
    if not rows:
        return
    extra = [k for k in ("gap_db", "on_palette", "psnr_black", "alpha_on_page") if any(k in r for r in rows)]
    head = ["name", "variant", "PSNR dB", "colours", "paths", "segments", "gzip B", "s", "R", *extra]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for r in rows:
        cells = [r["name"], r["variant"], fmt(r["psnr"], ".2f"), str(r["colours"]), str(r["paths"]),
                 str(r["segments"]), str(r["gzip_bytes"]), fmt(r["seconds"], ".1f"), fmt(r["R"], ".0f")]
        cells += [fmt(r.get(k), ".2f" if k != "on_palette" else "") for k in extra]
        print("| " + " | ".join(cells) + " |")
    by = {}
    for r in rows:
        by.setdefault(r["variant"].split(" (")[0], []).append(r)
    for variant, rs in by.items():
        print(f"mean {variant}: PSNR {statistics.mean(r['psnr'] for r in rs):.2f} dB, colours max "
              f"{max(r['colours'] for r in rs)}, {statistics.mean(r['seconds'] for r in rs):.1f} s")
    print()


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--sections", default=",".join(SECTIONS))
    p.add_argument("--limit", type=int, default=6)
    p.add_argument("--width", type=int, default=512)
    p.add_argument("--effort", default="normal", choices=["quick", "normal", "best"])
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--photo-paths", type=int, default=1000)
    p.add_argument("--names", default="", help="comma-separated case names, instead of --limit's spread")
    p.add_argument("--json")
    args = p.parse_args()
    NAMES.update(n for n in args.names.split(",") if n)
    from machine import machine_unit
    unit = machine_unit(repeats=5)
    print(f"machine unit R: {unit * 1000:.1f} ms; effort {args.effort}; width {args.width}\n")
    everything = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.sections.split(","):
            rows = globals()[f"section_{name}"](args, unit, Path(tmp))
            print(f"## {name}")
            print_table(rows)
            everything += rows
    if args.json:
        Path(args.json).write_text(json.dumps(everything, indent=1, default=float))


if __name__ == "__main__":
    main()

"""The round trip of issue 37 ("vectors a designer keeps"): designers' SVGs rendered, traced
back at the designer's number of paths, and the traced file compared with the designer's.

    python benchmarks/roundtrip.py [--sets noto-emoji,fxemoji,flags,logos,devicon,vscode-icons,
                                           fontawesome,tabler] [--limit 10 | --names NAME,... | --folder DIR]
                                   [--effort quick|normal|best] [--no-refine] [--rows vecfit,vtracer]
                                   [--threads 2] [--simplify DB] [--style fills|strokes|mixed]
                                   [--stacking cutouts [--gap-filler]]
                                   [--json out.json] [--verbose]

The files: the shared real-world corpus (../shared/realworld, its manifest.tsv; sets by name
prefix) and the line art (../shared/lineart, tabler-*), --limit files a set spread over it
(every k-th). Each is rendered by resvg at 512 px wide over white (the target), traced by
``vecfit.trace`` with the path budget set to the designer's number of drawn elements
(vecfit.svg.stats.design_stats; over an opaque image vecfit adds its backdrop, a
full-canvas rect, which the budget does not count and the paths column does) at --effort,
or not refined with --no-refine; and by vtracer at its defaults when it is importable (the
``bench`` extra: pip install vtracer==0.6.15). Each written SVG is rendered by resvg over
white and scored against the target (PSNR, dB, on RGB), and its design_stats compared with
the designer's: segments and gzip bytes as multiples of the designer's, colours,
translucent paints, crossed outlines, paths, and the seconds the tracer took in-process
(vecfit's first run is preceded by a warm-up trace, so torch's import is not counted).

With --stacking cutouts a row "cutouts" follows vecfit's: the same trace rewritten as pieces
that do not overlap (vecfit/initial/tracer/cutouts.py, what ``--stacking cutouts`` writes),
its seconds those of the rewriting alone.

Per set, a table of medians (PSNR, paths, segments x, gzip x, colours, seconds) and sums
(translucent paints, crossed outlines), the designer's own files first; --verbose adds a
row per file, --json writes every file's numbers.
"""
from __future__ import annotations

import argparse
import csv
import functools
import io
import json
import statistics
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

from common import ROOT, SHARED, resvg_rgb

SETS = ["noto-emoji", "fxemoji", "flags", "logos", "devicon", "vscode-icons", "fontawesome", "tabler"]
ROWS = ["vecfit", "vtracer"]
WIDTH = 512
WHITE = "#ffffff"


@functools.lru_cache(maxsize=None)
def _manifest(folder: Path) -> tuple[dict, ...]:
    """The rows of a shared corpus's manifest.tsv (read once a run)."""
    with open(folder / "manifest.tsv", encoding="utf-8") as f:
        return tuple(csv.DictReader(f, delimiter="\t"))


def _folder(name: str) -> Path:
    return SHARED / ("lineart" if name.startswith("tabler") else "realworld")


def manifest_cases(prefix: str, limit: int) -> list[tuple[str, Path]]:
    """(name, SVG) of ``limit`` files of one set, every k-th of the manifest's so that one
    family of glyphs does not fill it."""
    folder = _folder(prefix)
    rows = [r for r in _manifest(folder) if r["name"].startswith(prefix + "-")]
    step = max(1, len(rows) // max(limit, 1))
    return [(r["name"], folder / r["svg"]) for r in rows[::step][:limit]]


def named_cases(names: list[str]) -> list[tuple[str, Path]]:
    """(name, SVG) of the named files of the shared corpus (realworld or lineart)."""
    cases = []
    for name in names:
        folder = _folder(name)
        found = [r for r in _manifest(folder) if r["name"] == name]
        if not found:
            raise SystemExit(f"roundtrip.py: no file named {name} in {folder / 'manifest.tsv'}")
        cases.append((name, folder / found[0]["svg"]))
    return cases


def target_png(svg: Path) -> bytes:
    """The designer's file rendered by resvg at WIDTH px wide over white (opaque PNG)."""
    import resvg_py

    return bytes(resvg_py.svg_to_bytes(svg_path=str(svg), width=WIDTH, background=WHITE))


def png_rgb(png: bytes) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), np.float64) / 255


def run_vecfit(png: bytes, paths: int, effort: str, refine: bool, threads: int, simplify: float | None = None,
               style: str = "fills") -> str:
    import vecfit

    settings = {"trace": {"paths": max(1, paths), "style": style}, "optimize": {"threads": threads}}
    if simplify is not None:
        settings["optimize"]["simplify"] = simplify
    if not refine:
        settings["optimize"]["iterations"] = 0
    svg, _ = vecfit.trace(png, settings=settings, effort=effort if refine else None)
    return svg


def run_cutouts(svg: str, width: int, height: int, gap_filler: bool) -> str:
    from vecfit.initial.tracer.cutouts import cut_out

    return cut_out(svg.encode("utf-8"), (width, height), gap_filler=gap_filler)[0].decode("utf-8")


def run_vtracer(png: bytes) -> str:
    import vtracer

    return vtracer.convert_raw_image_to_svg(png, img_format="png")


def measure(svg_text: str, target: np.ndarray, folder: Path, designer: dict) -> dict:
    """The written SVG's PSNR against the target and its design_stats beside the designer's."""
    from vecfit.fitting.metrics import compare
    from vecfit.svg.stats import design_stats

    path = folder / "written.svg"
    path.write_text(svg_text, encoding="utf-8")
    rendered = resvg_rgb(path, target.shape[1])
    if rendered.shape != target.shape:
        raise RuntimeError(f"resvg rendered {rendered.shape}, the target is {target.shape}")
    stats = design_stats(svg_text)
    return {**stats, "psnr": compare(rendered, target)["psnr"],
            "segments_x": stats["segments"] / max(designer["segments"], 1),
            "gzip_x": stats["gzip_bytes"] / designer["gzip_bytes"]}


def warm_up(args) -> None:
    """One small trace, so that the first file's time is not torch's import."""
    from PIL import Image

    image = Image.new("RGB", (64, 64), "white")
    image.paste((200, 30, 30), (16, 16, 48, 48))
    buffer = io.BytesIO()
    image.save(buffer, format="PNG")
    run_vecfit(buffer.getvalue(), 4, args.effort, not args.no_refine, args.threads)


def machine_note() -> str | None:
    """This machine's speed unit, where benchmarks/machine.py provides one."""
    if not (ROOT / "benchmarks" / "machine.py").exists():
        return None
    from machine import machine_unit

    return str(machine_unit())


def summarise(records: list[dict]) -> dict:
    """Medians and sums of one set's rows (failed files left out, and counted)."""
    done = [r for r in records if "error" not in r]

    def median(key):
        values = [r[key] for r in done if r.get(key) is not None]
        return statistics.median(values) if values else float("nan")

    return {"files": len(done), "failed": len(records) - len(done), "psnr": median("psnr"),
            "paths": median("paths"), "segments": median("segments"), "segments_x": median("segments_x"),
            "gzip_bytes": median("gzip_bytes"), "gzip_x": median("gzip_x"), "colours": median("colours"),
            "translucent_paints": sum(r["translucent_paints"] for r in done),
            "crossed_outlines": sum(r["crossed_outlines"] for r in done), "seconds": median("seconds")}


def fmt(value, spec: str) -> str:
    return "-" if value is None or (isinstance(value, float) and np.isnan(value)) else format(value, spec)


def print_set(name: str, summaries: dict) -> None:
    print(f"\n{name}")
    print("| row | files | PSNR dB | paths | segments | segments x | gzip bytes | gzip x | colours "
          "| translucent | crossed | seconds |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for row, s in summaries.items():
        failed = f" ({s['failed']} failed)" if s["failed"] else ""
        print(f"| {row} | {s['files']}{failed} | {fmt(s['psnr'], '.2f')} | {fmt(s['paths'], '.0f')} "
              f"| {fmt(s['segments'], '.0f')} | {fmt(s['segments_x'], '.2f')} | {fmt(s['gzip_bytes'], ',.0f')} "
              f"| {fmt(s['gzip_x'], '.2f')} | {fmt(s['colours'], '.0f')} | {s['translucent_paints']} "
              f"| {s['crossed_outlines']} | {fmt(s['seconds'], '.2f')} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", default=",".join(SETS), help=f"of {','.join(SETS)}")
    ap.add_argument("--limit", type=int, default=10, help="files per set")
    ap.add_argument("--names", help="these files only (comma-separated manifest names), each in its set")
    ap.add_argument("--folder", type=Path, help="the SVG files of this folder instead of the shared sets (a set named by it)")
    ap.add_argument("--effort", default="normal", choices=["quick", "normal", "best"])
    ap.add_argument("--no-refine", action="store_true", help="vecfit's trace as it is, not refined")
    ap.add_argument("--rows", default=",".join(ROWS), help="vecfit, vtracer (vtracer where importable)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--style", choices=["fills", "strokes", "mixed"], default="fills",
                    help="vecfit's --style (mixed: fills under strokes for line work)")
    ap.add_argument("--simplify", type=float, default=None,
                    help="optimize.simplify, the node pass's budget in dB (0: off; default: trace's)")
    ap.add_argument("--stacking", choices=["stacked", "cutouts"], default="stacked",
                    help="vecfit's output: stacked shapes, or cut-outs (the stacked row is then added beside)")
    ap.add_argument("--gap-filler", action="store_true", help="cut-outs: with the gap filler")
    ap.add_argument("--json", type=Path, help="write every file's numbers here")
    ap.add_argument("--verbose", action="store_true", help="a row per file")
    args = ap.parse_args()
    rows = [r for r in args.rows.split(",") if r]
    if args.stacking == "cutouts" and "vecfit" in rows:  # beside the stacked trace it is cut from
        rows.insert(rows.index("vecfit") + 1, "cutouts")
    if "vtracer" in rows:
        try:
            import vtracer  # noqa: F401
        except ImportError:
            print("vtracer is not installed (pip install vtracer==0.6.15): its row is left out")
            rows.remove("vtracer")
    from vecfit.svg.stats import design_stats

    unit = machine_note()
    if unit is not None:
        print(f"machine unit: {unit}")
    print(f"effort: {'trace, not refined' if args.no_refine else args.effort}; style {args.style}; threads {args.threads}; "
          f"{WIDTH} px over white")
    if args.style != "fills" and args.stacking == "cutouts":
        ap.error("cut-outs are filled pieces: --stacking cutouts needs --style fills")
    if "vecfit" in rows:
        warm_up(args)
    results: dict = {"effort": None if args.no_refine else args.effort, "threads": args.threads, "width": WIDTH,
                     "machine_unit": unit, "files": [], "sets": {}}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for set_name in ([args.folder.name] if args.folder else args.sets.split(",")):
            per_row: dict = {"designer": []}
            if args.folder:
                cases = [(svg.stem, svg) for svg in sorted(args.folder.glob("*.svg"))]
            elif args.names:
                cases = [case for case in named_cases(args.names.split(",")) if case[0].startswith(set_name + "-")]
            else:
                cases = manifest_cases(set_name, args.limit)
            for name, svg in cases:
                designer = {**design_stats(svg), "psnr": None, "segments_x": 1.0, "gzip_x": 1.0, "seconds": None}
                per_row["designer"].append(designer)
                png = target_png(svg)
                target = png_rgb(png)
                record = {"name": name, "set": set_name, "designer": designer}
                stacked = None  # vecfit's trace of this file, which the cutouts row cuts
                for row in rows:
                    start = time.perf_counter()
                    try:
                        if row == "cutouts":  # the stacked row's trace as cut-outs (what --stacking cutouts writes)
                            if stacked is None:
                                raise RuntimeError("no stacked trace to cut")
                            written = run_cutouts(stacked, target.shape[1], target.shape[0], args.gap_filler)
                        else:
                            written = (run_vecfit(png, designer["paths"], args.effort, not args.no_refine, args.threads,
                                                  args.simplify, args.style)
                                       if row == "vecfit" else run_vtracer(png))
                            if row == "vecfit":
                                stacked = written
                        seconds = time.perf_counter() - start
                        record[row] = {**measure(written, target, folder, designer), "seconds": seconds}
                    except Exception as e:  # one file's failure is reported, not the end of the run
                        record[row] = {"error": f"{type(e).__name__}: {e}"}
                        print(f"FAILED {name} {row}: {record[row]['error']}")
                        if args.verbose:
                            traceback.print_exc()
                    per_row.setdefault(row, []).append(record[row])
                    if args.verbose and "error" not in record[row]:
                        r = record[row]
                        print(f"  {name} {row}: {r['psnr']:.2f} dB, {r['paths']} paths "
                              f"({designer['paths']}), {r['segments']} segments ({designer['segments']}), "
                              f"{r['gzip_bytes']:,} gzip bytes ({designer['gzip_bytes']:,}), {r['colours']} colours, "
                              f"{r['translucent_paints']} translucent, {r['crossed_outlines']} crossed, "
                              f"{r['seconds']:.2f} s", flush=True)
                results["files"].append(record)
            summaries = {row: summarise(records) for row, records in per_row.items()}
            results["sets"][set_name] = summaries
            print_set(set_name, summaries)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1, default=float), encoding="utf-8")


if __name__ == "__main__":
    main()

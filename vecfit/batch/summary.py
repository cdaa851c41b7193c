"""The run summary in OUT_DIR: summary.csv, summary.json, and index.html with thumbnails
(thumbs/) of each target and result, viewable offline. Every file is written atomically."""
from __future__ import annotations

import csv
import html
import io
import math
import warnings
from pathlib import Path
from urllib.parse import quote

from PIL import Image

from vecfit.io.files import atomic_write, atomic_write_text
from vecfit.io.orientation import upright_rgba
from vecfit.io.report import GAP, save_report

from .plan import DONE, FILE_COUNTS, INTERRUPTED, NOT_RUN, ROW_FIELDS, SKIPPED, STATUSES

THUMB = 160  # longest side of a thumbnail, pixels
THUMBS = "thumbs"
SUMMARY_FILES = ("summary.csv", "summary.json", "index.html")


def write_csv(path: Path, rows: list[dict]) -> None:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(ROW_FIELDS)
    for row in rows:
        w.writerow(["" if row.get(k) is None else
                    (repr(row[k]) if isinstance(row[k], float) else row[k]) for k in ROW_FIELDS])
    atomic_write_text(path, buf.getvalue())


def write_json(path: Path, meta: dict, rows: list[dict]) -> None:
    save_report(path, {**meta, "images": rows})  # (non-finite numbers, e.g. a perfect PSNR, as null)


# ------------------------------------------------------------------- thumbnails

def _fresh(thumb: Path, source: Path) -> bool:
    try:
        return thumb.stat().st_mtime >= source.stat().st_mtime
    except OSError:
        return False


def _save_thumb(im: Image.Image, path: Path) -> None:
    im = im.copy()
    im.thumbnail((THUMB, THUMB), Image.LANCZOS)
    atomic_write(path, lambda tmp: im.save(tmp, format="PNG"))


def _target_thumb(image: Path, path: Path) -> bool:
    if _fresh(path, image):
        return True
    try:
        with Image.open(image) as im, warnings.catch_warnings():
            warnings.simplefilter("ignore")  # (the job has warned of a broken EXIF block)
            rgba, _ = upright_rgba(im, str(image))  # as the job read it
    except Exception:  # a corrupt image has no thumbnail
        return False
    flat = Image.new("RGBA", rgba.size, (255, 255, 255, 255))
    flat.alpha_composite(rgba)
    _save_thumb(flat.convert("RGB"), path)
    return True


def _result_thumb(comparison: Path, path: Path) -> bool:
    """The third panel (the optimised result) of the comparison picture, which is
    target | initial | optimised | error map with GAP pixels between them."""
    if _fresh(path, comparison):
        return True
    try:
        with Image.open(comparison) as im:
            im.load()
            w, h = im.size
            panel = (w - 3 * GAP) // 4
            if panel < 1:
                return False
            x = 2 * (panel + GAP)
            result = im.convert("RGB").crop((x, 0, x + panel, h))
    except Exception:
        return False
    _save_thumb(result, path)
    return True


def make_thumbs(out_dir: Path, in_dir: Path, rows: list[dict]) -> None:
    """thumbs/NAME.target.png and thumbs/NAME.result.png; names each row's thumbnails
    (relative to out_dir) in row["thumbs"]."""
    names = [r["name"] for r in rows]
    for row in rows:
        row["thumbs"] = {"target": None, "result": None}
        if names.count(row["name"]) > 1:
            continue  # colliding names: no thumbnails rather than wrong ones
        target = f"{THUMBS}/{row['name']}.target.png"
        if _target_thumb(in_dir / row["file"], out_dir / target):
            row["thumbs"]["target"] = target
        if row.get("comparison") and row["status"] in (DONE, SKIPPED, INTERRUPTED):
            result = f"{THUMBS}/{row['name']}.result.png"
            if _result_thumb(out_dir / row["comparison"], out_dir / result):
                row["thumbs"]["result"] = result


# ------------------------------------------------------------------------- HTML

_STYLE = """
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse}
th,td{border:1px solid #ccc;padding:4px 8px;vertical-align:middle;text-align:left}
th{background:#f0f0f0}
td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
td.thumb{text-align:center;background:repeating-conic-gradient(#eee 0 25%,#fff 0 50%) 0 0/16px 16px}
img{display:block;max-width:160px;max-height:160px}
tr.failed td.status,tr.unpaired td.status{color:#b00020;font-weight:600}
tr.done td.status{color:#1b5e20;font-weight:600}
tr.interrupted td.status,tr.not-run td.status{color:#8a6d00;font-weight:600}
.reason{max-width:28em;font-size:90%}
"""


def _num(v, digits) -> str:
    if v is None:
        return ""
    if isinstance(v, float) and math.isinf(v):
        return "∞"
    return f"{v:.{digits}f}"


def _pair(row, metric, digits) -> str:
    a, b = row.get(f"{metric}_before"), row.get(f"{metric}_after")
    if a is None and b is None:
        return ""
    return f"{_num(a, digits)} → {_num(b, digits)}"


def _link(href, text) -> str:
    return f'<a href="{html.escape(quote(href), quote=True)}">{html.escape(text)}</a>'


def _img(href, alt) -> str:
    if not href:
        return ""
    return (f'<a href="{html.escape(quote(href), quote=True)}"><img src="{html.escape(quote(href), quote=True)}" '
            f'alt="{html.escape(alt, quote=True)}" loading="lazy"></a>')


def write_html(path: Path, meta: dict, rows: list[dict]) -> None:
    counts = meta["counts"]
    e = html.escape
    parts = [
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
        f"<title>vecfit batch: {e(meta['in_dir'])}</title>", f"<style>{_STYLE}</style></head><body>",
        f"<h1>vecfit batch ({e(meta['mode'])}, effort {e(str(meta.get('effort', 'normal')))})</h1>",
        f"<p>{e(meta['in_dir'])} → {e(meta['out_dir'])}, {len(rows)} images: "
        + ", ".join(f"{n} {e(s)}" for s, n in counts.items() if n)
        + f". {meta['seconds']:.1f} s, {meta['finished_at']}.</p>",
        "<p>Summaries: " + _link("summary.csv", "summary.csv") + ", "
        + _link("summary.json", "summary.json") + ".</p>",
        "<table><thead><tr><th>target</th><th>result</th><th>image</th><th>status</th><th>reason</th>"
        "<th>MSE before → after</th><th>PSNR (dB)</th><th>SSIM</th>"
        "<th>paths / segments / gzip bytes / colours / translucent / crossed</th><th>seconds</th><th>files</th>"
        "</tr></thead><tbody>",
    ]
    for row in rows:
        thumbs = row.get("thumbs") or {}
        links = [_link(row[k], label) for k, label in
                 (("svg", Path(row.get("svg") or "x.svg").suffix[1:].upper()),  # SVG, PDF or DXF
                  ("comparison", "comparison"), ("report", "report")) if row.get(k)]
        reason = row.get("reason") or ""
        if row.get("warnings"):
            reason = "; ".join(filter(None, [reason, *row["warnings"]]))
        parts.append(
            f'<tr class="{e(row["status"].split(" ")[0] if row["status"] != NOT_RUN else "not-run")}">'
            f'<td class="thumb">{_img(thumbs.get("target"), row["file"] + " (target)")}</td>'
            f'<td class="thumb">{_img(thumbs.get("result"), row["file"] + " (result)")}</td>'
            f'<td>{e(row["file"])}' + (f'<br><small>{e(Path(row["init_svg"]).name)}</small>'
                                        if row.get("init_svg") else "") + "</td>"
            f'<td class="status">{e(row["status"])}</td>'
            f'<td class="reason">{e(reason)}</td>'
            f'<td class="num">{_pair(row, "mse", 5)}</td>'
            f'<td class="num">{_pair(row, "psnr", 2)}</td>'
            f'<td class="num">{_pair(row, "ssim", 4)}</td>'
            f'<td class="num">{e(_file_counts(row))}</td>'
            f'<td class="num">{_num(row.get("seconds"), 2)}</td>'
            f'<td>{" ".join(links)}</td></tr>')
    parts += ["</tbody></table>", "</body></html>", ""]
    atomic_write_text(path, "\n".join(parts))


def _file_counts(row: dict) -> str:
    values = [row.get(f"file_{c}") for c in FILE_COUNTS]
    return "" if all(v is None for v in values) else " / ".join("–" if v is None else str(v) for v in values)


def write_all(out_dir: Path, in_dir: Path, meta: dict, rows: list[dict]) -> dict:
    """Thumbnails, summary.csv, summary.json and index.html; returns their paths."""
    make_thumbs(out_dir, in_dir, rows)
    paths = {name: out_dir / name for name in SUMMARY_FILES}
    write_csv(paths["summary.csv"], rows)
    write_json(paths["summary.json"], meta, rows)
    write_html(paths["index.html"], meta, rows)
    return paths


def count(rows: list[dict]) -> dict:
    return {s: sum(r["status"] == s for r in rows) for s in STATUSES}


"""What a batch run has to do: the images of a folder, their SVG pairs (refine, edit), their
outputs, and which of them are finished already (resume).

A finished image is one whose report (written last by every job) exists and says:
the same command, not interrupted, finite metrics, the same settings as now (less
``optimize.threads``, which divides the machine's cores and does not change the result),
for refine and edit the same initial SVG; its SVG and comparison picture exist; and neither the
image nor its initial SVG changed after the report was written.
"""
from __future__ import annotations

import copy
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from vecfit.jobs.protocol import JOB_MODULES, Inputs, Outputs, same_path
from vecfit import names

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp")
SVG_SUFFIXES = (".svg", ".svgz")
MODES = names.JOBS  # batch --mode: the job run on each input
PAIRED = ("refine", "edit")  # modes that pair each image with the SVG of its name
ON_SVGS = ("retarget",)      # modes whose inputs are the SVGs in IN_DIR, not images
# The job function of each mode (vecfit.jobs.protocol), as "module:function", imported
# where the task runs.
JOBS = {mode: f"{JOB_MODULES[mode]}:run" for mode in MODES}

# Statuses of a summary row.
DONE = "done"
SKIPPED = "skipped (finished)"
FAILED = "failed"
UNPAIRED = "unpaired"
INTERRUPTED = "interrupted"
NOT_RUN = "not run"
STATUSES = (DONE, SKIPPED, FAILED, UNPAIRED, INTERRUPTED, NOT_RUN)

METRICS = ("mse", "psnr", "ssim")
# What a designer finds in the written SVG (the report's "file" counts, vecfit/svg/stats.py).
FILE_COUNTS = ("paths", "segments", "gzip_bytes", "colours", "translucent_paints", "crossed_outlines")
ROW_FIELDS = ("name", "file", "status", "reason", "init_svg",
              *[f"{m}_{when}" for m in METRICS for when in ("before", "after")],
              *[f"file_{c}" for c in FILE_COUNTS], "palette", "layers", "split_colours",
              "seconds", "svg", "report", "comparison")


@dataclass
class Task:
    """One image's job; plain data, so it pickles to worker processes and Dask."""
    name: str                  # the image's stem: the outputs are NAME.svg, ...
    file: str                  # the image's file name in IN_DIR
    mode: str
    image: str
    init_svg: str | None
    svg: str
    report: str
    comparison: str
    config: dict
    job: str
    torch_threads: int = 0     # > 0: torch.set_num_threads(this) before the job

    def outputs(self) -> Outputs:
        from vecfit.export import format_for
        return Outputs(Path(self.svg), Path(self.report), Path(self.comparison), format=format_for(self.svg))

    def inputs(self) -> Inputs:
        if self.mode in ON_SVGS:  # the "image" is the SVG to work on
            return Inputs(svg=Path(self.image))
        return Inputs(image=Path(self.image), svg=None if self.init_svg is None else Path(self.init_svg))


@dataclass
class Plan:
    rows: dict = field(default_factory=dict)     # file name -> summary row decided already
    tasks: list = field(default_factory=list)    # Task, in sorted order
    order: list = field(default_factory=list)    # every image's file name, sorted


def find_images(folder: Path) -> list[Path]:
    """The images directly in ``folder`` (not recursive), sorted by file name."""
    return sorted((p for p in folder.iterdir()
                   if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file()),
                  key=lambda p: p.name)


def find_svgs(folder: Path) -> list[Path]:
    """The SVGs directly in ``folder`` (retarget's inputs), sorted by file name."""
    return sorted((p for p in folder.iterdir() if p.suffix.lower() in SVG_SUFFIXES and p.is_file()),
                  key=lambda p: p.name)


def outputs_for(image: Path, out_dir: Path, name: str, fmt: str = "svg") -> Outputs:
    return Outputs.beside(image, out_dir / f"{name}.{fmt}")


def empty_row(name: str, file: str, status: str, reason: str = "", init_svg=None) -> dict:
    row = {k: None for k in ROW_FIELDS}
    row.update(name=name, file=file, status=status, reason=reason,
               init_svg=None if init_svg is None else str(init_svg))
    row.update(iterations=None, shapes=None, orientation=None, warnings=[], traceback=None)  # summary.json only
    return row


def metrics_into(row: dict, report: dict) -> dict:
    """The report's metrics before/after into the row; PSNR of a perfect match is inf
    (the JSON report stores it as null, with an MSE of 0)."""
    for when, key in (("before", "initial"), ("after", "optimized")):
        values = report.get(key) or {}
        for m in METRICS:
            v = values.get(m)
            v = None if v is None else float(v)
            if m == "psnr" and v is None and values.get("mse") == 0:
                v = math.inf
            row[f"{m}_{when}"] = v
    counts = report.get("file") or {}
    for c in FILE_COUNTS:
        row[f"file_{c}"] = counts.get(c)
    colours = report.get("colours") or {}  # --palette, --group-by colour (vecfit/jobs/palette.py)
    layers = colours.get("layers") or {}
    row["palette"] = colours.get("palette")
    row["layers"] = len(layers["layers"]) if layers else None
    row["split_colours"] = len(layers["split"]) if layers else None
    return row


def comparable(config: dict) -> dict:
    """The settings as a report records them (JSON), less optimize.threads and
    optimize.device (neither changes the result beyond rounding)."""
    c = json.loads(json.dumps(config))
    c.get("optimize", {}).pop("threads", None)
    c.get("optimize", {}).pop("device", None)
    return c


def finished_report(task: Task) -> dict | None:
    """The report of ``task``'s earlier run if that run finished with the same settings
    (see the module's docstring), else None."""
    out = task.outputs()
    try:
        report_time = out.report.stat().st_mtime
        with open(out.report, encoding="utf-8") as f:
            report = json.load(f)
    except (OSError, ValueError):
        return None
    if not isinstance(report, dict) or report.get("interrupted") is not False:
        return None
    if report.get("command") != task.mode or not isinstance(report.get("config"), dict):
        return None
    mse = (report.get("optimized") or {}).get("mse")
    if not isinstance(mse, (int, float)) or not math.isfinite(mse):
        return None
    if not (out.svg.is_file() and out.comparison.is_file()) or report.get("format", "svg") != out.format:
        return None
    if comparable(report["config"]) != comparable(task.config):
        return None
    inputs = [Path(task.image)]
    if task.init_svg is not None:
        recorded = report.get("init")
        if recorded is None or not same_path(Path(recorded), Path(task.init_svg)):
            return None
        inputs.append(Path(task.init_svg))
    try:
        if any(p.stat().st_mtime > report_time for p in inputs):
            return None
    except OSError:
        return None
    return report


def _previous_seconds(out_dir: Path) -> dict:
    """file name -> seconds of the images the last summary.json lists as done or skipped."""
    try:
        with open(out_dir / "summary.json", encoding="utf-8") as f:
            images = json.load(f)["images"]
        return {r["file"]: float(r["seconds"]) for r in images
                if r.get("status") in (DONE, SKIPPED) and isinstance(r.get("seconds"), (int, float))}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


def svg_index(folder: Path) -> dict[str, list[Path]]:
    """stem -> the SVG files of that stem in ``folder``."""
    index: dict[str, list[Path]] = {}
    for p in folder.iterdir():
        if p.suffix.lower() in SVG_SUFFIXES and p.is_file():
            index.setdefault(p.stem, []).append(p)
    return index


def make_plan(in_dir: Path, out_dir: Path, mode: str, config: dict, *, init_dir: Path | None = None,
              resume: bool = True, job: str | None = None, torch_threads: int = 0, fmt: str = "svg") -> Plan:
    """The rows decided without running anything (unpaired, colliding names, finished)
    and the tasks left to run."""
    plan = Plan()
    previous = _previous_seconds(out_dir) if resume else {}
    images = find_svgs(in_dir) if mode in ON_SVGS else find_images(in_dir)
    plan.order = [p.name for p in images]
    stems: dict[str, list[Path]] = {}
    for p in images:
        stems.setdefault(p.stem, []).append(p)
    svgs = svg_index(init_dir or in_dir) if mode in PAIRED else {}
    svg_home = init_dir or in_dir
    for image in images:
        name = image.stem
        same = stems[name]
        if len(same) > 1:
            others = ", ".join(p.name for p in same)
            plan.rows[image.name] = empty_row(
                name, image.name, FAILED,
                f"{others} have the same name {name!r}: their outputs would collide (rename all but one)")
            continue
        init_svg = None
        if mode in PAIRED:
            pairs = svgs.get(name, [])
            if not pairs:
                plan.rows[image.name] = empty_row(
                    name, image.name, UNPAIRED, f"no {name}.svg in {svg_home}")
                continue
            if len(pairs) > 1:
                plan.rows[image.name] = empty_row(
                    name, image.name, FAILED,
                    f"several SVGs for {image.name}: {', '.join(sorted(p.name for p in pairs))}")
                continue
            init_svg = pairs[0]
        out = outputs_for(image, out_dir, name, fmt)
        task = Task(name=name, file=image.name, mode=mode, image=str(image),
                    init_svg=None if init_svg is None else str(init_svg), svg=str(out.svg),
                    report=str(out.report), comparison=str(out.comparison),
                    config=copy.deepcopy(config), job=job or JOBS[mode],
                    torch_threads=torch_threads)
        report = finished_report(task) if resume else None
        if report is not None:
            # seconds: what the run that made it took, as the last summary says (the
            # report's own count starts after loading and, for trace, after tracing)
            seconds = previous.get(image.name)
            if seconds is None:
                seconds = (report.get("seconds") or {}).get("total")
            plan.rows[image.name] = result_row(
                task, SKIPPED, report=report, seconds=None if seconds is None else float(seconds))
        else:
            plan.tasks.append(task)
    return plan


def result_row(task: Task, status: str, reason: str = "", report: dict | None = None,
               seconds: float | None = None) -> dict:
    row = empty_row(task.name, task.file, status, reason, task.init_svg)
    row["seconds"] = seconds
    if report is not None:
        metrics_into(row, report)
        out = task.outputs()
        row.update(svg=out.svg.name, report=out.report.name, comparison=out.comparison.name)
        row["iterations"] = report.get("iterations")
        row["shapes"] = report.get("shapes")
        row["orientation"] = report.get("orientation")  # the EXIF orientation the job applied
    return row

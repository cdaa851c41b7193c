"""The jobs from Python: ``vecfit.trace``, ``vecfit.refine``, ``vecfit.paint``,
``vecfit.edit`` and ``vecfit.retarget`` take an image as a path, bytes, a NumPy array or
a PIL image and the SVG as a path or its text,
and return the SVG text and the report. They write nothing unless given ``output`` (then
the SVG there, with its report and comparison picture beside it, as the command does).
Settings are the command's: defaults from configs/, then ``effort`` ("quick", "normal",
"best": the command's ``--effort``), ``preset``, ``config_file`` and ``settings`` (a nested
dict like the TOML files: {"optimize": {"iterations": 50}, "trace": {"paths": 64}})."""
from __future__ import annotations

from pathlib import Path

from .config import resolve
from .protocol import Inputs, Outputs, job_function


def _run(command: str, inputs: Inputs, output, settings, preset, config_file, progress,
         effort) -> tuple[str, dict]:
    config = resolve(command, preset=preset, config_file=config_file, overrides=settings or {}, effort=effort)
    outputs = Outputs.nowhere() if output is None else Outputs.beside(Path(output), output)
    report = job_function(command)(inputs, config, outputs, progress=progress)
    return outputs.text, report


def trace(image, *, output=None, settings: dict | None = None, effort: str | None = None,
          preset: str | None = None, config_file=None, progress=None, style: str | None = None) -> tuple[str, dict]:
    """`vecfit trace` from Python: (SVG text, report). ``style``: "fills", "strokes" or
    "mixed" (the command's ``--style``; None: the settings')."""
    if style is not None:
        settings = {**(settings or {}), "trace": {**(settings or {}).get("trace", {}), "style": style}}
    return _run("trace", Inputs(image=image), output, settings, preset, config_file, progress, effort)


def refine(image, svg, *, output=None, settings: dict | None = None, effort: str | None = None,
           config_file=None, progress=None) -> tuple[str, dict]:
    """`vecfit refine` from Python: ``svg`` (a path, or SVG text) fitted to ``image``."""
    return _run("refine", Inputs(image=image, svg=svg), output, settings, None, config_file, progress, effort)


def paint(image, *, output=None, settings: dict | None = None, effort: str | None = None,
          preset: str | None = None, config_file=None, progress=None) -> tuple[str, dict]:
    """`vecfit paint` from Python: (SVG text, report)."""
    return _run("paint", Inputs(image=image), output, settings, preset, config_file, progress, effort)


def edit(svg, edited, *, mask=None, output=None, settings: dict | None = None, effort: str | None = None,
         config_file=None, progress=None) -> tuple[str, dict]:
    """`vecfit edit` from Python: ``svg`` fitted to ``edited`` (its render, edited), changing
    little outside the edit (``mask``: a PNG path, white where the edit is)."""
    return _run("edit", Inputs(image=edited, svg=svg, mask=mask), output, settings, None, config_file, progress,
                effort)


def retarget(svg, width, height=None, *, output=None, settings: dict | None = None,
             effort: str | None = None, config_file=None, progress=None) -> tuple[str, dict]:
    """`vecfit retarget` from Python: ``svg`` resized to ``width`` (and ``height``), each in
    pixels or a percentage ("70%")."""
    size = {"width": str(width), **({} if height is None else {"height": str(height)})}
    settings = {**(settings or {}), "retarget": {**(settings or {}).get("retarget", {}), **size}}
    return _run("retarget", Inputs(svg=svg), output, settings, None, config_file, progress, effort)

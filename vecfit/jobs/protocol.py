"""The one shape of every job, for the command line, batch and Python alike:

    report = run(inputs, config, outputs, progress)

``inputs`` names the files a job reads (Inputs), ``config`` is the resolved settings
(config.resolve), ``outputs`` the files it writes (Outputs), ``progress`` an optional
listener (Progress) that the job tells how many Adam iterations it will run before it
runs them, then each iteration, and what it is doing. The report is a dict, also written
as JSON last (a report on disk marks a finished run).
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from vecfit.errors import VecfitError
from vecfit.names import JOBS

# The jobs, by command name: each module has run(inputs, config, outputs, progress=None).
JOB_MODULES = {name: f"vecfit.jobs.{name}" for name in JOBS}


def job_function(name: str) -> Callable[..., dict]:
    """The run function of the job called ``name`` (its module imported only now)."""
    return importlib.import_module(JOB_MODULES[name]).run


@dataclass(frozen=True)
class Inputs:
    """The files a job reads. From Python, ``image`` may also be the image itself (bytes of
    a PNG or JPEG, a NumPy array, a PIL image) and ``svg`` the SVG's text."""
    image: object = None  # the target (refine, trace, paint) or the edited render (edit)
    svg: object = None    # the SVG to start from (refine, edit, retarget)
    mask: Path | None = None  # edit: white where the edit is (default: where it differs)

    def __post_init__(self):
        for name in ("image", "svg", "mask"):
            value = getattr(self, name)
            if isinstance(value, str) and not (name == "svg" and value.lstrip().startswith("<")):
                object.__setattr__(self, name, Path(value))
            elif hasattr(value, "__fspath__") and not isinstance(value, Path):
                object.__setattr__(self, name, Path(value))

    def need(self, job: str, *names: str) -> None:
        missing = [n for n in names if getattr(self, n) is None]
        if missing:
            raise VecfitError(f"{job}: no {' and no '.join(missing)} given")

    @property
    def main(self) -> Path:
        """The input file that outputs are named after: the image, else the SVG."""
        return self.image if isinstance(self.image, Path) else self.svg

    def files(self) -> list[Path]:
        return [p for p in (self.image, self.svg, self.mask) if isinstance(p, Path)]

    def name(self, which: str) -> str:
        """How messages name an input: its path, or what it is."""
        value = getattr(self, which)
        return str(value) if isinstance(value, Path) else f"the {which} given"


@dataclass
class Outputs:
    """The files a job writes; None writes nothing there (the Python API writes nothing
    unless asked). ``text`` is set by the job: the SVG it wrote, or would have written.
    ``format``: what ``svg`` is written as, svg, pdf or dxf (vecfit/export/); ``text``
    is the SVG whatever the format."""
    svg: Path | None
    report: Path | None
    comparison: Path | None
    frames: Path | None = None  # paint: a folder for frame_NNNNN.png and a GIF
    text: str | None = None
    format: str = "svg"

    @classmethod
    def nowhere(cls) -> "Outputs":
        return cls(None, None, None)

    def names(self) -> dict:
        """The report's entries naming the outputs (None where nothing is written)."""
        names = {key: None if path is None else str(path)
                 for key, path in (("output", self.svg), ("comparison", self.comparison), ("report", self.report))}
        if self.format != "svg":  # (an SVG's report stays as it was)
            names["format"] = self.format
        return names

    def forget_report(self) -> None:
        """The report marks a finished run: an old one must not sit beside new outputs if
        this run dies before it writes its own."""
        if self.report is not None:
            self.report.unlink(missing_ok=True)

    def keep_report(self, report: dict) -> dict:
        """The job's report, written where asked (last: a report means a finished run);
        returned for the job to return."""
        if self.report is not None:
            from vecfit.io.report import save_report
            save_report(self.report, report)
        return report

    def keep_svg(self, payload: bytes) -> None:
        """The job's SVG (UTF-8 bytes): kept as ``text``, and written where asked, as SVG
        or converted to ``format``."""
        from vecfit.svg.write import write_bytes
        self.text = payload.decode("utf-8")
        if self.svg is None:
            return
        if self.format == "svg":
            write_bytes(self.svg, payload)
        else:
            from vecfit import export
            export.write(self.svg, export.svg_to(payload, self.format))

    @classmethod
    def beside(cls, main: Path, svg: Path | None = None, report: Path | None = None,
               comparison: Path | None = None, frames: Path | None = None,
               format: str | None = None) -> "Outputs":
        """Defaults: NAME.vecfit.svg next to ``main`` (the input outputs are named after);
        the report and the picture take the SVG's name with .report.json and .compare.png.
        ``format`` (svg, pdf, dxf; default: the output's suffix, else svg) names the
        default NAME.vecfit.pdf or .dxf; an output named for another format is refused."""
        from vecfit.export import SUFFIXES, format_for
        main = Path(main)
        fmt = format_for(svg, format)
        svg = Path(svg) if svg else main.with_name(main.stem + f".vecfit.{fmt}")
        stem = svg.with_suffix("") if svg.suffix.lower() in SUFFIXES else svg
        return cls(svg, Path(report) if report else stem.with_name(stem.name + ".report.json"),
                   Path(comparison) if comparison else stem.with_name(stem.name + ".compare.png"),
                   None if frames is None else Path(frames), format=fmt)

    def check_against(self, inputs: Inputs) -> None:
        """Refuses outputs that would overwrite an input or each other."""
        paths = [p for p in (self.svg, self.report, self.comparison) if p is not None]
        for out in paths:
            for src in inputs.files():
                if same_path(out, src):
                    raise VecfitError(f"{out}: output would overwrite the input {src}; choose another name")
        if len({p.resolve() for p in paths}) < len(paths):
            raise VecfitError("the SVG, report and comparison outputs must be different files")


def same_path(a: Path, b: Path) -> bool:
    """Whether two paths name the same file or folder (False when one cannot be resolved)."""
    try:
        return a.resolve() == b.resolve()
    except OSError:
        return False


class Progress:
    """What a job tells its listener; subclass and override what you need. A plain
    callable is accepted too (see ``listener``): it is called per iteration."""

    def start(self, iterations: int) -> None:
        """Before optimising: the Adam iterations the job will run in all."""

    def __call__(self, step) -> None:
        """After each iteration (vecfit.fitting.loop.Progress: iteration, loss, ...)."""

    def status(self, message: str) -> None:
        """A line on what the job is doing (tracing, ...)."""


class _Calls(Progress):
    def __init__(self, function):
        self.function = function

    def __call__(self, step) -> None:
        self.function(step)


def listener(progress) -> Progress:
    """``progress`` as a Progress: None listens to nothing, a plain callable gets the
    iterations."""
    if progress is None:
        return Progress()
    if isinstance(progress, Progress) or all(hasattr(progress, a) for a in ("start", "status")):
        return progress
    return _Calls(progress)

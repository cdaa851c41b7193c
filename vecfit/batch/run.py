"""Running a batch: the plan made, the images handed to an executor, the summary
written, stale temporaries swept; resumable after Ctrl-C or a crash.

The per-image work is the commands' own job functions (vecfit.jobs.protocol: every
job run alike), called by vecfit.batch.work.run_task."""
from __future__ import annotations

import copy
import os
import re
import time
from dataclasses import dataclass, field
from pathlib import Path

from vecfit.errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, VecfitError
from vecfit.jobs.protocol import same_path
from vecfit.names import FORMATS

from .plan import FAILED, INTERRUPTED, MODES, NOT_RUN, PAIRED, UNPAIRED, make_plan, result_row
from .summary import SUMMARY_FILES, THUMBS, count, write_all


class BatchUsageError(VecfitError):
    """A batch that cannot start: the CLI exits with EXIT_USAGE."""


@dataclass
class BatchResult:
    rows: list = field(default_factory=list)   # one per image, in sorted order
    exit_code: int = EXIT_OK
    interrupted: bool = False
    summary: dict = field(default_factory=dict)  # name -> path of summary.csv, ...
    workers: int = 0
    threads: int = 0

    @property
    def counts(self) -> dict:
        return count(self.rows)


def available_cores() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def resolve_config(mode: str, preset: str | None = None, config_file=None, device: str | None = None,
                   size: dict | None = None, effort: str | None = None, colours: dict | None = None,
                   style: str | None = None) -> dict:
    """The command's settings (vecfit.jobs.config.resolve, which also checks the values, the
    device included); BatchUsageError when they are bad. size: retarget's width / height;
    effort: quick, normal or best (None: the config file's, else normal)."""
    from vecfit.jobs.config import resolve

    overrides = {"optimize": {"device": device}}
    if size:
        overrides["retarget"] = size
    colours = colours or {}  # --palette, --group-by, --remove-background, --stacking, --gap-filler
    if colours.get("palette") is not None:
        overrides["optimize"]["palette"] = colours["palette"]
    output = {k: colours[k] for k in ("group_by", "stacking", "gap_filler") if colours.get(k) is not None}
    if output:
        overrides["output"] = output
    if colours.get("remove_background"):
        if mode != "trace":
            raise BatchUsageError("--remove-background is for --mode trace")
        overrides["trace"] = {"remove_background": True}
    if style is not None:  # trace's --style
        if mode != "trace":
            raise BatchUsageError(f"--style is trace's, not {mode}'s")
        overrides.setdefault("trace", {})["style"] = style
    try:
        return resolve(mode, preset=preset, config_file=config_file, overrides=overrides, effort=effort)
    except VecfitError as e:
        raise BatchUsageError(str(e)) from None


_TMP = re.compile(r"^\.(?P<name>.+)\.[A-Za-z0-9_]{8}\.tmp$")
_OUR_SUFFIXES = (".svg", ".svgz", ".pdf", ".dxf", ".report.json", ".compare.png", *SUMMARY_FILES)


def remove_stale_temporaries(out_dir: Path) -> list[Path]:
    """Temporary files of atomic writes (".NAME.xxxxxxxx.tmp") that a killed run left
    behind in out_dir and its thumbs/: never a finished output, so they go."""
    removed = []
    for folder, suffixes in ((out_dir, _OUR_SUFFIXES), (out_dir / THUMBS, (".png",))):
        if not folder.is_dir():
            continue
        for p in folder.iterdir():
            m = _TMP.match(p.name)
            if m and m["name"].endswith(suffixes) and p.is_file():
                try:
                    p.unlink()
                    removed.append(p)
                except OSError:
                    pass
    return removed


class _Lock:
    """OUT_DIR/.vecfit-batch.lock, held for the run: two runs into one folder would
    overwrite each other's work."""

    def __init__(self, out_dir: Path):
        self.path = out_dir / ".vecfit-batch.lock"
        self.f = None

    def __enter__(self):
        try:
            import fcntl
        except ImportError:  # not POSIX: no lock
            return self
        self.f = open(self.path, "a+")
        try:
            fcntl.flock(self.f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self.f.close()
            self.f = None
            raise BatchUsageError(f"{self.path.parent}: another vecfit batch is writing into this "
                                  "folder") from None
        return self

    def __exit__(self, *exc):
        if self.f is not None:
            self.f.close()  # releases the lock; the file stays (harmless, empty)


class _Silent:
    def start(self, total): pass
    def row(self, row): pass
    def finish(self): pass


def run_batch(in_dir, out_dir, mode: str, *, config_file=None, preset: str | None = None,
              jobs: int = 1, threads: int | None = None, resume: bool = True, init_dir=None,
              scheduler: str | None = None, client=None, job: str | None = None,
              reporter=None, device: str | None = None, width: str | None = None,
              height: str | None = None, effort: str | None = None, format: str = "svg",
              palette: str | None = None, group_by: str | None = None,
              remove_background: bool = False, style: str | None = None, stacking: str | None = None,
              gap_filler: bool | None = None) -> BatchResult:
    """Runs ``mode`` (refine, trace, paint, edit) on every image directly in ``in_dir``, or
    retarget on every SVG there (to ``width`` and/or ``height``: pixels or a percentage), writing
    NAME.svg, NAME.report.json and NAME.compare.png per image and the summary into
    ``out_dir``.

    jobs: worker processes on this machine (0: one per core; 1 runs in this process);
    threads: threads per worker (default: the cores divided between the workers; 1 per
    task on a Dask cluster). resume: skip finished images (see vecfit.batch.plan).
    init_dir: where refine's (edit's) SVGs are (default in_dir). scheduler: a Dask scheduler's
    address (or give a connected ``client``). job: "module:function" in place of the
    mode's job function (same signature; for tests and extensions). reporter: an object
    with start(total), row(row) and finish() (see vecfit.batch.progress.Progress).
    device: where pixels are shaded (auto, cpu, cuda[:N]; default: the config's).
    effort: every image's effort, quick, normal or best (configs/: the mode's [efforts]
    tables; default: the config file's, else normal).
    format: what each result is written as, svg, pdf or dxf (NAME.svg, NAME.pdf, NAME.dxf).
    palette, group_by, remove_background, stacking, gap_filler: as the commands' --palette,
    --group-by, (trace) --remove-background, --stacking and --gap-filler.

    Raises BatchUsageError before any work when the run cannot start."""
    started = time.time()
    reporter = reporter or _Silent()
    in_dir, out_dir = Path(in_dir), Path(out_dir)
    init_dir = Path(init_dir) if init_dir is not None else None
    if mode not in MODES:
        raise BatchUsageError(f"unknown mode {mode!r} (known: {', '.join(MODES)})")
    if not in_dir.is_dir():
        raise BatchUsageError(f"{in_dir}: no such folder" if not in_dir.exists()
                              else f"{in_dir}: not a folder")
    if init_dir is not None:
        if mode not in PAIRED:
            raise BatchUsageError("--init-dir is for --mode refine and --mode edit")
        if not init_dir.is_dir():
            raise BatchUsageError(f"{init_dir}: no such folder")
    for d in (in_dir, init_dir):
        if d is not None and same_path(out_dir, d):
            raise BatchUsageError(f"the output folder must differ from {d} (the outputs would be "
                                  "taken for inputs)")
    size = {k: v for k, v in (("width", width), ("height", height)) if v is not None}
    if size and mode != "retarget":
        raise BatchUsageError("--width and --height are for --mode retarget")
    if mode == "retarget" and not size:
        raise BatchUsageError("--mode retarget needs --width (and/or --height)")
    if format not in FORMATS:
        raise BatchUsageError(f"unknown output format {format!r} (known: {', '.join(FORMATS)})")
    if jobs < 0 or (threads is not None and threads < 1):
        raise BatchUsageError("jobs must be >= 0 and threads >= 1")
    config = resolve_config(mode, preset, config_file, device, size, effort,
                            {"palette": palette, "group_by": group_by, "remove_background": remove_background,
                             "stacking": stacking, "gap_filler": gap_filler}, style)
    if scheduler is not None and client is None:
        from .execute import connect
        try:
            client = connect(scheduler)
        except VecfitError as e:
            raise BatchUsageError(str(e)) from None
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise BatchUsageError(f"{out_dir}: cannot make the folder ({e.strerror or e})") from None

    with _Lock(out_dir):
        remove_stale_temporaries(out_dir)
        plan = make_plan(in_dir, out_dir, mode, config, init_dir=init_dir, resume=resume, job=job, fmt=format)
        cores = available_cores()
        if client is not None:
            workers, per_worker = 0, threads or 1
        else:
            workers = max(1, min(jobs or cores, len(plan.tasks)))
            per_worker = threads or max(1, cores // workers)
        config = copy.deepcopy(config)
        config["optimize"]["threads"] = per_worker
        for t in plan.tasks:
            t.config["optimize"]["threads"] = per_worker
            # a process of its own (or a Dask worker): its torch threads too
            t.torch_threads = per_worker if (client is not None or workers > 1) else 0

        rows = dict(plan.rows)
        reporter.start(len(plan.order))
        for name in plan.order:
            if name in rows:
                reporter.row(rows[name])

        def on_row(row):
            rows[row["file"]] = row
            reporter.row(row)

        interrupted = False
        try:
            if not plan.tasks:
                pass
            elif client is not None:
                from .execute import run_dask
                interrupted = run_dask(plan.tasks, client, on_row)
            elif workers == 1:
                from .execute import run_serial
                interrupted = run_serial(plan.tasks, on_row)
            else:
                from .execute import run_processes
                interrupted = run_processes(plan.tasks, workers, per_worker, on_row)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            reporter.finish()
            if scheduler is not None and client is not None:
                try:
                    client.close()
                except Exception:
                    pass

        for t in plan.tasks:
            if t.file not in rows:
                rows[t.file] = result_row(t, NOT_RUN, "the run was interrupted before this image started")
        ordered = [rows[name] for name in plan.order]
        result = BatchResult(rows=ordered, interrupted=interrupted,
                             workers=workers if client is None else 0, threads=per_worker)
        counts = result.counts
        if interrupted or counts[INTERRUPTED] or counts[NOT_RUN]:
            result.exit_code = EXIT_INTERRUPTED
        elif counts[FAILED] or counts[UNPAIRED]:
            result.exit_code = EXIT_FAILED
        # Workers stopped by Ctrl-C, or killed by the executor when another one crashed,
        # leave their temporaries; all are finished now, so whatever is left is stale.
        remove_stale_temporaries(out_dir)
        from vecfit import __version__
        meta = {
            "vecfit": __version__, "mode": mode, "in_dir": str(in_dir.resolve()),
            "out_dir": str(out_dir.resolve()),
            "init_dir": None if init_dir is None else str(init_dir.resolve()),
            "resume": resume, "workers": result.workers, "threads_per_worker": per_worker,
            "scheduler": scheduler, "started_at": time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(started)),
            "finished_at": time.strftime("%Y-%m-%d %H:%M:%S"), "seconds": time.time() - started,
            "interrupted": interrupted, "exit_code": result.exit_code, "counts": counts,
            "effort": config["effort"], "config": config,
        }
        result.summary = write_all(out_dir, in_dir, meta, ordered)
    return result


"""The per-image function that runs where the work is done: in this process, in a worker
process of this machine or on a Dask worker. It calls the command's job function (vecfit.jobs.protocol) and
turns whatever happens into a summary row; it never raises for one image's trouble.

Ctrl-C in a worker process: the first SIGINT while a job runs raises KeyboardInterrupt
in it (the job stops, its atomic writes leave nothing half-written; the optimisation loop
may still write its best result so far, with a report marked interrupted, which resume
redoes); further SIGINTs, and one arriving between jobs, only stop the next jobs from
starting. The parent process forwards its own Ctrl-C to the workers."""
from __future__ import annotations

import importlib
import math
import os
import signal
import time
import traceback
import warnings
from pathlib import Path

from vecfit.errors import VecfitError

from .plan import DONE, FAILED, INTERRUPTED, NOT_RUN, Task, result_row

_state = {"running": False, "stop": False, "raised": False, "event": None}


def _on_sigint(signum, frame):
    _state["stop"] = True
    if _state["running"] and not _state["raised"]:
        _state["raised"] = True
        raise KeyboardInterrupt


def _stopping() -> bool:
    event = _state["event"]
    return _state["stop"] or (event is not None and event.is_set())


def init_worker(threads: int, stop_event=None) -> None:
    """Initializer of a worker process: its share of the cores, and Ctrl-C as above.
    ``stop_event`` (a multiprocessing Event) set by the parent also stops the next jobs
    from starting: a worker still starting up when Ctrl-C came did not see it."""
    _state["event"] = stop_event
    for var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = str(threads)
    signal.signal(signal.SIGINT, _on_sigint)
    if hasattr(signal, "pthread_sigmask"):  # blocked by the parent while it started us
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    import torch
    torch.set_num_threads(threads)


def load_job(spec: str):
    module, _, name = spec.partition(":")
    return getattr(importlib.import_module(module), name)


def _remove_outputs(task: Task) -> None:
    """Before a job: its earlier outputs go, the report (the mark of a finished image)
    first, so that an interrupted or failed run never leaves an old report beside newer
    files."""
    out = task.outputs()
    for p in (out.report, out.svg, out.comparison):
        try:
            p.unlink()
        except FileNotFoundError:
            pass


def _call(task: Task):
    return load_job(task.job)(task.inputs(), task.config, task.outputs(), progress=None)


def run_task(task: Task) -> dict:
    """Runs one image's job; returns its summary row (status done, failed or
    interrupted, or not run when a stop was asked for before it started)."""
    start = time.perf_counter()
    caught: list = []
    try:
        _state["running"] = True  # from here on, Ctrl-C raises KeyboardInterrupt
        if _stopping():
            return result_row(task, NOT_RUN, "the run was interrupted before this image started")
        _remove_outputs(task)
        if task.torch_threads > 0:
            import torch
            torch.set_num_threads(task.torch_threads)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            report = _call(task)
    except VecfitError as e:
        row = result_row(task, FAILED, str(e), seconds=time.perf_counter() - start)
    except KeyboardInterrupt:
        row = result_row(task, INTERRUPTED, "interrupted (Ctrl-C)", seconds=time.perf_counter() - start)
    except Exception as e:  # anything else is recorded too: the run goes on
        row = result_row(task, FAILED, f"{type(e).__name__}: {e}", seconds=time.perf_counter() - start)
        row["traceback"] = traceback.format_exc()
    else:
        seconds = time.perf_counter() - start
        if not isinstance(report, dict):
            row = result_row(task, FAILED, f"the job returned {type(report).__name__}, not a report",
                             seconds=seconds)
        elif report.get("interrupted"):
            row = result_row(task, INTERRUPTED, "interrupted (Ctrl-C): the best result so far "
                             "was written and will be redone", report=report, seconds=seconds)
        else:
            row = result_row(task, DONE, report=report, seconds=seconds)
            bad = [k for k in ("mse_before", "mse_after", "ssim_after")
                   if row[k] is None or not math.isfinite(row[k])]
            if bad or row["psnr_after"] is None or math.isnan(row["psnr_after"]):
                row["status"] = FAILED
                row["reason"] = "the result's metrics are not finite (NaN)"
                _remove_report(task)
    finally:
        _state["running"] = False
    messages = list(dict.fromkeys(str(w.message) for w in caught))
    if messages:
        row["warnings"] = messages
    return row


def _remove_report(task: Task) -> None:
    try:
        Path(task.report).unlink()
    except FileNotFoundError:
        pass

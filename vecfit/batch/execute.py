"""Where the tasks run: in this process (one worker), in worker processes of this machine,
or on a Dask distributed cluster. Each runner calls ``on_row(row)`` once per task it
finished, in the order they finish, and returns True if the run was interrupted (Ctrl-C);
tasks it did not report were not run."""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from vecfit.errors import VecfitError

from .plan import FAILED, INTERRUPTED, Task, result_row
from .work import init_worker, run_task

CRASHED = "the worker process died while running this image (a crash, or killed)"


def run_serial(tasks: list[Task], on_row) -> bool:
    for task in tasks:
        try:
            row = run_task(task)
        except KeyboardInterrupt:  # between two tasks
            return True
        on_row(row)
        if row["status"] == INTERRUPTED:
            return True
    return False


# ------------------------------------------------------------------ processes

class _Interrupted(Exception):
    pass


@contextlib.contextmanager
def _workers_ignore_sigint():
    """While the pool starts its workers: SIGINT ignored, which the workers inherit
    until init_worker puts their handler in place (a Ctrl-C while a worker still imports
    torch would otherwise print its traceback). Meanwhile it is blocked here, not lost:
    Linux keeps a blocked signal pending even while it is ignored, and delivers it once
    the handler is back and the block is lifted."""
    if threading.current_thread() is not threading.main_thread() or not hasattr(signal, "pthread_sigmask"):
        yield
        return
    old_mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    old_handler = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old_handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)


def _workers_of(executor) -> list:
    return list((getattr(executor, "_processes", None) or {}).values())


def _round(tasks: list[Task], workers: int, threads: int, on_row) -> tuple[list[Task], bool]:
    """Runs ``tasks`` on a fresh pool of ``workers`` processes. Returns the tasks not
    finished (in their order) and whether the pool broke (a worker died). Raises
    _Interrupted after a clean stop on Ctrl-C."""
    ctx = multiprocessing.get_context("spawn")
    finished: set[int] = set()
    broken = False
    futures = {}
    executor = None
    try:
        stop = ctx.Event()
        with _workers_ignore_sigint():
            executor = ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                           initializer=init_worker, initargs=(threads, stop))
            futures = {executor.submit(run_task, t): i for i, t in enumerate(tasks)}
        pending = set(futures)
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for f in done:
                i = futures[f]
                try:
                    row = f.result()
                except BrokenProcessPool:
                    broken = True
                    continue
                except Exception as e:  # e.g. a task that does not pickle
                    row = result_row(tasks[i], FAILED, f"{type(e).__name__}: {e}")
                finished.add(i)
                on_row(row)
    except KeyboardInterrupt:
        if executor is not None:
            _stop(executor, stop, futures, finished, on_row)
        raise _Interrupted from None
    executor.shutdown(wait=True)
    return [t for i, t in enumerate(tasks) if i not in finished], broken


def _stop(executor, stop_event, futures, finished, on_row) -> None:
    """Ctrl-C: the workers stop their jobs, queued tasks are dropped; waits for the
    running ones to report and the workers to exit. A second Ctrl-C kills the workers
    (run_batch then removes the temporary files they may leave)."""
    procs = _workers_of(executor)  # before shutdown() lets go of them
    stop_event.set()
    for p in procs:
        try:
            if p.is_alive():
                os.kill(p.pid, signal.SIGINT)
        except (OSError, ValueError):
            pass
    executor.shutdown(wait=False, cancel_futures=True)
    try:
        for f, i in futures.items():
            if f.cancelled() or i in finished:
                continue
            try:
                row = f.result()
            except Exception:
                continue
            finished.add(i)
            on_row(row)
        for p in procs:
            p.join()
    except KeyboardInterrupt:
        for p in procs:
            try:
                p.kill()
                p.join(5)
            except (OSError, ValueError, AttributeError):
                pass


def run_processes(tasks: list[Task], workers: int, threads: int, on_row) -> bool:
    """Worker processes ("spawn": torch and fork do not mix), ``threads`` each. A worker
    that dies (a crash in native code, the OOM killer) breaks the pool: the tasks that
    were in flight then run one at a time, each in a pool of its own, which finds the one
    that kills its worker (recorded as failed), and the rest go on in parallel."""
    pending = list(tasks)
    try:
        while pending:
            n = max(1, min(workers, len(pending)))
            unfinished, broken = _round(pending, n, threads, on_row)
            if not broken:
                return False
            # Tasks start in submission order, so the ones in flight when the pool broke
            # are among the first n + 1 unfinished (n running, one queued).
            suspects, pending = unfinished[:n + 1], unfinished[n + 1:]
            # Each suspect alone in a pool of its own, so that a pool that breaks names its
            # task. (Queued behind another in one pool, it would not: the executor can
            # report a result that a worker sent just before dying as broken too.)
            for task in suspects:
                _, broken = _round([task], 1, threads, on_row)
                if broken:
                    on_row(result_row(task, FAILED, CRASHED))
    except _Interrupted:
        return True
    return False


# ------------------------------------------------------------------------- Dask

def connect(address: str):
    """A distributed.Client for the scheduler at ``address``; VecfitError when the
    optional dependency is missing or the scheduler cannot be reached."""
    try:
        import distributed
    except ImportError:
        raise VecfitError("--scheduler needs the optional dependency 'distributed' "
                          "(pip install distributed)") from None
    try:
        return distributed.Client(address)
    except Exception as e:  # OSError, TimeoutError, a malformed address, ...
        raise VecfitError(f"cannot reach the Dask scheduler at {address}: {e}") from None


def run_dask(tasks: list[Task], client, on_row) -> bool:
    """The same per-image function submitted to a Dask cluster. Paths must mean the same
    on the workers (a shared file system) and vecfit must be installed there."""
    from distributed import as_completed

    futures = {}
    finished: set[int] = set()
    try:
        for i, t in enumerate(tasks):
            futures[client.submit(run_task, t, pure=False, key=f"vecfit-batch-{t.name}-{os.getpid()}-{i}")] = i
        for f in as_completed(list(futures)):
            i = futures[f]
            try:
                row = f.result()
            except Exception as e:  # the worker died (KilledWorker), a lost connection, ...
                row = result_row(tasks[i], FAILED, f"{type(e).__name__}: {e}")
            finished.add(i)
            on_row(row)
    except KeyboardInterrupt:
        # The tasks not started are cancelled; those already running on the cluster cannot
        # be, so they are waited for (their outputs are written atomically, and the run's
        # lock and its sweep of temporaries must not come before they finish). A second
        # Ctrl-C stops waiting.
        pending = [f for f, i in futures.items() if i not in finished]
        try:
            client.cancel(pending)
        except Exception:
            pass
        try:
            from distributed import wait
            wait(pending)
        except KeyboardInterrupt:
            pass
        except Exception:
            pass
        return True
    return False

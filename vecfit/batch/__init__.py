"""`vecfit batch`: every image of a folder through refine, trace, paint or edit; resumable,
parallel on one machine (worker processes) or on a Dask distributed cluster, with a
summary (summary.csv, summary.json, index.html with thumbnails).

run.py runs a batch; plan.py decides what to run and what is finished; execute.py hands
images to worker processes or a Dask cluster; work.py is one image's task; progress.py
and summary.py report.
"""
from vecfit.errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE  # noqa: F401

from .plan import (DONE, FAILED, INTERRUPTED, JOBS, MODES, NOT_RUN, SKIPPED, STATUSES, UNPAIRED,
                   Plan, Task, find_images, finished_report)
from .run import (BatchResult, BatchUsageError, available_cores, remove_stale_temporaries,
                  resolve_config, run_batch)

__all__ = ["DONE", "EXIT_FAILED", "EXIT_INTERRUPTED", "EXIT_OK", "EXIT_USAGE", "FAILED", "INTERRUPTED",
           "JOBS", "MODES", "NOT_RUN", "SKIPPED", "STATUSES", "UNPAIRED", "Plan", "Task", "BatchResult",
           "BatchUsageError", "available_cores", "remove_stale_temporaries", "run_batch", "resolve_config",
           "find_images", "finished_report"]

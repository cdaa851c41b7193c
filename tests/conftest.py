"""pytest set-up for the whole suite: OpenMP threads asleep when idle, the helpers beside the
tests importable, and the end-of-run notes (shared data missing, the conformance table)."""
import os
import sys
from pathlib import Path

# As vecfit does on import, but before anything loads torch: idle OpenMP threads sleep
# (spinning, they starve the core's threads on a busy machine; see vecfit/__init__.py).
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

# Test helpers are imported by name from any folder: the shared ones here, the reference
# renderer and conformance harness in oracles/, the fuzzer in fuzz/.
for _folder in ("fuzz", "oracles", "."):
    sys.path.insert(0, str((Path(__file__).resolve().parent / _folder).resolve()))


import time

_SESSION_START = time.time()


def pytest_terminal_summary(terminalreporter):
    """Show the conformance table when this run wrote it; say loudly when the shared data
    was missing (its tests skipped: conformance, Fig. 9, the real traces)."""
    from shared_data import SHARED
    if not SHARED.is_dir():
        terminalreporter.write_sep("!", f"shared test data not found at {SHARED}: its tests were "
                                        "skipped (set VECFIT_SHARED to its folder)")
    table = Path(__file__).resolve().parent / "failures" / "conformance-table.txt"
    if table.exists() and table.stat().st_mtime >= _SESSION_START:
        terminalreporter.write_sep("-", "conformance pass rate per tag")
        terminalreporter.write_line(table.read_text())

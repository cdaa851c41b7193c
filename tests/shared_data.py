"""Where the shared test data lives: ../shared beside the repository (as on the project's
machines), or the folder named by VECFIT_SHARED. Tests that need it skip without it, and
the run's summary says so loudly (see conftest.py)."""
from __future__ import annotations

import os
from pathlib import Path

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
FAILURES = TESTS / "failures"  # what failing checks leave to look at (not in git)
SHARED = Path(os.environ.get("VECFIT_SHARED") or ROOT.parent / "shared")
CONFORMANCE = SHARED / "conformance"
PHOTOS = SHARED / "data" / "photos"
SCENES = SHARED / "data" / "scenes"

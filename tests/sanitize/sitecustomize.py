"""Loaded by `make sanitize` (PYTHONPATH=tests/sanitize): imports vecfit._core from the
sanitizer build named by VECFIT_CORE instead of the installed one."""
import importlib.util
import os
import sys


class _SanitizedCore:
    def find_spec(self, name, path=None, target=None):
        if name == "vecfit._core" and os.environ.get("VECFIT_CORE"):
            return importlib.util.spec_from_file_location(name, os.environ["VECFIT_CORE"])
        return None


sys.meta_path.insert(0, _SanitizedCore())

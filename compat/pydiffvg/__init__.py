"""``import pydiffvg``: vecfit's implementation of diffvg's Python API (vecfit.pydiffvg)."""
import sys

import vecfit.pydiffvg as _impl

sys.modules[__name__] = _impl  # one module: `pydiffvg` and `vecfit.pydiffvg` are the same object

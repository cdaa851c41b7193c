"""Every resource limit is defined once, in vecfit/limits.py: the modules that enforce one
read it from there (a module-level alias is allowed, so that a test can lower it), and no
other module assigns a number to a name of a limit."""
import ast
from pathlib import Path

from vecfit import limits
from vecfit.svg import effects, read

ROOT = Path(__file__).resolve().parents[2]
LIMITS = [name for name in vars(limits) if name.startswith(("MAX_", "MIN_"))]


def test_the_readers_limits_are_those_of_limits_py():
    assert read.MAX_NESTING == limits.MAX_NESTING == 200
    assert read.MAX_EFFECT_NESTING == limits.MAX_EFFECT_NESTING == 16
    assert effects.MAX_STEPS == limits.MAX_STEPS == 64
    assert read.MAX_ELEMENTS == limits.MAX_ELEMENTS and read.MAX_SEGMENTS == limits.MAX_SEGMENTS


def test_no_module_but_limits_py_defines_a_limit():
    """A name of limits.py bound to a literal number anywhere else in the package is a
    second copy of the limit (the layer depth is the core's: Python keeps no copy)."""
    copies = []
    for path in (ROOT / "vecfit").rglob("*.py"):
        if path.name == "limits.py" and path.parent.name == "vecfit":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant):
                for target in node.targets:
                    if isinstance(target, ast.Name) and (target.id in LIMITS or target.id == "MAX_LAYER_DEPTH"):
                        copies.append(f"{path.relative_to(ROOT)}:{node.lineno} {target.id}")
    assert not copies, copies
    assert not hasattr(limits, "MAX_LAYER_DEPTH")

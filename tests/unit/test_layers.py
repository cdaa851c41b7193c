"""The package's layers: no module imports from a layer above its own (function-level
imports included). Lowest first; packages on one line are siblings that may not import
each other."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LAYERS = [
    ["vecfit.errors", "vecfit.limits", "vecfit.names", "vecfit._core"],
    ["vecfit.io"],                       # files, images, compositing
    ["vecfit.scene"],                    # the Scene and its geometry
    ["vecfit.renderer", "vecfit.svg"],   # drawing it; reading and writing it
    ["vecfit.fitting", "vecfit.editing", "vecfit.initial", "vecfit.export"],
    ["vecfit.jobs", "vecfit.pydiffvg"],
    ["vecfit.batch"],
    ["vecfit.cli", "vecfit", "vecfit.__main__"],  # the command line and the public API
]
RANK = {package: rank for rank, names in enumerate(LAYERS) for package in names}


def _module_files():
    for path in (ROOT / "vecfit").rglob("*.py"):
        yield "vecfit." + ".".join(path.relative_to(ROOT / "vecfit").with_suffix("").parts), path
    for path in (ROOT / "cli").glob("*.py"):
        yield "vecfit.cli." + path.stem, path


def _package(module: str) -> str:
    """The layer unit a module belongs to: vecfit.X (or the root package itself)."""
    parts = module.split(".")
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts[:2])


def _imports(module: str, path: Path):
    package = module.rsplit(".", 1)[0] if not module.endswith("__init__") else module[: -len(".__init__")]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target == "vecfit":  # from vecfit import X: a submodule, or a name of the API
                for alias in node.names:
                    sub = ROOT / "vecfit" / alias.name
                    if alias.name == "_core" or sub.with_suffix(".py").exists() or sub.is_dir():
                        yield node.lineno, f"vecfit.{alias.name}"
                    elif alias.name != "__version__":  # the version lives in the root package
                        yield node.lineno, "vecfit"
            elif target.startswith("vecfit"):
                yield node.lineno, target
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("vecfit"):
                    yield node.lineno, alias.name


def test_every_package_has_a_layer():
    packages = {_package(m) for m, _ in _module_files()}
    assert packages - set(RANK) == set()


def test_no_module_imports_from_a_layer_above_it():
    upward = []
    for module, path in _module_files():
        own = _package(module)
        for line, target in _imports(module, path):
            other = _package(target)
            if other != own and RANK[other] >= RANK[own] and RANK[own] != RANK["vecfit"]:
                upward.append(f"{path.relative_to(ROOT)}:{line} imports {target}")
    assert upward == []


def test_the_check_sees_an_upward_import(tmp_path):
    """The walker finds imports inside functions and relative imports."""
    path = tmp_path / "m.py"
    path.write_text("def f():\n    from ..jobs import fit\n")
    assert [t for _, t in _imports("vecfit.svg.m", path)] == ["vecfit.jobs"]

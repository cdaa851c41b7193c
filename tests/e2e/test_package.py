"""vecfit as a user installs it: a wheel built from this checkout, installed (not editable)
into a fresh virtual environment, every command run from a folder outside the checkout;
and the sdist's contents.

The wheel's virtual environment reuses this environment's packages (torch and the other
runtime requirements) through a path file, so nothing is downloaded but the build tools.
Its vecfit comes first on sys.path, and the test checks the commands really run it. A
site hook there makes dev-only packages unimportable: the commands must not need them.
About 2 minutes on 2 cores, most of it compiling the core."""
from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
import tarfile
import venv
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
DEV_ONLY = ("pytest", "hypothesis", "resvg_py", "distributed", "dask", "build", "skimage", "scipy")

pytestmark = pytest.mark.slow

BLOCK_DEV_ONLY = f"""
import sys
class _DevOnly:
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in {DEV_ONLY!r}:
            raise ModuleNotFoundError(f"dev-only package {{name}} imported at run time", name=name)
sys.meta_path.insert(0, _DevOnly())
"""

SVG = """<svg xmlns="http://www.w3.org/2000/svg" width="24" height="16" viewBox="0 0 24 16">
<rect x="2" y="2" width="20" height="12" fill="#3366cc"/>
<circle cx="12" cy="8" r="4" fill="#ffcc00"/></svg>"""


def _pip(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "pip", "--disable-pip-version-check", *args],
                          cwd=cwd, capture_output=True, text=True, timeout=900)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheelhouse")
    # A build folder of its own: the editable install's must not leak into the wheel.
    build_dir = tmp_path_factory.mktemp("wheel-build")
    r = _pip("wheel", "--no-deps", "-w", str(out), "--config-settings", f"build-dir={build_dir}",
             str(ROOT))
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    wheels = list(out.glob("vecfit-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


@pytest.fixture(scope="module")
def user_env(wheel, tmp_path_factory) -> Path:
    """A virtual environment with the wheel installed; its python's path."""
    env = tmp_path_factory.mktemp("user-venv")
    venv.create(env, with_pip=False)
    python = env / "bin" / "python"
    site = Path(subprocess.check_output(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], text=True).strip())
    # This environment's packages after the new one's own; a path file adds the folder
    # without running its own path files, so the editable vecfit's finder stays out.
    (site / "test-env.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    (site / "sitecustomize.py").write_text(BLOCK_DEV_ONLY)
    r = subprocess.run([sys.executable, "-m", "pip", "--disable-pip-version-check", "--python",
                        str(python), "install", "--no-deps", "--no-index", str(wheel)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    return python


def _run(python: Path, cwd: Path, *args, module=False):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VECFIT_SHARED")}
    cmd = [python, "-m", "vecfit", *args] if module else [python.parent / "vecfit", *args]
    r = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, f"{args}: exit {r.returncode}\n{r.stdout}\n{r.stderr}"
    return r.stdout


def test_the_installed_wheel_runs_every_command(user_env, tmp_path):
    work = tmp_path / "work"  # outside the checkout
    work.mkdir()
    where = subprocess.check_output([user_env, "-c", "import vecfit, vecfit.configs, vecfit._core;"
                                     "print(vecfit.__file__)"], cwd=work, text=True)
    assert Path(where).resolve().is_relative_to(user_env.parent.parent.resolve()), where

    (work / "in.svg").write_text(SVG)
    _run(user_env, work, "render", "in.svg", "-o", "r.png")
    assert "circle" in _run(user_env, work, "info", "in.svg")
    rng = np.random.default_rng(0)
    target = np.asarray(Image.open(work / "r.png").convert("RGB"), dtype=np.int16)
    target = np.clip(target + rng.integers(-20, 20, target.shape), 0, 255).astype(np.uint8)
    Image.fromarray(target).save(work / "t.png")
    few = ["--iterations", "3", "-q"]
    _run(user_env, work, "refine", "t.png", "in.svg", "-o", "refined.svg", *few)
    _run(user_env, work, "trace", "t.png", "-o", "traced.svg", "--paths", "8", *few)
    _run(user_env, work, "paint", "t.png", "-o", "painted.svg", "--paths", "4", *few)
    for name in ("r.png", "refined.svg", "refined.report.json", "refined.compare.png",
                 "traced.svg", "painted.svg"):
        assert (work / name).stat().st_size > 0, name

    version = _run(user_env, work, "--version", module=True)
    assert version.startswith("vecfit 0.") and "core:" in version, version


PYDIFFVG_SCRIPT = """
import torch, pydiffvg, diffvg, vecfit.pydiffvg
assert pydiffvg is vecfit.pydiffvg and pydiffvg.__file__.startswith(SITE), pydiffvg.__file__
center = torch.tensor([12.0, 8.0], requires_grad=True)
shapes = [pydiffvg.Circle(torch.tensor(4.0), center)]
groups = [pydiffvg.ShapeGroup(torch.tensor([0]), torch.tensor([1.0, 0.8, 0.0, 1.0]))]
args = pydiffvg.RenderFunction.serialize_scene(24, 16, shapes, groups,
                                               pydiffvg.PixelFilter(diffvg.FilterType.hann, torch.tensor(1.0)))
img = pydiffvg.RenderFunction.apply(24, 16, 2, 2, 0, None, *args)
(img[:, :12, 3].sum() - img[:, 12:, 3].sum()).backward()
assert img.shape == (16, 24, 4) and center.grad[0] < 0, center.grad
pydiffvg.save_svg("d.svg", 24, 16, shapes, groups)
w, h, shapes2, groups2 = pydiffvg.svg_to_scene("d.svg")
assert (w, h, len(shapes2)) == (24, 16, 1)
pydiffvg.imwrite(img.detach(), "d.png")
print("ok")
"""


def test_the_installed_wheel_has_pydiffvg(user_env, tmp_path):
    """`import pydiffvg` and `import diffvg` in the installed wheel: render, gradients, SVG."""
    site = subprocess.check_output([user_env, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                                   text=True).strip()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VECFIT_SHARED")}
    r = subprocess.run([str(user_env), "-c", f"SITE = {site!r}\n" + PYDIFFVG_SCRIPT], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stdout + r.stderr
    assert (tmp_path / "d.png").stat().st_size > 0


def test_sdist_carries_the_sources(tmp_path):
    pytest.importorskip("build", reason="the sdist is built with the 'build' package (dev extra)")
    r = subprocess.run([sys.executable, "-m", "build", "--sdist", "--outdir", str(tmp_path), str(ROOT)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    (sdist,) = tmp_path.glob("vecfit-*.tar.gz")
    with tarfile.open(sdist) as tar:
        names = {n.split("/", 1)[1] for n in tar.getnames() if "/" in n}
    for needed in ("README.md", "LICENSE", "pyproject.toml", "CMakeLists.txt",
                   "configs/refine.toml", "configs/trace.toml", "configs/paint.toml",
                   "cli/commands.py", "vecfit/__init__.py", "vecfit/__main__.py",
                   "compat/pydiffvg/__init__.py", "compat/diffvg/__init__.py", "vecfit/pydiffvg/render.py"):
        assert needed in names, needed
    assert any(n.startswith("csrc/") and n.endswith(".cpp") for n in names)
    assert not any(n.startswith(("build/", ".venv/", "out/")) for n in names)

"""The CUDA build: its sources compile (with nvcc, wherever it is installed, GPU or not),
a build without CUDA says so clearly, and, where a CUDA build meets a GPU, the GPU's
images agree with the CPU's on the conformance corpus."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import torch

import vecfit
from helpers import gpu_lists, quiet_load, run
from shared_data import ROOT, SCENES
from vecfit.errors import VecfitError

pytestmark = pytest.mark.slow  # over 30 s: `make test-fast` leaves it out
CUDA_SOURCES = sorted((ROOT / "csrc" / "cuda").glob("*.cu"))
GPU = vecfit.has_cuda() and vecfit.cuda_device_count() > 0


def find_nvcc() -> str | None:
    """nvcc where CMakeLists.txt looks for it: CUDACXX, PATH, CUDA_HOME, CUDA_PATH, /usr/local/cuda."""
    homes = [os.environ.get(v) for v in ("CUDA_HOME", "CUDA_PATH")] + ["/usr/local/cuda"]
    candidates = [os.environ.get("CUDACXX"), shutil.which("nvcc")]
    candidates += [str(Path(h) / "bin" / "nvcc") for h in homes if h]
    return next((c for c in candidates if c and Path(c).is_file()), None)


@pytest.mark.skipif(find_nvcc() is None, reason="nvcc is not installed")
@pytest.mark.parametrize("source", CUDA_SOURCES, ids=[s.name for s in CUDA_SOURCES])
def test_cuda_source_compiles(source, tmp_path):
    # One architecture is enough to catch what breaks the build: host-only code reached
    # from device code (an error here, as in CMakeLists.txt), and syntax nvcc rejects.
    cmd = [find_nvcc(), "-std=c++17", "-arch=sm_80", "--Werror=cross-execution-space-call",
           "-DVECFIT_WITH_CUDA=1", '-DVECFIT_CUDA_ARCHS="sm_80"', f"-I{ROOT / 'csrc'}",
           "-c", str(source), "-o", str(tmp_path / "out.o")]
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, f"nvcc failed on {source.name}:\n{done.stderr[-4000:]}"
    assert (tmp_path / "out.o").stat().st_size > 0


def test_cuda_sources_exist():
    assert CUDA_SOURCES, "csrc/cuda/ has no .cu files"


def small_scene():
    return vecfit.Scene(width=16, height=12, shapes=[vecfit.Shape(
        geometry=vecfit.Circle(center=torch.tensor([8.0, 6.0]), radius=torch.tensor(4.0)),
        fill=vecfit.Solid(torch.tensor([1.0, 0.0, 0.0, 1.0])))])


@pytest.mark.skipif(vecfit.has_cuda(), reason="this build has CUDA")
class TestWithoutCuda:
    def test_render_on_cuda_is_a_clear_error(self):
        with pytest.raises(VecfitError, match="built without CUDA"):
            vecfit.render(small_scene(), device="cuda")

    def test_auto_and_cpu_render_the_same(self):
        a = vecfit.render(small_scene(), device="auto")
        b = vecfit.render(small_scene(), device="cpu")
        assert torch.equal(a, b) and a[6, 8, 0] == 1.0

    def test_bad_device_name(self):
        with pytest.raises(VecfitError, match="device must be"):
            vecfit.render(small_scene(), device="gpu")

    def test_info_build(self):
        r = run("info", "--build")
        assert r.exit_code == 0, r.output
        assert "CUDA: not compiled" in r.output and "device auto resolves to: cpu" in r.output

    def test_cli_device_cuda_is_a_usage_error(self, tmp_path):
        svg = tmp_path / "a.svg"
        svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="8" height="8">'
                       '<rect width="4" height="4"/></svg>')
        r = run("render", str(svg), "-o", str(tmp_path / "a.png"), "--device", "cuda")
        assert r.exit_code == 2 and "without CUDA" in r.output
        assert not (tmp_path / "a.png").exists()


    def test_optimising_commands_refuse_cuda(self, tmp_path):
        from vecfit.io.png import save_png
        save_png(torch.from_numpy(np.full((16, 16, 4), 0.5, np.float32)), tmp_path / "in" / "a.png")
        for args in (["trace", str(tmp_path / "in" / "a.png"), "-o", str(tmp_path / "a.svg")],
                     ["batch", str(tmp_path / "in"), "-o", str(tmp_path / "out"), "--mode", "trace"]):
            r = run(*args, "--device", "cuda")
            assert r.exit_code == 2 and "without CUDA" in r.output, r.output
        assert not (tmp_path / "a.svg").exists() and not (tmp_path / "out").exists()


def test_bad_device_in_a_config_is_a_usage_error(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('[optimize]\ndevice = "gpu"\n')
    r = run("refine", "a.png", "a.svg", "--config", str(cfg))
    assert r.exit_code == 2 and "device must be" in r.output, r.output


def test_device_does_not_change_a_batch_settings_key():
    from vecfit.batch.plan import comparable
    a = {"optimize": {"device": "cpu", "threads": 2, "iterations": 5}}
    b = {"optimize": {"device": "cuda", "threads": 1, "iterations": 5}}
    assert comparable(a) == comparable(b) == {"optimize": {"iterations": 5}}


@pytest.mark.skipif(not vecfit.has_cuda(), reason="this build has no CUDA")
def test_cuda_build_names_a_missing_device():
    n = vecfit.cuda_device_count()
    with pytest.raises(VecfitError, match=f"no CUDA device {n}: this machine has {n}"):
        vecfit.render(small_scene(), device=f"cuda:{n}")
    r = run("info", "--build")
    assert r.exit_code == 0 and "CUDA: compiled for" in r.output


def test_info_needs_svg_or_build():
    r = run("info")
    assert r.exit_code == 2


# ------------------------------------- a GPU thread's list sizes, checked on the CPU

def stacked_discs(n: int) -> vecfit.Scene:
    """n translucent discs over one another: n draws hit the centre."""
    shapes = [vecfit.Shape(geometry=vecfit.Circle(center=torch.tensor([16.0, 16.0]),
                                                  radius=torch.tensor(12.0 - 0.2 * i)),
                           fill=vecfit.Solid(torch.tensor([i / n, 0.5, 1 - i / n, 0.3])))
              for i in range(n)]
    return vecfit.Scene(width=32, height=32, shapes=shapes)


def grouped_discs(n: int, depth: int = 3) -> vecfit.Scene:
    """n translucent discs, two by two in groups nested `depth` deep with opacity (a group
    over one draw would fold into its alpha): fewer hits than a GPU thread holds, but each
    pair opens and closes its layers, so the compositing tape (96 steps) runs out first."""
    scene = stacked_discs(n)
    for i in range(0, n, 2):
        parent = -1
        for _ in range(depth):
            scene.groups.append(vecfit.Group(opacity=torch.tensor(0.9), parent=parent))
            parent = len(scene.groups) - 1
        for shape in scene.shapes[i:i + 2]:
            shape.group = parent
    return scene


def gradients(scene, **render_options) -> torch.Tensor:
    """All of the scene's gradients, flat, for loss = sum of the squared render."""
    params = [t for ts in scene.parameters().values() for t in ts]
    for t in params:
        t.requires_grad_(True)
        t.grad = None
    img = vecfit.render(scene, **render_options)
    (img ** 2).sum().backward()
    return torch.cat([t.grad.flatten() for t in params if t.grad is not None])


@pytest.mark.parametrize("mode", ["mc", "analytic"])
@pytest.mark.parametrize("make,depth,falls_back", [(stacked_discs, 20, False), (stacked_discs, 40, True),
                                                   (grouped_discs, 16, False), (grouped_discs, 30, True)],
                         ids=["20-discs", "40-discs", "16-grouped", "30-grouped"])
def test_gpu_list_sizes_on_the_cpu(mode, make, depth, falls_back):
    """The CPU lanes run with a GPU thread's lists (32 hits, 96 compositing steps): 20
    discs deep fits and gives the very same gradients, as do 16 in nested groups; 40 deep
    overflow the hits, 30 in nested groups the tape (15 pairs x 8 steps), which is flagged,
    and the pass is redone with lists sized to the scene, as a GPU run would be."""
    from vecfit.renderer.raster import backward_fallbacks
    scene = make(depth)
    before = backward_fallbacks()
    with gpu_lists():
        emulated = gradients(scene, samples=2, mode=mode, threads=2)
    assert backward_fallbacks() - before == int(falls_back)
    exact = gradients(scene, samples=2, mode=mode, threads=2)
    assert backward_fallbacks() - before == int(falls_back)  # (only fixed lists count)
    assert exact.abs().max() > 0 and torch.equal(emulated, exact)


def test_benchmark_scenes_fit_a_gpu_thread():
    """The scenes the GPU is timed on never overflow a GPU thread's lists, so the GPU
    timings are not CPU fallbacks."""
    from vecfit.renderer.raster import backward_fallbacks
    names = ["tiger", "boston", "mcseem2"]
    if not all((SCENES / f"{n}.svg").exists() for n in names):
        pytest.skip("the shared benchmark scenes are not present")
    before = backward_fallbacks()
    for name in names:
        scene = quiet_load(SCENES / f"{name}.svg")
        for mode, samples in (("mc", 2), ("analytic", 1)):
            with gpu_lists():
                gradients(scene, samples=samples, mode=mode)
    assert backward_fallbacks() == before


# ------------------------------------------------------- with a GPU (the `device` tool)

@pytest.mark.skipif(not GPU, reason="needs a CUDA build and a GPU")
def test_gpu_matches_cpu_on_conformance_corpus():
    import conformance as conf
    if not (conf.CORPUS / "manifest.tsv").exists():
        pytest.skip("the shared conformance corpus is not present")
    worst, compared = 0.0, 0
    for case in conf.load_manifest():
        try:
            scene = quiet_load(case.svg)
        except VecfitError:
            continue  # a case that is an error on both (malformed input)
        for mode, samples in (("mc", 4), ("analytic", 1)):
            cpu, gpu = (vecfit.render(scene, case.width, case.height, samples=samples, mode=mode, device=device)
                        for device in ("cpu", "cuda"))
            diff = float((cpu - gpu).abs().max())
            worst = max(worst, diff)
            assert diff <= 1e-4, f"{case.name} ({mode}): CPU and GPU differ by {diff:.2e}"
        compared += 1
    assert compared > 200, f"only {compared} cases could be compared"
    print(f"largest CPU-GPU difference over {compared} cases: {worst:.2e}")


@pytest.mark.skipif(not GPU, reason="needs a CUDA build and a GPU")
@pytest.mark.parametrize("mode", ["mc", "analytic"])
def test_gpu_gradients_match_cpu(mode):
    # The tiger: fills and strokes, many overlaps, group transforms. Same seed, so the
    # same pixel and boundary samples on both devices; only the order of the sums differs.
    from vecfit.renderer.raster import backward_fallbacks
    scene = quiet_load(ROOT / "examples" / "tiger.svg")
    fallbacks = backward_fallbacks()
    grads = {device: gradients(scene, width=160, height=160, samples=2, mode=mode, device=device)
             for device in ("cpu", "cuda")}
    assert backward_fallbacks() == fallbacks  # the GPU's gradients came from the GPU
    cpu, gpu = grads["cpu"], grads["cuda"]
    assert cpu.abs().max() > 0
    scale = float(cpu.abs().max())
    worst = float((cpu - gpu).abs().max())
    assert worst <= 1e-4 * scale, f"gradients differ by {worst:.3e} (largest {scale:.3e})"

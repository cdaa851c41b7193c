"""`--effort quick|normal|best`: the [efforts] tables of configs/, where they sit in the
order of resolution, normal as today's defaults (settings and SVG bytes), the effort in
reports and batch, and the same SVG from Python as from the command."""
from __future__ import annotations

import copy
import json

import numpy as np
import pytest
from PIL import Image

import vecfit
from helpers import run, two_shapes_png
from vecfit.batch import DONE, EXIT_OK, EXIT_USAGE, run_batch
from vecfit.errors import VecfitError
from vecfit.io.configs import configs_dir, read_toml
from vecfit.jobs.config import EFFORTS, merge, resolve

COMMANDS = ("refine", "trace", "paint", "edit", "retarget")


def _files_without_efforts(command: str) -> dict:
    """refine.toml and the command's file merged by hand, their presets and efforts left out:
    the defaults as they were before efforts existed."""
    base = read_toml(configs_dir() / "refine.toml")
    base.pop("efforts", None)
    if command != "refine":
        own = read_toml(configs_dir() / f"{command}.toml")
        own.pop("efforts", None)
        own.pop("presets", None)
        schema = {**copy.deepcopy(base), **{k: v for k, v in own.items() if k not in base}}
        base = merge(base, own, schema, command)
    return base


@pytest.mark.parametrize("command", COMMANDS)
def test_normal_is_the_files_as_they_are_and_the_default(command):
    normal = resolve(command, effort="normal")
    assert normal == resolve(command)
    assert normal.pop("effort") == "normal"
    assert normal == _files_without_efforts(command)


@pytest.mark.parametrize("command", COMMANDS)
def test_quick_and_best_are_defined_and_shorter_and_longer(command):
    normal, quick, best = (resolve(command, effort=e) for e in EFFORTS[1::-1] + EFFORTS[2:])
    assert (normal["effort"], quick["effort"], best["effort"]) == ("normal", "quick", "best")
    key = ("retarget", "iterations_per_step") if command == "retarget" else ("optimize", "iterations")
    assert quick[key[0]][key[1]] < normal[key[0]][key[1]] < best[key[0]][key[1]]


def test_the_order_effort_then_preset_then_file_then_options(tmp_path):
    quick = resolve("trace", effort="quick")
    poster = resolve("trace", effort="quick", preset="poster")
    assert poster["trace"]["paths"] == 300 and poster["optimize"]["iterations"] == quick["optimize"]["iterations"]
    user = tmp_path / "u.toml"
    user.write_text("[optimize]\nsamples = 3\n")
    assert resolve("trace", effort="quick", config_file=user)["optimize"]["samples"] == 3
    assert resolve("trace", effort="quick", config_file=user,
                   overrides={"optimize": {"iterations": 7}})["optimize"]["iterations"] == 7


def test_a_config_file_may_choose_the_effort_and_the_option_wins(tmp_path):
    user = tmp_path / "u.toml"
    user.write_text('effort = "quick"\n[optimize]\nseed = 3\n')
    chosen = resolve("trace", config_file=user)
    assert chosen["effort"] == "quick" and chosen["optimize"]["seed"] == 3
    assert chosen["optimize"]["iterations"] == resolve("trace", effort="quick")["optimize"]["iterations"]
    assert resolve("trace", config_file=user, effort="best")["effort"] == "best"


def test_unknown_efforts_are_refused_clearly(tmp_path):
    with pytest.raises(VecfitError, match="unknown effort 'fast'"):
        resolve("trace", effort="fast")
    user = tmp_path / "u.toml"
    user.write_text('effort = "fast"\n')
    r = run("trace", tmp_path / "none.png", "--config", user)
    assert r.exit_code == EXIT_USAGE and "unknown effort 'fast'" in r.output and "Traceback" not in r.output
    r = run("trace", tmp_path / "none.png", "--effort", "fast")
    assert r.exit_code == EXIT_USAGE and "fast" in r.output


@pytest.mark.slow
def test_normal_writes_the_same_bytes_as_no_effort_and_quick_the_same_as_python(tmp_path):
    image = tmp_path / "in.png"
    two_shapes_png(image)
    common = ["--iterations", 6, "--threads", 1, "--paths", 12, "-q"]
    for name, extra in (("plain", []), ("normal", ["--effort", "normal"]), ("quick", ["--effort", "quick"])):
        r = run("trace", image, "-o", tmp_path / f"{name}.svg", *common, *extra)
        assert r.exit_code == 0, r.output
    plain, normal, quick = ((tmp_path / f"{n}.svg").read_text() for n in ("plain", "normal", "quick"))
    assert normal == plain
    reports = {n: json.loads((tmp_path / f"{n}.report.json").read_text()) for n in ("normal", "quick")}
    assert reports["normal"]["effort"] == "normal" and reports["quick"]["effort"] == "quick"
    assert reports["quick"]["config"]["effort"] == "quick"
    settings = {"optimize": {"iterations": 6, "threads": 1}, "trace": {"paths": 12}}
    svg, report = vecfit.trace(image.read_bytes(), settings=settings, effort="quick")
    assert svg == quick and report["effort"] == "quick"
    assert report["config"] == reports["quick"]["config"]


def test_refine_from_python_is_the_commands_svg(tmp_path):
    image = tmp_path / "in.png"
    two_shapes_png(image)
    init = tmp_path / "init.svg"
    init.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="36">'
                    '<circle id="c" cx="20" cy="18" r="10" fill="#884444"/>'
                    '<rect id="r" x="24" y="12" width="16" height="16" fill="#3050a0"/></svg>')
    for effort in ("normal", "quick"):
        out = tmp_path / f"cli-{effort}.svg"
        r = run("refine", image, init, "-o", out, "--iterations", 5, "--threads", 1, "--seed", 4,
                "--effort", effort, "-q")
        assert r.exit_code == 0, r.output
        svg, report = vecfit.refine(np.asarray(Image.open(image)), init.read_text(), effort=effort,
                                    settings={"optimize": {"iterations": 5, "threads": 1, "seed": 4}})
        assert svg == out.read_text() and report["effort"] == effort
        assert report["optimized"]["mse"] < report["initial"]["mse"]


@pytest.mark.slow
def test_batch_takes_the_effort_to_every_image_and_resume_sees_it(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    two_shapes_png(d / "a.png")
    user = tmp_path / "c.toml"
    user.write_text("[optimize]\niterations = 3\n[trace]\npaths = 8\n")
    out = tmp_path / "out"
    result = run_batch(d, out, "trace", config_file=user, effort="quick")
    assert result.exit_code == EXIT_OK and [r["status"] for r in result.rows] == [DONE]
    assert json.loads((out / "a.report.json").read_text())["effort"] == "quick"
    assert json.loads((out / "summary.json").read_text())["effort"] == "quick"
    again = run("batch", d, "-o", out, "--mode", "trace", "--config", user, "--effort", "quick", "-q")
    assert again.exit_code == EXIT_OK and "1 skipped" in again.output
    normal = run("batch", d, "-o", out, "--mode", "trace", "--config", user, "-q")
    assert normal.exit_code == EXIT_OK and "1 done" in normal.output  # another effort: redone
    assert json.loads((out / "a.report.json").read_text())["effort"] == "normal"


def test_quick_trace_changes_the_tracer_too_and_normal_does_not():
    """trace.toml's [efforts.quick.trace]: a short run starts from a closer trace."""
    quick, normal = resolve("trace", effort="quick"), resolve("trace")
    assert (quick["trace"]["overlap"], quick["trace"]["smoothing"]) == (2, 0.5)
    assert (normal["trace"]["overlap"], normal["trace"]["smoothing"]) == (1, 1.0)
    assert resolve("trace", effort="quick", overrides={"trace": {"overlap": 1}})["trace"]["overlap"] == 1

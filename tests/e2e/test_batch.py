"""`vecfit batch`: folders of images, pairing, failures recorded, resume, worker processes,
Dask, the summary files and index.html. Tiny images and three iterations: fast."""
from __future__ import annotations

import csv
import json
import math
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from vecfit.batch import (DONE, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE, FAILED,
                          INTERRUPTED, NOT_RUN, SKIPPED, UNPAIRED, available_cores, run_batch)
from vecfit.batch.execute import CRASHED
from helpers import run
from vecfit.jobs.config import configs_dir

SIZE = 32


def disc_png(path: Path, cx, cy, r, color) -> Path:
    yy, xx = np.mgrid[0:SIZE, 0:SIZE] + 0.5
    a = np.full((SIZE, SIZE, 3), 255, np.uint8)
    a[(xx - cx) ** 2 + (yy - cy) ** 2 <= r * r] = color
    Image.fromarray(a).save(path)
    return path


def circle_svg(path: Path, cx=16, cy=16, r=6, fill="#404040") -> Path:
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" width="{SIZE}" height="{SIZE}">'
                    f'<circle cx="{cx}" cy="{cy}" r="{r}" fill="{fill}"/></svg>')
    return path


def config(folder: Path, text="[optimize]\niterations = 3\n", name="c.toml") -> Path:
    p = folder / name
    p.write_text(text)
    return p


@pytest.fixture
def folder(tmp_path):
    """a, b: good pairs; c: a corrupt image (with an SVG); d: an image without an SVG."""
    d = tmp_path / "in"
    d.mkdir()
    disc_png(d / "a.png", 18, 15, 8, (0, 0, 255))
    circle_svg(d / "a.svg", fill="#4040a0")
    disc_png(d / "b.png", 12, 18, 7, (255, 0, 0))
    circle_svg(d / "b.svg", fill="#a04040")
    (d / "c.png").write_bytes(b"\x89PNG\r\n\x1a\n this is not a picture")
    circle_svg(d / "c.svg")
    disc_png(d / "d.png", 16, 16, 5, (0, 128, 0))
    (d / "notes.txt").write_text("not an image")
    return d


def read_csv(out: Path) -> dict:
    with open(out / "summary.csv", newline="", encoding="utf-8") as f:
        return {row["file"]: row for row in csv.DictReader(f)}


def read_json(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def statuses(out: Path) -> dict:
    return {k: v["status"] for k, v in read_csv(out).items()}


def mtimes(out: Path, *names) -> dict:
    return {n: (out / n).stat().st_mtime_ns for n in names}


def no_leftovers(out: Path) -> None:
    left = [p for p in out.rglob("*") if p.name.endswith(".tmp")]
    assert left == []


# ------------------------------------------------------------------ refine

def test_refine_folder_records_failures_and_writes_the_summary(folder, tmp_path):
    out = tmp_path / "out"
    cfg = config(tmp_path)
    r = run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg)
    assert r.exit_code == EXIT_FAILED, r.output
    assert "Traceback" not in r.output
    # one line per image, and the totals
    for name in ("a.png", "b.png", "c.png", "d.png"):
        assert re.search(rf"\[\d/4\] {name}: ", r.output), r.output
    assert "2 done, 1 failed, 1 unpaired" in r.output

    for name in ("a", "b"):
        for suffix in (".svg", ".report.json", ".compare.png"):
            assert (out / f"{name}{suffix}").is_file()
    assert not list(out.glob("c.*")) and not list(out.glob("d.*"))

    rows = read_csv(out)
    assert list(rows) == ["a.png", "b.png", "c.png", "d.png"]  # sorted; notes.txt is no image
    assert {k: v["status"] for k, v in rows.items()} == {
        "a.png": DONE, "b.png": DONE, "c.png": FAILED, "d.png": UNPAIRED}
    assert "c.png" in rows["c.png"]["reason"] and "not an image" in rows["c.png"]["reason"]
    assert rows["d.png"]["reason"] == f"no d.svg in {folder}"
    for name in ("a", "b"):
        row = rows[f"{name}.png"]
        report = json.loads((out / f"{name}.report.json").read_text())
        for m in ("mse", "psnr", "ssim"):
            assert float(row[f"{m}_before"]) == pytest.approx(report["initial"][m])
            assert float(row[f"{m}_after"]) == pytest.approx(report["optimized"][m])
        assert float(row["mse_after"]) < float(row["mse_before"])
        assert row["svg"] == f"{name}.svg" and row["comparison"] == f"{name}.compare.png"
        assert row["report"] == f"{name}.report.json" and row["reason"] == ""
        assert Path(row["init_svg"]) == folder / f"{name}.svg"
        assert float(row["seconds"]) > 0
        assert report["config"]["optimize"]["iterations"] == 3
        # one worker in this process: all the cores
        assert report["config"]["optimize"]["threads"] == available_cores()
    for name in ("c.png", "d.png"):
        assert rows[name]["mse_before"] == rows[name]["svg"] == ""

    summary = read_json(out)
    assert summary["mode"] == "refine" and summary["exit_code"] == EXIT_FAILED
    assert summary["counts"][DONE] == 2 and summary["counts"][FAILED] == 1
    assert summary["counts"][UNPAIRED] == 1 and summary["counts"][SKIPPED] == 0
    assert [i["file"] for i in summary["images"]] == list(rows)
    assert summary["images"][0]["iterations"] == 3 and summary["images"][0]["shapes"] == 1
    assert summary["config"]["optimize"]["iterations"] == 3

    # index.html: every image named, thumbnails referenced and present, links relative
    page = (out / "index.html").read_text()
    for name in ("a.png", "b.png", "c.png", "d.png"):
        assert name in page
    assert "not an image" in page and "unpaired" in page
    srcs = re.findall(r'<img src="([^"]+)"', page)
    assert set(srcs) == {"thumbs/a.target.png", "thumbs/a.result.png", "thumbs/b.target.png",
                         "thumbs/b.result.png", "thumbs/d.target.png"}
    for src in srcs:
        with Image.open(out / src) as im:
            assert im.size == (SIZE, SIZE)
    for href in re.findall(r'href="([^"]+)"', page):
        assert not href.startswith(("/", "http")) and (out / href).is_file(), href
    no_leftovers(out)


@pytest.mark.slow
def test_resume_skips_finished_images_and_redoes_changed_ones(folder, tmp_path):
    out = tmp_path / "out"
    cfg = config(tmp_path)
    assert run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg).exit_code == 1
    files = ("a.svg", "a.report.json", "a.compare.png", "b.svg", "b.report.json")
    before = mtimes(out, *files)
    first = read_csv(out)
    (out / ".a.svg.k2j4x_9q.tmp").write_text("<svg")  # as a killed run leaves it

    r = run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg)
    assert r.exit_code == EXIT_FAILED  # c and d still fail
    assert statuses(out) == {"a.png": SKIPPED, "b.png": SKIPPED, "c.png": FAILED, "d.png": UNPAIRED}
    assert mtimes(out, *files) == before  # not redone
    again = read_csv(out)
    for k in ("mse_before", "mse_after", "psnr_after", "ssim_after", "file_segments", "seconds", "svg"):
        assert again["a.png"][k] == first["a.png"][k]  # from the finished run's report
    svg_text = (out / "a.svg").read_text()
    assert int(first["a.png"]["file_paths"]) >= 1 and first["a.png"]["file_crossed_outlines"] == "0"
    assert int(first["a.png"]["file_gzip_bytes"]) > 0 and ("opacity" in svg_text) == (
        first["a.png"]["file_translucent_paints"] != "0")
    assert "skipped (finished)" in r.output
    no_leftovers(out)

    # a newer image is redone, the other is not
    stamp = (folder / "a.png").stat().st_mtime + 10
    os.utime(folder / "a.png", (stamp, stamp))
    assert run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg).exit_code == 1
    assert statuses(out)["a.png"] == DONE and statuses(out)["b.png"] == SKIPPED
    assert mtimes(out, "b.svg")["b.svg"] == before["b.svg"]

    # changed settings: both redone (threads alone would not count)
    cfg2 = config(tmp_path, "[optimize]\niterations = 4\n", "c2.toml")
    assert run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg2).exit_code == 1
    assert statuses(out)["a.png"] == DONE and statuses(out)["b.png"] == DONE
    assert json.loads((out / "b.report.json").read_text())["iterations"] == 4
    r = run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg2, "--threads", 1)
    assert statuses(out)["b.png"] == SKIPPED, r.output

    # --no-resume redoes everything
    before = mtimes(out, "b.svg", "b.report.json")
    assert run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg2,
               "--no-resume").exit_code == 1
    assert statuses(out)["a.png"] == DONE and statuses(out)["b.png"] == DONE
    after = mtimes(out, "b.svg", "b.report.json")
    assert all(after[k] > before[k] for k in after)


def test_init_dir_pairs_svgs_from_another_folder(tmp_path):
    images, svgs, out = tmp_path / "images", tmp_path / "svgs", tmp_path / "out"
    images.mkdir()
    svgs.mkdir()
    disc_png(images / "x.png", 18, 15, 8, (0, 0, 255))
    circle_svg(svgs / "x.svg")
    r = run("batch", images, "-o", out, "--mode", "refine", "--config", config(tmp_path),
            "--init-dir", svgs, "-q")
    assert r.exit_code == EXIT_OK, r.output
    assert statuses(out) == {"x.png": DONE}
    assert Path(read_csv(out)["x.png"]["init_svg"]) == svgs / "x.svg"
    assert "[1/1]" not in r.output  # quiet


def test_interrupted_image_is_not_taken_as_finished(folder, tmp_path, monkeypatch):
    """Ctrl-C during b: exit 130, a kept, b's best-so-far marked interrupted, c not run;
    nothing half-written. The next run redoes b and only b."""
    import vecfit.fitting.loop as fit_module  # jobs.fit imports the loop where it runs it
    real = fit_module.optimize

    def interrupted(scene, target, settings, progress=None, **kwargs):
        def stop(p):
            if p.iteration == 2 and scene.shapes[0].fill.color[0] > 0.5:  # b's red circle
                raise KeyboardInterrupt
        return real(scene, target, settings, progress=stop, **kwargs)

    monkeypatch.setattr(fit_module, "optimize", interrupted)
    out = tmp_path / "out"
    cfg = config(tmp_path)
    r = run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg)
    assert r.exit_code == EXIT_INTERRUPTED, r.output
    assert "Traceback" not in r.output and "interrupted" in r.output
    assert statuses(out) == {"a.png": DONE, "b.png": INTERRUPTED, "c.png": NOT_RUN, "d.png": UNPAIRED}
    assert read_json(out)["interrupted"] is True
    assert json.loads((out / "b.report.json").read_text())["interrupted"] is True
    no_leftovers(out)

    monkeypatch.setattr(fit_module, "optimize", real)
    a = mtimes(out, "a.svg")
    assert run("batch", folder, "-o", out, "--mode", "refine", "--config", cfg).exit_code == 1
    assert statuses(out) == {"a.png": SKIPPED, "b.png": DONE, "c.png": FAILED, "d.png": UNPAIRED}
    assert mtimes(out, "a.svg") == a
    assert json.loads((out / "b.report.json").read_text())["interrupted"] is False


# Job functions standing in for refine (the job protocol's signature), found by "test_batch:NAME" in
# this process or in a worker process.

def exploding_refine(inputs, config, outputs, progress=None):
    if inputs.image.stem == "a":
        raise RuntimeError("boom")
    from vecfit.jobs.refine import run as refine
    report = refine(inputs, config, outputs, progress=progress)
    if inputs.image.stem == "b":
        report["optimized"]["mse"] = math.nan
    return report


def crashing_refine(inputs, config, outputs, progress=None):
    if inputs.image.stem == "crash":
        os._exit(3)  # as a crash in native code would end the worker
    from vecfit.jobs.refine import run as refine
    return refine(inputs, config, outputs, progress=progress)


def test_unexpected_exceptions_and_nan_are_recorded(folder, tmp_path):
    out = tmp_path / "out"
    result = run_batch(folder, out, "refine", config_file=config(tmp_path),
                       job="test_batch:exploding_refine")
    assert result.exit_code == EXIT_FAILED
    rows = {r["file"]: r for r in result.rows}
    assert rows["a.png"]["status"] == FAILED and rows["a.png"]["reason"] == "RuntimeError: boom"
    assert "Traceback" in read_json(out)["images"][0]["traceback"]
    assert rows["b.png"]["status"] == FAILED and "not finite" in rows["b.png"]["reason"]
    assert not (out / "b.report.json").exists()  # a NaN result is not a finished one
    assert [r["status"] for r in result.rows] == [FAILED, FAILED, FAILED, UNPAIRED]
    assert statuses(out) == {"a.png": FAILED, "b.png": FAILED, "c.png": FAILED, "d.png": UNPAIRED}


@pytest.mark.slow
def test_worker_processes_divide_the_cores_and_survive_a_crash(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    for name, color in (("a", (0, 0, 255)), ("b", (255, 0, 0)), ("crash", (0, 0, 0))):
        disc_png(d / f"{name}.png", 18, 15, 8, color)
        circle_svg(d / f"{name}.svg")
    out = tmp_path / "out"
    result = run_batch(d, out, "refine", config_file=config(tmp_path), jobs=2,
                       job="test_batch:crashing_refine")
    assert result.workers == 2 and result.threads == max(1, available_cores() // 2)
    assert statuses(out) == {"a.png": DONE, "b.png": DONE, "crash.png": FAILED}
    assert read_csv(out)["crash.png"]["reason"] == CRASHED
    assert result.exit_code == EXIT_FAILED
    for name in ("a", "b"):
        report = json.loads((out / f"{name}.report.json").read_text())
        assert report["config"]["optimize"]["threads"] == result.threads
    assert read_json(out)["workers"] == 2
    no_leftovers(out)


# ----------------------------------------------------------- trace and paint

def test_paint_mode(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    disc_png(d / "p.png", 16, 16, 8, (0, 0, 255))
    cfg = config(tmp_path, "[optimize]\niterations = 3\n[paint]\npaths = 4\n")
    out = tmp_path / "out"
    r = run("batch", d, "-o", out, "--mode", "paint", "--config", cfg)
    assert r.exit_code == EXIT_OK, r.output
    assert statuses(out) == {"p.png": DONE}
    report = json.loads((out / "p.report.json").read_text())
    assert report["command"] == "paint" and report["paint"]["paths"] == 4
    assert (out / "p.svg").is_file() and (out / "p.compare.png").is_file()
    assert (out / "thumbs" / "p.result.png").is_file()
    r = run("batch", d, "-o", out, "--mode", "paint", "--config", cfg)
    assert r.exit_code == EXIT_OK and statuses(out) == {"p.png": SKIPPED}


@pytest.mark.skipif(not (configs_dir() / "trace.toml").exists(),
                    reason="configs/trace.toml (the trace command's defaults) is not there yet")
def test_trace_mode(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    disc_png(d / "t.png", 16, 16, 8, (0, 0, 255))
    out = tmp_path / "out"
    r = run("batch", d, "-o", out, "--mode", "trace", "--config", config(tmp_path))
    assert r.exit_code == EXIT_OK, r.output
    assert statuses(out) == {"t.png": DONE}
    report = json.loads((out / "t.report.json").read_text())
    assert report["command"] == "trace" and report["shapes"] >= 1
    assert float(read_csv(out)["t.png"]["psnr_after"]) > 15


# ------------------------------------------------------------------- Dask

@pytest.mark.slow
def test_dask_scheduler(folder, tmp_path):
    distributed = pytest.importorskip("distributed")
    import torch
    out = tmp_path / "out"
    torch_threads = torch.get_num_threads()  # the task sets it, here in this process
    try:
        with distributed.LocalCluster(processes=False, n_workers=1, threads_per_worker=1,
                                      dashboard_address=None) as cluster:
            r = run("batch", folder, "-o", out, "--mode", "refine", "--config", config(tmp_path),
                    "--scheduler", cluster.scheduler_address)
    finally:
        torch.set_num_threads(torch_threads)
    assert r.exit_code == EXIT_FAILED, r.output
    assert statuses(out) == {"a.png": DONE, "b.png": DONE, "c.png": FAILED, "d.png": UNPAIRED}
    summary = read_json(out)
    assert summary["scheduler"] == cluster.scheduler_address
    assert summary["threads_per_worker"] == 1
    assert json.loads((out / "a.report.json").read_text())["config"]["optimize"]["threads"] == 1


def test_scheduler_without_distributed_is_a_clear_error(folder, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import fails
    r = run("batch", folder, "-o", tmp_path / "out", "--mode", "refine", "--scheduler",
            "tcp://127.0.0.1:8786")
    assert r.exit_code == EXIT_USAGE
    assert "needs the optional dependency 'distributed'" in r.output and "Traceback" not in r.output


# ------------------------------------------------------------- bad usage

def test_bad_usage(folder, tmp_path):
    out = tmp_path / "out"
    r = run("batch", tmp_path / "nope", "-o", out, "--mode", "refine")
    assert r.exit_code == EXIT_USAGE and "does not exist" in r.output
    bad = config(tmp_path, "[optimize]\niteratons = 3\n", "bad.toml")
    r = run("batch", folder, "-o", out, "--mode", "refine", "--config", bad)
    assert r.exit_code == EXIT_USAGE and "unknown setting 'optimize.iteratons'" in r.output
    r = run("batch", folder, "-o", folder, "--mode", "paint")
    assert r.exit_code == EXIT_USAGE and "output folder must differ" in r.output
    r = run("batch", folder, "-o", out, "--mode", "paint", "--init-dir", folder)
    assert r.exit_code == EXIT_USAGE and "--init-dir is for --mode refine" in r.output
    r = run("batch", folder, "-o", out, "--mode", "vectorise")
    assert r.exit_code == EXIT_USAGE
    assert not out.exists()  # nothing started
    r = run("batch", "--help")
    assert r.exit_code == 0
    for code in ("0 ", "1 ", "2 ", "130 "):
        assert f"  {code}" in r.output


def test_colliding_names_and_empty_folder(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    disc_png(d / "x.png", 16, 16, 8, (0, 0, 255))
    Image.open(d / "x.png").convert("RGB").save(d / "x.JPG")
    circle_svg(d / "x.svg")
    out = tmp_path / "out"
    r = run("batch", d, "-o", out, "--mode", "refine")
    assert r.exit_code == EXIT_FAILED
    rows = read_csv(out)
    assert set(rows) == {"x.JPG", "x.png"}
    assert all(v["status"] == FAILED and "would collide" in v["reason"] for v in rows.values())
    assert not (out / "x.svg").exists()

    empty = tmp_path / "empty"
    empty.mkdir()
    r = run("batch", empty, "-o", tmp_path / "out2", "--mode", "paint")
    assert r.exit_code == EXIT_OK and "no images" in r.output
    assert read_json(tmp_path / "out2")["images"] == []

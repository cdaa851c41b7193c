"""vecfit.batch's planning and summary, without running a job: which files of a folder
become tasks, how images pair with SVGs, when an earlier run counts as finished, and what
the summary rows and lines say. (tests/e2e/test_batch.py runs whole batches.)"""
from __future__ import annotations

import csv
import json
import math
import os

from vecfit.batch.plan import (DONE, FAILED, SKIPPED, UNPAIRED, comparable, empty_row, find_images,
                               finished_report, make_plan, metrics_into, result_row)
from vecfit.batch.progress import outcome_line
from vecfit.batch.summary import count, write_csv

CONFIG = {"optimize": {"iterations": 5, "threads": 2, "device": "cpu"}, "loss": {"kind": "mse"}}


def touch(folder, *names):
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        (folder / name).write_bytes(b"x")


def test_find_images_takes_image_suffixes_in_name_order(tmp_path):
    touch(tmp_path, "b.PNG", "a.jpg", "c.svg", "notes.txt", "d.webp")
    (tmp_path / "e.png").mkdir()  # a folder is no image
    assert [p.name for p in find_images(tmp_path)] == ["a.jpg", "b.PNG", "d.webp"]


def test_plan_pairs_images_with_svgs_and_explains_the_rest(tmp_path):
    src, out = tmp_path / "in", tmp_path / "out"
    touch(src, "cat.png", "dog.png", "owl.png", "owl.svg", "owl.svgz", "fox.png", "fox.jpg", "cat.svg")
    plan = make_plan(src, out, "refine", CONFIG)
    assert plan.order == ["cat.png", "dog.png", "fox.jpg", "fox.png", "owl.png"]
    assert [t.file for t in plan.tasks] == ["cat.png"]
    task = plan.tasks[0]
    assert task.init_svg == str(src / "cat.svg") and task.svg == str(out / "cat.svg")
    assert task.report == str(out / "cat.report.json") and task.comparison == str(out / "cat.compare.png")
    assert task.job == "vecfit.jobs.refine:run" and task.config == CONFIG and task.config is not CONFIG
    rows = plan.rows
    assert rows["dog.png"]["status"] == UNPAIRED and "no dog.svg" in rows["dog.png"]["reason"]
    assert rows["owl.png"]["status"] == FAILED and "owl.svg, owl.svgz" in rows["owl.png"]["reason"]
    assert rows["fox.png"]["status"] == FAILED and "outputs would collide" in rows["fox.png"]["reason"]
    # unpaired modes take every image; retarget takes the SVGs themselves
    assert [t.file for t in make_plan(src, out, "trace", CONFIG).tasks] == ["cat.png", "dog.png", "owl.png"]
    svgs = make_plan(src, out, "retarget", CONFIG)
    assert [t.file for t in svgs.tasks] == ["cat.svg"] and svgs.rows["owl.svgz"]["status"] == FAILED
    # an output format names the outputs
    assert make_plan(src, out, "trace", CONFIG, fmt="pdf").tasks[0].svg == str(out / "cat.pdf")


def finish(task, **changes):
    """Write the outputs and the report a finished run leaves."""
    for path in (task.svg, task.comparison):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        open(path, "w").close()
    report = {"command": task.mode, "interrupted": False, "config": {**CONFIG, "optimize": {"iterations": 5}},
              "init": task.init_svg, "optimized": {"mse": 0.01, "psnr": 20.0, "ssim": 0.9},
              "initial": {"mse": 0.04, "psnr": 14.0, "ssim": 0.5}, "seconds": {"total": 3.5}, **changes}
    with open(task.report, "w") as f:
        json.dump(report, f)
    later = os.stat(task.image).st_mtime + 10
    os.utime(task.report, (later, later))
    return report


def test_a_finished_run_is_skipped_unless_something_changed(tmp_path):
    src, out = tmp_path / "in", tmp_path / "out"
    touch(src, "cat.png")
    task = make_plan(src, out, "trace", CONFIG).tasks[0]
    finish(task)
    # threads and device do not change the result: still finished
    assert finished_report(task) is not None
    plan = make_plan(src, out, "trace", {**CONFIG, "optimize": {"iterations": 5, "threads": 8}})
    assert not plan.tasks and plan.rows["cat.png"]["status"] == SKIPPED
    assert plan.rows["cat.png"]["seconds"] == 3.5 and plan.rows["cat.png"]["psnr_after"] == 20.0
    assert make_plan(src, out, "trace", CONFIG, resume=False).tasks  # --no-resume runs it again
    assert make_plan(src, out, "trace", {**CONFIG, "optimize": {"iterations": 6}}).tasks
    assert make_plan(src, out, "paint", CONFIG).tasks  # another command
    for changes in ({"interrupted": True}, {"optimized": {"mse": math.nan}}, {"format": "pdf"}):
        finish(task, **changes)
        assert finished_report(task) is None, changes
    finish(task)
    os.remove(task.comparison)
    assert finished_report(task) is None
    finish(task)
    later = os.stat(task.report).st_mtime + 10
    os.utime(task.image, (later, later))  # the image changed after the report
    assert finished_report(task) is None


def test_comparable_drops_threads_and_device_only():
    assert comparable(CONFIG) == {"optimize": {"iterations": 5}, "loss": {"kind": "mse"}}
    assert CONFIG["optimize"]["threads"] == 2  # (a copy)


def test_rows_take_the_reports_metrics():
    row = metrics_into(empty_row("cat", "cat.png", DONE),
                       {"initial": {"mse": 0.5, "psnr": 3.0}, "optimized": {"mse": 0, "psnr": None},
                        "file": {"paths": 4, "segments": 31},
                        "colours": {"palette": ["#ff0000"], "layers": {"layers": [1, 2], "split": [3]}}})
    assert row["psnr_before"] == 3.0 and row["psnr_after"] == math.inf and row["mse_after"] == 0.0
    assert row["ssim_before"] is None and row["file_paths"] == 4 and row["file_segments"] == 31
    assert row["palette"] == ["#ff0000"] and row["layers"] == 2 and row["split_colours"] == 1


def test_outcome_lines_and_counts(tmp_path):
    src = tmp_path / "in"
    touch(src, "cat.png")
    task = make_plan(src, tmp_path / "out", "trace", CONFIG).tasks[0]
    done = result_row(task, DONE, report={"initial": {"psnr": 14.0}, "optimized": {"psnr": 20.25}}, seconds=2.0)
    assert outcome_line(done) == "cat.png: done, PSNR 14.00 -> 20.25 dB (2.00 s)"
    perfect = result_row(task, SKIPPED, report={"optimized": {"mse": 0}}, seconds=2.0)
    assert outcome_line(perfect) == "cat.png: skipped (finished), PSNR ? -> inf dB"
    failed = empty_row("dog", "dog.png", FAILED, "out of memory")
    assert outcome_line(failed) == "dog.png: failed: out of memory"
    assert count([done, perfect, failed])[DONE] == 1 and count([done, perfect, failed])[FAILED] == 1
    write_csv(tmp_path / "summary.csv", [done, failed])
    with open(tmp_path / "summary.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["status"] for r in rows] == [DONE, FAILED]
    assert rows[0]["psnr_after"] == "20.25" and rows[0]["svg"] == "cat.svg" and rows[1]["svg"] == ""

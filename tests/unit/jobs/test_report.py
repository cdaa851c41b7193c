"""The one report builder (vecfit/jobs/report.py), the loop's runs joined into one
(retarget's rounds), and a job's settings checked once, with its device resolved once."""
from __future__ import annotations

import time

import pytest

from vecfit.fitting.result import Result, joined
from vecfit.fitting.settings import Settings
from vecfit.jobs.config import resolve
from vecfit.jobs.protocol import Outputs
from vecfit.jobs.report import job_report
from vecfit.renderer import device as devices

SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="36">'
       '<circle cx="20" cy="18" r="10" fill="#884444"/></svg>')


def _report(**changes):
    config = resolve("refine")
    arguments = dict(started=time.perf_counter(), inputs={"command": "refine", "later": lambda: 7},
                     canvas={"size": [48, 36]}, background=(1.0, 1.0, 1.0, 1.0),
                     initial={"mse": 0.04, "psnr": 14.0, "ssim": 0.5},
                     optimized={"mse": 0.01, "psnr": 20.0, "ssim": 0.9}, shapes=1, written=SVG.encode())
    arguments.update(changes)
    result = Result(losses=[0.2, 0.1], iterations=2, seconds=0.5, parameters={"points": 10, "colors": 4},
                    iteration_seconds=[0.2, 0.3])
    return job_report(config, Settings.defaults(), Outputs.nowhere(), result, **arguments)


def test_the_report_names_each_fact_once_in_one_order():
    report = _report()
    keys = list(report)
    assert keys[0] == "vecfit" and keys[-1] == "config"
    assert report["later"] == 7  # a callable entry is called when the report is made
    assert keys.index("size") < keys.index("background") < keys.index("initial") < keys.index("iterations")
    assert report["background"] == "#ffffff"
    assert report["psnr_gain_db"] == pytest.approx(6.0) and report["mse_ratio"] == pytest.approx(4.0)
    assert report["seconds"]["optimize"] == 0.5 and report["seconds"]["per_iteration"] == 0.25
    assert report["seconds"]["iterations"] == [0.2, 0.3]
    assert report["parameters"] == {"points": 10, "colors": 4, "total": 14}
    assert report["file"]["paths"] == 1 and report["file"]["bytes"] == len(SVG)  # the file written
    assert report["device"] == devices.device_name(devices.resolve("auto"))  # never "auto"
    assert report["effort"] == "normal" and report["config"]["optimize"]["device"] == "auto"


def test_no_gain_without_a_start_to_compare_and_none_over_an_exact_match():
    assert _report(initial=None)["psnr_gain_db"] is None and _report(initial=None)["mse_ratio"] is None
    exact = _report(optimized={"mse": 0.0, "psnr": float("inf"), "ssim": 1.0})
    assert exact["mse_ratio"] is None


def test_the_job_places_its_own_entries():
    report = _report(measured={"changed_region": {"pixels": 3}}, outcome={"untangled_outlines": 0})
    keys = list(report)
    assert keys.index("mse_ratio") < keys.index("changed_region") < keys.index("iterations")
    assert keys.index("shapes") < keys.index("untangled_outlines") < keys.index("file")


def test_runs_joined_add_up_and_keep_the_last_ones_rates():
    a = Result(losses=[3.0, 2.0], iterations=2, seconds=1.0, skipped_steps=1, parameters={"points": 8},
               iteration_seconds=[0.5, 0.5], coarse_iterations=1, point_rate=2.0, outline_density=0.1)
    b = Result(losses=[1.0], iterations=1, seconds=0.25, interrupted=True, parameters={"points": 8},
               iteration_seconds=[0.25], point_rate=1.5, outline_density=0.2, best_loss=1.0)
    both = joined([a, b])
    assert both.losses == [3.0, 2.0, 1.0] and both.iterations == 3 and both.seconds == 1.25
    assert both.skipped_steps == 1 and both.coarse_iterations == 1 and both.interrupted
    assert both.iteration_seconds == [0.5, 0.5, 0.25]
    assert (both.point_rate, both.outline_density, both.best_loss, both.parameters) == (1.5, 0.2, 1.0, {"points": 8})
    assert joined([]).iterations == 0 and not joined([]).interrupted


def test_a_jobs_settings_are_checked_once_and_its_device_resolved_once(tmp_path, monkeypatch):
    """resolve() checks them; the job takes them as checked, resolves "auto" once, and the
    loop renders on that name (not "auto" again at every iteration)."""
    import vecfit
    import vecfit.fitting.loop as loop
    from helpers import two_shapes_png

    two_shapes_png(tmp_path / "in.png")
    checks, devices_rendered = [], set()
    real_check, real_render = Settings.check, loop.render
    monkeypatch.setattr(Settings, "check", lambda self: (checks.append(1), real_check(self))[1])

    def render(*args, device, **kwargs):
        devices_rendered.add(device)
        return real_render(*args, device=device, **kwargs)

    monkeypatch.setattr(loop, "render", render)
    _, report = vecfit.refine(tmp_path / "in.png", SVG, settings={"optimize": {"iterations": 2, "threads": 1}})
    assert len(checks) == 1
    assert devices_rendered == {report["device"]} == {devices.device_name(devices.resolve("auto"))}


def test_a_bad_device_is_refused_where_the_settings_are_made():
    from vecfit.errors import VecfitError
    with pytest.raises(VecfitError, match="device must be one of auto, cpu, cuda or cuda:N, not 'gpu'"):
        resolve("refine", overrides={"optimize": {"device": "gpu"}})

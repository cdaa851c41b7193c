"""Interruptions of real processes: Ctrl-C (SIGINT) and SIGKILL during the commands.

Each leaves the previous output or a complete new one (never a partial or .tmp file) and
its inputs untouched; Ctrl-C exits with 130, during torch's import too, and cancels a
long render at once instead of waiting for the core. A batch killed mid-run resumes
without redoing its finished images. About 60 s (each process imports torch)."""
from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fuzzing import NS

pytestmark = pytest.mark.slow  # over 30 s: `make test-fast` leaves it out

ROOT = Path(__file__).resolve().parents[2]
PHOTO = ROOT / "examples" / "chelsea.png"  # 240 x 160


def start(*args, cwd):
    # (SIGINT back to its default: a shell starts background jobs with it ignored, and
    # Python then installs no handler, which would make these tests depend on how they run)
    return subprocess.Popen([sys.executable, "-m", "vecfit", *map(str, args)], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def finish(proc, timeout=60):
    out, err = proc.communicate(timeout=timeout)
    return proc.returncode, out, err


def wait_for_torch_loading(proc, timeout=60):
    """Waits until the process has begun loading torch's C++ library: the middle of
    torch's import, which goes on for a second or more after that."""
    maps = Path(f"/proc/{proc.pid}/maps")
    if not maps.exists():  # (not Linux: a fixed wait instead)
        time.sleep(0.5)
        return
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and proc.poll() is None and "libtorch" not in maps.read_text():
        time.sleep(0.005)


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def no_leftovers(folder: Path):
    stray = [p.name for p in folder.rglob("*") if p.name.endswith(".tmp")]  # atomic writes' temporaries
    assert not stray, stray


def test_ctrl_c_while_torch_is_imported(tmp_path):
    # (paint imports torch at once; render of a plain file needs no torch at all, and
    # once finished in the 0.4 s this test used to wait, so its Ctrl-C hit an exiting
    # process)
    target = tmp_path / "target.png"
    target.write_bytes(PHOTO.read_bytes())
    out = tmp_path / "out.svg"
    proc = start("paint", target, "-o", out, "--iterations", "100000", "--threads", "1", cwd=tmp_path)
    wait_for_torch_loading(proc)
    proc.send_signal(signal.SIGINT)
    code, _, err = finish(proc)
    assert code == 130 and "Traceback" not in err and "interrupted" in err, (code, err)
    assert not out.exists()
    no_leftovers(tmp_path)


def test_ctrl_c_cancels_a_long_render(tmp_path):
    circles = "".join(f'<circle cx="{(i * 37) % 3000}" cy="{(i * 91) % 3000}" r="{300 + i % 500}" '
                      f'fill="#{(i * 2654435761) % 0xFFFFFF:06x}" fill-opacity="0.5"/>' for i in range(300))
    svg = tmp_path / "heavy.svg"
    svg.write_text(f'<svg {NS} width="3000" height="3000">{circles}</svg>')
    out = tmp_path / "heavy.png"
    proc = start("render", svg, "-o", out, "--samples", "8", "--mode", "analytic", cwd=tmp_path)
    time.sleep(6)  # well into the core's work (which takes minutes)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    code, _, err = finish(proc)
    assert code == 130 and "Traceback" not in err, err
    assert time.monotonic() - sent < 5  # not after the core finished
    assert not out.exists()
    no_leftovers(tmp_path)


def _previous_outputs(folder: Path) -> dict:
    """Outputs of an earlier run, which an interrupted one must leave or replace whole."""
    names = {"svg": "out.svg", "report": "out.report.json", "comparison": "out.compare.png"}
    (folder / names["svg"]).write_text(f'<svg {NS} width="240" height="160"><rect width="9" height="9"/></svg>')
    (folder / names["report"]).write_text("{}")
    (folder / names["comparison"]).write_bytes(PHOTO.read_bytes())
    return {k: folder / v for k, v in names.items()}


def _check_outputs(outputs: dict, before: dict):
    svg = outputs["svg"]
    assert svg.exists()
    text = svg.read_text()
    assert digest(svg) == before["svg"] or (text.rstrip().endswith("</svg>") and "nan" not in text)
    report = outputs["report"]
    if report.exists():  # a report marks a finished (or a cleanly interrupted) run
        json.loads(report.read_text())


@pytest.mark.parametrize("command, sig", [("refine", signal.SIGINT), ("trace", signal.SIGKILL),
                                          ("paint", signal.SIGINT), ("refine", signal.SIGKILL)])
def test_interrupted_fit_leaves_whole_files(tmp_path, command, sig):
    target = tmp_path / "target.png"
    target.write_bytes(PHOTO.read_bytes())
    init = tmp_path / "init.svg"
    init.write_text(f'<svg {NS} viewBox="0 0 240 160"><rect width="240" height="160" fill="#777"/>'
                    '<circle cx="120" cy="80" r="50" fill="#c84"/></svg>')
    inputs = {p: digest(p) for p in (target, init)}
    outputs = _previous_outputs(tmp_path)
    before = {k: digest(p) for k, p in outputs.items()}
    args = [command, target] + ([init] if command == "refine" else []) + [
        "-o", outputs["svg"], "--iterations", "100000", "--threads", "1"]
    proc = start(*args, cwd=tmp_path)
    time.sleep(7)  # into the optimisation loop
    proc.send_signal(sig)
    code, _, err = finish(proc)
    if sig == signal.SIGINT:
        assert code == 130 and "Traceback" not in err, err
    else:
        assert code == -signal.SIGKILL
    _check_outputs(outputs, before)
    assert {p: digest(p) for p in inputs} == inputs
    no_leftovers(tmp_path)


def test_batch_resumes_after_sigkill(tmp_path):
    from PIL import Image
    images = tmp_path / "in"
    images.mkdir()
    photo = Image.open(PHOTO).convert("RGB").resize((48, 32))
    for i in range(4):
        photo.rotate(90 * i, expand=False).save(images / f"p{i}.png")
    inputs = {p: digest(p) for p in images.iterdir()}
    out = tmp_path / "out"
    config = tmp_path / "fast.toml"
    config.write_text("[optimize]\niterations = 150\nthreads = 1\n[trace]\npaths = 8\n")
    proc = start("batch", images, "-o", out, "--mode", "trace", "--config", config, "-q", cwd=tmp_path)
    deadline = time.monotonic() + 90
    while not (out / "p0.report.json").exists() and time.monotonic() < deadline:
        time.sleep(0.1)
    assert (out / "p0.report.json").exists()
    proc.send_signal(signal.SIGKILL)
    finish(proc)
    no_leftovers(out)
    finished = {p.name for p in out.glob("*.report.json")}
    assert finished and len(finished) < 4
    stamps = {n: (out / n).stat().st_mtime_ns for n in finished}
    code, _, err = finish(start("batch", images, "-o", out, "--mode", "trace", "--config", config, "-q",
                                cwd=tmp_path), timeout=180)
    assert code == 0, err
    assert all((out / n).stat().st_mtime_ns == stamps[n] for n in finished)  # not redone
    assert len(list(out.glob("*.report.json"))) == 4
    assert {p: digest(p) for p in images.iterdir()} == inputs
    no_leftovers(out)

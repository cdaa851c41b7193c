"""PDF and DXF from the command line: every job's -o NAME.pdf|.dxf or --format, batch
--format, render -o OUT.pdf|.dxf, and the refusals (a format the name contradicts, a
place that cannot be written: exit 2, nothing written)."""
from __future__ import annotations

import io
import json

import numpy as np
import pytest
from PIL import Image

from helpers import run

ezdxf = pytest.importorskip("ezdxf")
pdfium = pytest.importorskip("pypdfium2")

SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="48" height="32">'
       '<rect width="48" height="32" fill="#fff"/>'
       '<circle cx="20" cy="16" r="9" fill="#2050c0"/>'
       '<path d="M4 28 L44 4" fill="none" stroke="#c02020" stroke-width="3"/></svg>')


@pytest.fixture
def files(tmp_path):
    svg = tmp_path / "d.svg"
    svg.write_text(SVG)
    assert run("render", svg, "-o", tmp_path / "d.png").exit_code == 0
    return tmp_path


def pdf_size(path):
    return pdfium.PdfDocument(path.read_bytes())[0].get_size()


def test_trace_to_pdf_by_suffix(files):
    out = files / "t.pdf"
    r = run("trace", files / "d.png", "-o", out, "--no-refine", "-q")
    assert r.exit_code == 0, r.output
    assert out.read_bytes().startswith(b"%PDF-1.4") and pdf_size(out) == pytest.approx((36, 24))
    report = json.loads((files / "t.report.json").read_text())
    assert report["output"] == str(out) and report["format"] == "pdf"
    assert (files / "t.compare.png").is_file() and "pdf: " in r.output


def test_refine_to_dxf_by_format(files):
    """--format dxf names the default output NAME.vecfit.dxf."""
    r = run("refine", files / "d.png", files / "d.svg", "--format", "dxf", "--iterations", 2, "-q")
    assert r.exit_code == 0, r.output
    out = files / "d.vecfit.dxf"
    doc = ezdxf.readfile(out)
    assert len(doc.audit().errors) == 0
    assert {"#2050c0", "#c02020"} <= {layer.dxf.name for layer in doc.layers}
    assert json.loads((files / "d.vecfit.report.json").read_text())["format"] == "dxf"


def test_svg_reports_stay_as_they_were(files):
    r = run("trace", files / "d.png", "-o", files / "t.svg", "--no-refine", "-q")
    assert r.exit_code == 0, r.output
    assert "format" not in json.loads((files / "t.report.json").read_text())


@pytest.mark.parametrize("args, message", [
    (["-o", "{d}/x.svg", "--format", "pdf"], "the name says SVG but the format asked is PDF"),
    (["-o", "{d}/x.dxf", "--format", "pdf"], "the name says DXF"),
    (["-o", "{d}/afile/x.pdf"], "cannot write there"),
])
def test_refusals_write_nothing(files, args, message):
    (files / "afile").write_text("a file, not a folder")
    before = sorted(p.name for p in files.iterdir())
    r = run("trace", files / "d.png", "--no-refine", "-q", *[a.format(d=files) for a in args])
    assert r.exit_code == 2
    assert message in r.output and len([line for line in r.output.splitlines() if line.strip()]) == 1
    assert sorted(p.name for p in files.iterdir()) == before


def test_unknown_format_is_a_usage_error(files):
    r = run("trace", files / "d.png", "--no-refine", "--format", "eps")
    assert r.exit_code == 2 and "eps" in r.output


def test_render_converts(files):
    for suffix in ("pdf", "dxf"):
        r = run("render", files / "d.svg", "-o", files / f"r.{suffix}")
        assert r.exit_code == 0, r.output
    page = pdfium.PdfDocument((files / "r.pdf").read_bytes())[0]
    image = page.render(scale=2 / 0.75, rev_byteorder=True).to_numpy()[..., :3]
    assert image.shape[:2] == (64, 96)
    # the circle's middle is blue, the canvas's corner white
    assert np.abs(image[24, 32].astype(int) - (0x20, 0x50, 0xc0)).max() <= 2
    assert image[2, 90].tolist() == [255, 255, 255]
    assert ezdxf.readfile(files / "r.dxf").header["$INSUNITS"] == 4


def test_batch_format(files):
    folder = files / "in"
    folder.mkdir()
    Image.open(files / "d.png").save(folder / "a.png")
    (files / "c.toml").write_text("[optimize]\niterations = 0\n")
    r = run("batch", folder, "-o", files / "out", "--mode", "trace", "--format", "pdf", "--config", files / "c.toml",
            "-q")
    assert r.exit_code == 0, r.output
    assert (files / "out" / "a.pdf").read_bytes().startswith(b"%PDF")
    assert json.loads((files / "out" / "a.report.json").read_text())["format"] == "pdf"
    # the same run again is finished; asked in DXF it runs anew
    r = run("batch", folder, "-o", files / "out", "--mode", "trace", "--format", "dxf", "--config", files / "c.toml",
            "-q")
    assert r.exit_code == 0, r.output
    assert ezdxf.readfile(files / "out" / "a.dxf").audit().has_errors is False


def test_python_api_writes_by_suffix(files):
    import vecfit
    from vecfit.export import export
    text, report = vecfit.trace(files / "d.png", output=files / "api.dxf", settings={"optimize": {"iterations": 0}})
    assert text.startswith("<svg") or "<svg" in text[:200]
    assert report["format"] == "dxf" and (files / "api.dxf").is_file()
    assert export(text, files / "again.pdf") == "pdf"
    assert (files / "again.pdf").read_bytes().startswith(b"%PDF")
    assert io.BytesIO((files / "api.dxf").read_bytes()).read(1)

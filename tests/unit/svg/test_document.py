"""The document model (vecfit.svg.document): an SVG is parsed once per job, and what refine,
edit and retarget write keeps the file's ids, comments, namespaces and every attribute
they do not model."""
from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from PIL import Image, ImageDraw

from vecfit.jobs.config import resolve
from vecfit.jobs.protocol import Inputs, Outputs, job_function
from vecfit.svg.document import SvgDocument
from vecfit.svg.pathdata import format_path_data, parse_path_data, to_arrays

NS = 'xmlns="http://www.w3.org/2000/svg"'
INKSCAPE = "http://www.inkscape.org/namespaces/inkscape"
SOURCE = f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- drawn by hand -->
<svg {NS} xmlns:inkscape="{INKSCAPE}" xmlns:xlink="http://www.w3.org/1999/xlink"
     width="64" height="48" viewBox="0 0 64 48" data-origin="test">
  <title>a test drawing</title>
  <defs><linearGradient id="g" x1="0" y1="0" x2="1" y2="0"><stop offset="0" stop-color="#c33"/>
    <stop offset="1" stop-color="#33c"/></linearGradient></defs>
  <!-- the background -->
  <rect id="bg" x="0" y="0" width="64" height="48" fill="#eeeeee" class="paper"/>
  <g id="layer1" inkscape:label="Shapes" inkscape:groupmode="layer" transform="translate(2 1)">
    <circle id="sun" cx="20" cy="18" r="9" fill="url(#g)" data-note="keep me"/>
    <path id="hill" d="M0 40 C 16 20 40 20 60 40 Z" fill="#3a7" stroke="#142" stroke-width="2"
          inkscape:path-effect="none"/>
    <use xlink:href="#sun" x="24" y="8" id="sun2" opacity="0.5"/>
  </g>
</svg>
"""
# What the jobs may write: the values a Scene models (and the canvas, for retarget).
MODELLED = {"d", "cx", "cy", "r", "rx", "ry", "x", "y", "width", "height", "points", "x1", "y1",
            "x2", "y2", "fill", "stroke", "stroke-width", "opacity", "fill-opacity",
            "stroke-opacity", "transform", "style", "offset", "stop-color", "stop-opacity",
            "fx", "fy", "gradientTransform", "viewBox"}


def _everything_else(path) -> list:
    """Per element in document order: tag, and its attributes the jobs do not model;
    per comment, its text."""
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    parser.feed(path.read_bytes())
    out = []
    for e in parser.close().iter():
        if e.tag is ET.Comment:
            out.append(("comment", e.text))
        else:
            out.append((e.tag, sorted((k, v) for k, v in e.attrib.items() if k not in MODELLED)))
    return out


@pytest.fixture
def drawing(tmp_path):
    svg = tmp_path / "drawing.svg"
    svg.write_text(SOURCE)
    # a target: the drawing's own render, a little changed
    image = Image.new("RGB", (64, 48), (238, 238, 238))
    draw = ImageDraw.Draw(image)
    draw.ellipse((12, 10, 34, 32), fill=(180, 60, 90))
    draw.polygon([(2, 41), (30, 24), (62, 41)], fill=(60, 160, 110))
    target = tmp_path / "target.png"
    image.save(target)
    return svg, target


@pytest.mark.parametrize("job", ["refine", "edit", "retarget"])
def test_written_svg_keeps_what_the_job_does_not_model(drawing, tmp_path, job, monkeypatch):
    svg, target = drawing
    parses = []
    original_parse = SvgDocument.parse.__func__
    monkeypatch.setattr(SvgDocument, "parse", classmethod(
        lambda cls, *a, **k: parses.append(a[0]) or original_parse(cls, *a, **k)))
    overrides = {"optimize": {"iterations": 6, "threads": 1}}
    if job == "retarget":
        overrides["retarget"] = {"width": "48", "steps": 1, "iterations_per_step": 3,
                                 "final_iterations": 3, "work_size": 0}
    config = resolve(job, overrides=overrides)
    inputs = Inputs(svg=svg) if job == "retarget" else Inputs(image=target, svg=svg)
    outputs = Outputs.beside(tmp_path / "out.png")
    report = job_function(job)(inputs, config, outputs)
    assert report["iterations"] == 6
    # the SVG is parsed once per job (the report's file counts read the written one back)
    written = outputs.svg.read_bytes()
    assert len([data for data in parses if data != written]) == 1
    text = outputs.svg.read_text()
    assert "<!-- drawn by hand -->" in text and 'xmlns:inkscape="' + INKSCAPE + '"' in text
    assert "ns0:" not in text and "ns1:" not in text
    assert _everything_else(outputs.svg) == _everything_else(svg)
    root = ET.parse(outputs.svg).getroot()
    assert root.get("width") == ("48" if job == "retarget" else "64")


def test_generated_documents_are_never_parsed(tmp_path, monkeypatch):
    """A trace or a painting is fitted from the document it was made as, never from its text;
    the one parse is the report's count of what the written file holds."""
    calls = []
    original_parse = SvgDocument.parse.__func__
    monkeypatch.setattr(SvgDocument, "parse", classmethod(
        lambda cls, *a, **k: calls.append(a[0]) or original_parse(cls, *a, **k)))
    image = Image.new("RGB", (40, 30), (255, 255, 255))
    ImageDraw.Draw(image).rectangle((8, 6, 30, 22), fill=(20, 90, 200))
    image.save(tmp_path / "t.png")
    for job in ("trace", "paint"):
        config = resolve(job, overrides={"optimize": {"iterations": 2, "threads": 1}})
        report = job_function(job)(Inputs(image=tmp_path / "t.png"), config,
                                   Outputs.beside(tmp_path / f"{job}.png"))
        assert report["iterations"] == 2 and (tmp_path / f"{job}.vecfit.svg").exists()
        assert calls == [(tmp_path / f"{job}.vecfit.svg").read_bytes()]
        calls.clear()


def test_new_document_handles_follow_the_reader():
    doc = SvgDocument.new(10, 8)
    doc.add("rect", {"id": "a", "width": "4", "height": "4"})
    doc.add("circle", {"r": "2"})
    again = SvgDocument.parse(doc.serialize())
    assert doc.handles.keys() == again.handles.keys() == {"/", "a", "/1"}
    assert doc.text() == again.text()
    with pytest.raises(ValueError):
        doc.add("rect", {"id": "a"})


def test_xml_declaration_only_where_the_source_had_one():
    generated = SvgDocument.new(10, 8).serialize()
    assert generated.startswith(b"<svg")
    assert SvgDocument.parse(SOURCE).serialize().startswith(b'<?xml version="1.0" encoding="UTF-8"?>\n<!-- drawn by hand -->')
    bare = SvgDocument.parse(SOURCE.split("\n", 1)[1])
    assert bare.serialize().startswith(b"<!-- drawn by hand -->") and bare.copy().serialize() == bare.serialize()
    with_bom = SvgDocument.parse(b"\xef\xbb\xbf" + SOURCE.encode())
    assert with_bom.copy().serialize().startswith(b"<?xml ")


@pytest.mark.parametrize("d", ["M1 2 L5 1 L5 5 Z M6 6 Q7 7 8 6 C8 7 9 7 9 6 Z M2 8 L5 8",
                               "M0 0 C1 2 3 4 5 6 C7 8 9 9 0 0", "M3 3 C4 5 6 7 8 9 Z"])
def test_path_data_round_trips(d):
    points, degrees, subpaths = to_arrays(parse_path_data(d))
    written = format_path_data(points, degrees, subpaths)
    again = to_arrays(parse_path_data(written))
    assert np.array_equal(again[0], points) and list(again[1]) == list(degrees)
    assert list(again[2]) == list(subpaths)
    compact = format_path_data(points, degrees, subpaths, compact=True)
    assert len(compact) < len(written) and " C" not in compact and " Z" not in compact
    assert np.array_equal(to_arrays(parse_path_data(compact))[0], points)

"""Clip paths, masks and filters through the reader and the writer: what they become in
the Scene, what `vecfit info` says of them, optimised clip geometry written back into its
element, and references that loop, lead nowhere or nest too deeply."""
from __future__ import annotations

import time
import warnings
import xml.etree.ElementTree as ET

import pytest
import torch

from vecfit.scene.summary import summarize
from vecfit.svg.read import read_svg
from vecfit.svg.skips import VecfitWarning
from vecfit.svg.write import svg_bytes

NS = 'xmlns="http://www.w3.org/2000/svg"'

FILE = f"""<svg {NS} width="100" height="100" viewBox="0 0 100 100">
  <defs>
    <clipPath id="round" clip-rule="evenodd"><circle id="disc" cx="50" cy="50" r="30"/></clipPath>
    <mask id="fade" maskUnits="userSpaceOnUse" x="0" y="0" width="100" height="100" style="mask-type: alpha">
      <rect id="veil" width="100" height="100" fill="white" fill-opacity="0.5"/></mask>
    <filter id="soft" x="-20%" y="-20%" width="140%" height="140%">
      <feGaussianBlur stdDeviation="2 3" result="blur"/><feOffset dx="1" dy="2"/>
      <feMerge><feMergeNode in="blur"/><feMergeNode in="SourceGraphic"/></feMerge></filter>
  </defs>
  <rect id="a" width="100" height="60" fill="red" clip-path="url(#round)"/>
  <g id="b" style="clip-path: url(#round)" mask="url(#fade)"><rect id="c" y="60" width="100" height="40"/></g>
  <circle id="d" cx="20" cy="20" r="10" filter="url(#soft)"/>
</svg>"""


def read(tmp_path, text=FILE, name="in.svg"):
    path = tmp_path / name
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing here is skipped
        return read_svg(path)


def test_effects_in_the_scene(tmp_path):
    scene, _ = read(tmp_path)
    a, c, d = scene.shapes
    group = scene.groups[c.group]
    assert a.clip is group.clip  # one object per <clipPath>, shared by its references
    clip = a.clip
    assert clip.units == "userSpaceOnUse" and clip.source == "round"
    assert [s.fill_rule for s in clip.content.shapes] == ["evenodd"]  # clip-rule from the clipPath
    assert group.mask.kind == "alpha" and group.mask.region == (0, 0, 100, 100)
    assert [s.kind for s in d.filter.steps] == ["GaussianBlur", "Offset", "Merge"]
    assert d.filter.steps[0].params["std"] == (2, 3) and d.filter.steps[2].inputs == ["blur", "SourceGraphic"]
    assert d.filter.region == pytest.approx((-0.2, -0.2, 1.4, 1.4))
    # The clip's geometry is optimised with the rest; its paint is not (it does not show).
    kinds = scene.parameters()
    assert any(t is clip.content.shapes[0].geometry.radius for t in kinds["radii"])
    assert not any(t is clip.content.shapes[0].fill.color for t in kinds["colors"])
    assert any(t is group.mask.content.shapes[0].fill.color for t in kinds["colors"])


def test_info_lists_them(tmp_path):
    scene, _ = read(tmp_path)
    text = summarize(scene)
    assert "clip paths: 1 on 2 shapes and groups (1 shapes drawn in them): round" in text
    assert "masks: 1 on 1 shapes and groups (1 shapes drawn in them): fade" in text
    assert "filters: 1 on 1 shapes and groups (1 GaussianBlur, 1 Merge, 1 Offset): soft" in text


def test_clip_geometry_is_written_back_and_nothing_else_changes(tmp_path):
    scene, document = read(tmp_path)
    unchanged = svg_bytes(scene, document)
    assert unchanged == document.serialize()
    disc = scene.shapes[0].clip.content.shapes[0].geometry
    with torch.no_grad():
        disc.radius.fill_(24.5)
        disc.center.add_(torch.tensor([3.0, 0.0]))
    written = svg_bytes(scene, document)
    root = ET.fromstring(written)
    element = next(e for e in root.iter() if e.get("id") == "disc")
    assert (element.get("cx"), element.get("r")) == ("53", "24.5")
    again, _ = read(tmp_path, written.decode(), "out.svg")
    assert float(again.shapes[0].clip.content.shapes[0].geometry.radius) == 24.5
    # The clip path, the mask and the filter stay in the file, referenced as before.
    assert ET.tostring(root).count(b"url(#round)") == 2 and b"<filter" in written.replace(b"ns0:", b"")


@pytest.mark.parametrize("body, kind, says", [
    ('<clipPath id="c"><rect width="9" height="9" clip-path="url(#c)"/></clipPath>'
     '<rect width="50" height="50" clip-path="url(#c)"/>', "clip-path", "leads back to itself"),
    ('<mask id="m" mask="url(#m)"><rect width="9" height="9" fill="white"/></mask>'
     '<rect width="50" height="50" mask="url(#m)"/>', "mask", "leads back to itself"),
    ('<rect width="50" height="50" clip-path="url(#nowhere)"/>', "clip-path", "no <clipPath> #nowhere"),
    ('<rect width="50" height="50" mask="url(#r)"/><rect id="r" width="1" height="1"/>', "mask", "no <mask> #r"),
    ('<rect width="50" height="50" filter="url(#nowhere)"/>', "filter reference", "no <filter> #nowhere"),
    ('<filter id="f"><feTurbulence/></filter><rect width="50" height="50" filter="url(#f)"/>',
     "filter", "feTurbulence"),
])
def test_references_that_loop_or_lead_nowhere_warn(tmp_path, body, kind, says):
    path = tmp_path / "in.svg"
    path.write_text(f"<svg {NS} width='64' height='64'>{body}</svg>")
    with pytest.warns(VecfitWarning):
        scene, _ = read_svg(path)
    assert any(says in name for name in scene.skipped[kind])


def test_masks_nested_a_thousand_deep_are_cut_with_a_warning(tmp_path):
    masks = "".join(f'<mask id="m{i}"><rect width="64" height="64" fill="white" mask="url(#m{i + 1})"/></mask>'
                    for i in range(1000))
    path = tmp_path / "in.svg"
    path.write_text(f"<svg {NS} width='64' height='64'>{masks}<rect width='64' height='64' mask='url(#m0)'/></svg>")
    start = time.perf_counter()
    with pytest.warns(VecfitWarning, match="nested more than"):
        scene, _ = read_svg(path)
    assert time.perf_counter() - start < 10
    import vecfit
    image = vecfit.render(scene, 32, 32, samples=1)
    assert torch.isfinite(image).all() and float(image[16, 16, 3]) == pytest.approx(1.0)

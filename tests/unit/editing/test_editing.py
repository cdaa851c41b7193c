"""vecfit.editing: the changed region of an edit, seam carving and the points carried
through removed seams, and the settings' checks, on small arrays with known answers.
(tests/unit/jobs/test_edit.py and test_retarget.py run the jobs built on them.)"""
from __future__ import annotations

import numpy as np
import pytest
import torch
from PIL import Image

from vecfit.editing.mask import changed_region, grown, load_mask
from vecfit.editing.points import carve_points, point_tensors
from vecfit.editing.seams import carve, energy, foreground, remove_seam, shift, vertical_seam
from vecfit.editing.settings import EditSettings, RetargetSettings
from vecfit.errors import VecfitError
from vecfit.scene import Circle, Path, Rect, Scene, Shape, Solid


# ----------------------------------------------------------------------------- mask

def test_changed_region_keeps_large_changes_and_drops_specks():
    original = np.zeros((20, 20, 3), np.float32)
    edited = original.copy()
    edited[2:8, 2:8] = 0.5      # a 36-pixel edit
    edited[15, 15, 1] = 0.9     # a one-pixel speck (anti-aliasing, not an edit)
    edited[12, 3] = 0.05        # under the threshold
    region = changed_region(original, edited, threshold=0.1, min_area=4, grow=0)
    assert region.dtype == bool and region.sum() == 36 and region[2:8, 2:8].all()
    assert changed_region(original, edited, threshold=0.1, min_area=1, grow=0).sum() == 37
    # grown by one pixel (OpenCV's 3 x 3 ellipse is a cross): 8 x 8 less its 4 corners
    assert changed_region(original, edited, threshold=0.1, min_area=4, grow=1).sum() == 60


def test_grown_is_a_disc_dilation():
    region = np.zeros((9, 9), bool)
    region[4, 4] = True
    assert grown(region, 0) is region
    disc = grown(region, 2)
    assert disc.sum() == 17  # OpenCV's 5 x 5 ellipse: rows of 1, 5, 5, 5, 1
    assert disc[4, 2] and disc[2, 4] and disc[3, 2] and not disc[2, 3]
    assert not grown(np.zeros((5, 5), bool), 3).any()


def test_load_mask_reads_light_opaque_pixels_and_checks_the_size(tmp_path):
    rgba = np.zeros((4, 6, 4), np.uint8)
    rgba[..., 3] = 255
    rgba[1, 2] = (255, 255, 255, 255)   # white: changed
    rgba[2, 3] = (255, 255, 255, 40)    # white but nearly transparent: not
    rgba[3, 4] = (100, 100, 100, 255)   # dark grey: not
    path = tmp_path / "mask.png"
    Image.fromarray(rgba, "RGBA").save(path)
    mask = load_mask(path, (6, 4))
    assert mask.shape == (4, 6) and mask.sum() == 1 and mask[1, 2]
    with pytest.raises(VecfitError, match="the mask is 6x4 pixels but the edited image is 4x6"):
        load_mask(path, (4, 6))


# ---------------------------------------------------------------------------- seams

def test_vertical_seam_follows_the_cheapest_8_connected_path():
    e = np.full((4, 5), 9.0)
    for y, x in enumerate([3, 2, 1, 2]):  # a diagonal valley
        e[y, x] = 0.0
    assert vertical_seam(e).tolist() == [3, 2, 1, 2]
    # a cheaper column two steps away cannot be reached in one row: 8-connected only
    e = np.full((2, 5), 9.0)
    e[0, 0], e[1, 3] = 0.0, 0.0
    seam = vertical_seam(e)
    assert abs(seam[1] - seam[0]) <= 1


def test_remove_seam_drops_one_pixel_per_row():
    image = np.arange(12).reshape(3, 4)
    out = remove_seam(image, np.array([0, 3, 1]))
    assert out.tolist() == [[1, 2, 3], [4, 5, 6], [8, 10, 11]]
    rgb = np.stack([image] * 3, axis=2)
    assert remove_seam(rgb, np.array([0, 3, 1])).shape == (3, 3, 3)


def test_energy_and_foreground():
    flat = np.ones((5, 5, 3), np.float32)
    assert not energy(flat).any()
    step = np.zeros((5, 6), np.float32)
    step[:, 3:] = 1.0
    e = energy(step)
    assert e[:, 2:4].min() > 0 and not e[:, 0].any() and not e[:, 5].any()
    seen = np.zeros((2, 2, 3), np.float32)
    seen[0, 1] = (0.2, 0.9, 0.5)
    assert foreground(seen, np.zeros(3, np.float32)).tolist() == [[0, pytest.approx(0.9)], [0, 0]]


def test_carve_avoids_the_salient_columns():
    h, w = 6, 8
    image = np.zeros((h, w, 3), np.float32)
    salience = np.zeros((h, w), np.float32)
    salience[:, :4] = 10.0  # the left half matters
    out, seams = carve(image, 3, salience=salience)
    assert out.shape == (h, w - 3, 3) and len(seams) == 3
    for seam in seams:
        assert seam.min() >= 4  # each seam lies in what is left of the right half


def test_shift_moves_points_left_by_the_seams_wholly_left_of_them():
    seams = [np.array([2, 2, 5])]  # column 2 in rows 0 and 1, column 5 in row 2
    x = np.array([1.0, 2.5, 6.0, 4.0])
    y = np.array([0.5, 1.5, 1.0, 2.2])
    # x = 1 is left of the seam; 2.5 lies half way into its pixel; 6 and 4 in rows 1 and 2
    assert shift(x, y, seams).tolist() == [1.0, 2.0, 5.0, 4.0]
    assert shift(np.array([9.0]), np.array([0.0]), seams * 3).tolist() == [6.0]


def test_carve_points_maps_through_the_shape_transforms():
    circle = Shape(Circle(torch.tensor([3.0, 0.5]), torch.tensor(1.0)), fill=Solid(torch.ones(4)))
    scale = torch.tensor([[2.0, 0, 0], [0, 2.0, 0], [0, 0, 1.0]])  # the shape drawn at 2x
    rect = Shape(Rect(torch.tensor([0.0, 0.0]), torch.tensor([4.0, 1.0])), fill=Solid(torch.ones(4)),
                 transform=scale)
    flat = Shape(Rect(torch.tensor([5.0, 0.0]), torch.tensor([6.0, 1.0])), fill=Solid(torch.ones(4)),
                 transform=torch.tensor([[0.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]))  # drawn as a line
    scene = Scene(10, 4, [circle, rect, flat])
    assert [len(point_tensors(s)) for s in scene.shapes] == [1, 2, 2]
    seams = [np.zeros(4, np.int64)]  # column 0 of every row removed
    carve_points(scene, seams, 10, 4)
    # the circle's centre at pixel x 3 moves to 2; the rect's corners at pixels 0 and 8 move
    # to 0 and 7, which are 0 and 3.5 in its own (halved) units; the flattened one is left
    assert circle.geometry.center.tolist() == [2.0, 0.5]
    assert rect.geometry.p_min.tolist() == [0.0, 0.0] and rect.geometry.p_max.tolist() == [3.5, 1.0]
    assert flat.geometry.p_min.tolist() == [5.0, 0.0]
    # axis 1: horizontal seams move y (row 1 of every column removed)
    path = Shape(Path(torch.tensor([[1.0, 3.0], [2.0, 0.5]]), np.array([1]), [(0, 1, False)]),
                 stroke=Solid(torch.ones(4)))
    carve_points(Scene(4, 4, [path]), [np.ones(4, np.int64)], 4, 4, axis=1)
    assert path.geometry.points.tolist() == [[1.0, 2.0], [2.0, 0.5]]


# ------------------------------------------------------------------------- settings

def test_edit_settings_defaults_pass_and_bad_values_are_named():
    EditSettings.defaults().check()
    for change, message in [(dict(threshold=1.0), "edit.threshold must be below 1"),
                            (dict(changed_weight=0.5), "edit.changed_weight must be at least 1"),
                            (dict(anchor=float("nan")), "edit.anchor must be a number >= 0"),
                            (dict(grow=-1), "edit.grow must be 0 or more")]:
        with pytest.raises(VecfitError, match=message):
            EditSettings.defaults(**change).check()


def test_retarget_settings_defaults_pass_and_bad_values_are_named():
    RetargetSettings.defaults().check()
    for change, message in [(dict(steps=0), "retarget.steps must be at least 1"),
                            (dict(work_size=16), "retarget.work_size must be 0 or at least 32"),
                            (dict(final_iterations=-1), "retarget.final_iterations must be 0 or more"),
                            (dict(foreground=-0.5), "retarget.foreground must be a number >= 0")]:
        with pytest.raises(VecfitError, match=message):
            RetargetSettings.defaults(**change).check()
    RetargetSettings.defaults(work_size=0).check()

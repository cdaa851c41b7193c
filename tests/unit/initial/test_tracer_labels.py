"""The tracer's label helpers (vecfit/initial/tracer/labels.py) give what SciPy gives,
on random label maps, masks and graphs, edge cases included."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from vecfit.initial.tracer.labels import bounding_boxes, connected_groups, fill_holes


def blobs(rng, shape, levels):
    """A label map of blobs (smoothed noise cut into levels), so labels form regions."""
    noise = ndimage.gaussian_filter(rng.random(shape), 2.0)
    edges = np.quantile(noise, np.linspace(0, 1, levels + 1)[1:-1])
    return np.digitize(noise, edges).astype(np.int32)


@pytest.mark.parametrize("seed", range(6))
def test_bounding_boxes_are_scipys(seed):
    rng = np.random.default_rng(seed)
    labels = blobs(rng, (int(rng.integers(1, 60)), int(rng.integers(1, 60))), 7) - 1  # -1: none
    count = 9  # labels 6..8 never occur: None
    assert bounding_boxes(labels, count) == ndimage.find_objects(labels + 1, max_label=count)


def test_bounding_boxes_of_nothing():
    assert bounding_boxes(np.full((3, 4), -1, np.int32), 2) == [None, None]
    assert bounding_boxes(np.zeros((0, 0), np.int32), 1) == [None]
    assert bounding_boxes(np.array([[0, 1], [1, 1]], np.int32), 2) == [
        (slice(0, 1), slice(0, 1)), (slice(0, 2), slice(0, 2))]


@pytest.mark.parametrize("seed", range(8))
def test_fill_holes_is_scipys(seed):
    rng = np.random.default_rng(seed)
    mask = blobs(rng, (int(rng.integers(1, 50)), int(rng.integers(1, 50))), 3) == 1
    np.testing.assert_array_equal(fill_holes(mask), ndimage.binary_fill_holes(mask))


def test_fill_holes_of_a_ring_and_a_diagonal_gap():
    ring = np.ones((5, 5), bool)
    ring[2, 2] = False
    assert fill_holes(ring).all()
    # the hole reaches the border only diagonally: still a hole (4-connected outside)
    corner = np.array([[1, 0, 1], [0, 1, 1], [1, 1, 1]], bool)
    corner[0, 1] = True
    np.testing.assert_array_equal(fill_holes(corner), ndimage.binary_fill_holes(corner))
    assert not fill_holes(np.zeros((4, 4), bool)).any()


@pytest.mark.parametrize("seed", range(8))
def test_connected_groups_are_scipys(seed):
    rng = np.random.default_rng(seed)
    count = int(rng.integers(1, 400))
    edges = int(rng.integers(0, count))
    a, b = rng.integers(0, count, edges), rng.integers(0, count, edges)
    graph = coo_matrix((np.ones(edges), (a, b)), shape=(count, count))
    expected_n, expected = connected_components(graph, directed=False)
    n, labels = connected_groups(count, a, b)
    assert n == expected_n
    np.testing.assert_array_equal(labels, expected)


def test_connected_groups_of_a_long_chain():
    count = 1000
    order = np.random.default_rng(1).permutation(count)  # a chain in a scrambled order
    n, labels = connected_groups(count, order[:-1], order[1:])
    assert n == 1 and not labels.any()

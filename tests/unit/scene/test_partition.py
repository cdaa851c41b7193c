"""The sampled drawing as a planar partition (vecfit/scene/partition.py): samples filled by
winding number, stacks of shapes, specks, and outlines that pieces share edge to edge."""
import numpy as np
import pytest

from vecfit.scene.partition import EMPTY, OUTSIDE, absorb_specks, partition, sample_stacks, winding_samples


def square(x0, y0, x1, y1, clockwise=False):
    p = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)
    return p[::-1] if clockwise else p


def test_winding_samples_fill_a_square_by_its_sample_centres():
    inside = winding_samples([square(1, 1, 3, 2)], False, (0, 8, 0, 8), 2)
    # samples (i + 0.5) / 2: x in [1, 3) holds 4 columns, y in [1, 2) 2 rows
    assert inside.sum() == 8
    assert inside[2:4, 2:6].all()


def test_abutting_squares_share_no_sample_and_leave_none_out():
    a = winding_samples([square(0, 0, 2.3, 4)], False, (0, 16, 0, 16), 4)
    b = winding_samples([square(2.3, 0, 4, 4)], False, (0, 16, 0, 16), 4)
    assert not (a & b).any()
    assert (a | b).sum() == 16 * 16


def test_fill_rules():
    ring = [square(0, 0, 4, 4), square(1, 1, 3, 3)]  # same direction: nonzero fills the hole
    assert winding_samples(ring, False, (0, 4, 0, 4), 1).sum() == 16
    assert winding_samples(ring, True, (0, 4, 0, 4), 1).sum() == 12
    opposite = [square(0, 0, 4, 4), square(1, 1, 3, 3, clockwise=True)]
    assert winding_samples(opposite, False, (0, 4, 0, 4), 1).sum() == 12


def test_stacks_keep_the_top_shape_and_translucent_ones_over_it():
    shapes = [([square(0, 0, 4, 4)], False, True),     # backdrop
              ([square(1, 0, 3, 4)], False, True),     # opaque, hides the backdrop
              ([square(0, 1, 4, 2)], False, False)]    # translucent, over both
    s = sample_stacks(shapes, 4, 4, 1)
    stacks = [s.stacks[k] for k in s.labels[:, 0]] + [s.stacks[k] for k in s.labels[:, 2]]
    assert stacks == [(0,), (0, 2), (0,), (0,), (1,), (1, 2), (1,), (1,)]
    assert len(s.stacks) == 4


def test_a_speck_goes_to_its_neighbour_and_empty_samples_stay():
    labels = np.zeros((6, 6), np.int64)
    labels[:, 3:] = 1
    labels[2, 1] = 2          # a one-sample speck inside 0
    labels[4, 4] = EMPTY      # a hole stays a hole
    out = absorb_specks(labels, 2)
    assert out[2, 1] == 0 and out[4, 4] == EMPTY
    assert (out[:, 3:][out[:, 3:] != EMPTY] == 1).all()


def _ring(part, outline):
    """An outline's grid corners in order (closed: first == last), checked to join up."""
    seq = []
    for k, backwards in outline:
        chain = part.chains[k]
        c = np.vstack([chain.corners, chain.corners[:1]]) if chain.closed else chain.corners
        c = c[::-1] if backwards else c
        if seq:
            assert (seq[-1] == c[0]).all()
        seq.extend(c[1:] if seq else c)
    seq = np.array(seq)
    assert (seq[0] == seq[-1]).all()
    return seq


@pytest.mark.parametrize("seed", range(6))
def test_outlines_enclose_each_piece_and_share_every_chain(seed):
    rng = np.random.default_rng(seed)
    labels = rng.integers(0, 4, (5, 7)).repeat(2, 0).repeat(2, 1)  # blocks, diagonals, islands
    labels[rng.random(labels.shape) < 0.05] = EMPTY
    part = partition(labels)
    uses = np.zeros(len(part.chains), int)
    for piece, outlines in part.outlines.items():
        area = 0.0
        for outline in outlines:
            ring = _ring(part, outline)
            y, x = ring[:, 0].astype(float), ring[:, 1].astype(float)
            area += 0.5 * np.sum(x[:-1] * y[1:] - x[1:] * y[:-1])
            for k, backwards in outline:
                uses[k] += 1
                chain = part.chains[k]
                assert (chain.right if backwards else chain.left) == piece  # the piece is on the outline's left
        # every outline keeps its piece on its left: the signed areas add up to its samples
        assert -area == (labels == piece).sum()
    for k, chain in enumerate(part.chains):
        sides = sum(side >= 0 for side in (chain.left, chain.right))
        assert uses[k] == sides  # a shared chain in both pieces, an edge chain in one
        assert chain.left != chain.right
    assert set(part.outlines) == set(np.unique(labels[labels >= 0]).tolist())


def test_an_island_is_one_closed_chain_in_both_pieces():
    labels = np.zeros((6, 6), np.int64)
    labels[2:4, 2:4] = 1
    part = partition(labels)
    assert len(part.chains) == 2 and all(c.closed for c in part.chains)  # no junction anywhere
    island = [c for c in part.chains if OUTSIDE not in (c.left, c.right)]
    assert len(island) == 1 and {island[0].left, island[0].right} == {0, 1}
    assert len(part.outlines[0]) == 2 and len(part.outlines[1]) == 1

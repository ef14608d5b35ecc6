"""The track (vtsi/track.py): validation, host-element search and the constraint rows N(x).

Checks, in the order of the module: a Track refuses chains it cannot run wheels along, naming
the element at fault; a wheel finds its host element (a node belongs to the element starting
there, the chain's last node to the last element, off the chain -1 and a zero row); the
Hermite rows reproduce any cubic field exactly (values and slopes) and their uy part is a
partition of unity; the B-spline-smoothed rows (remedy (a), docs/theory/constraints.md) equal a
brute-force numerical convolution of the Hermite rows, reproduce w + (knot²/6) w'' for a cubic
field, have a fixed width, and nothing is renumbered when the wheels move.
"""
import numpy as np
import pytest
from scipy.integrate import quad_vec

import vtsi
from vtsi.errors import ModelError
from vtsi.track import Track, bspline_kernel, host_element, row_width

# A free-free chain with unequal elements (short ones next to long ones).
NODE_X = np.array([0.0, 1.3, 2.0, 4.5, 5.0, 5.4, 7.9, 10.0])


def _chain(node_x=NODE_X, fix_ends=False, element_order=None, reverse_nodes=()):
    model = vtsi.Model()
    for i, x in enumerate(node_x):
        model.node(i + 1, float(x), 0.0)
    if fix_ends:
        model.fix(1, 1, 1, 0)
        model.fix(len(node_x), 0, 1, 0)
    else:
        model.fix(1, 1, 0, 0)   # only the axial rigid-body mode is held; bending is free-free
    tags = list(range(1, len(node_x)))
    for e in (element_order or tags):
        nodes = (e + 1, e) if e in reverse_nodes else (e, e + 1)
        model.element("elasticBeamColumn", e, nodes, A=1.0, E=2e11, I=1e-3, rho=100.0, cmass=1)
    return model, tags


def _dense(track, cols, vals):
    """Rows (n_w, width) -> dense (n_w, n_track)."""
    out = np.zeros((cols.shape[0], track.n_track))
    for i in range(cols.shape[0]):
        keep = cols[i] >= 0
        np.add.at(out[i], cols[i][keep], vals[i][keep])
    return out


def _track_field(model, track, w, dw):
    """Track-dof vector of the nodal values of a field: uy = w(x_n), rz = w'(x_n)."""
    asm = model.build()
    u_free = np.zeros(asm.n_free)
    for tag, (x, _) in model.nodes.items():
        for dof, value in ((2, w(x)), (3, dw(x))):
            f = asm.free_of_full[asm.full_dof(tag, dof)]
            if f >= 0:
                u_free[f] = value
    return u_free[track.free_index]


def _uy_mask(model, track):
    asm = model.build()
    return asm.full_of_free[track.free_index] % asm.ndf == 1


# -- validation --------------------------------------------------------------------------------
def test_non_horizontal_element_is_refused():
    model, tags = _chain()
    model.node(100, 10.0, 0.0)
    model.node(101, 12.0, 0.5)
    model.element("elasticBeamColumn", 50, (100, 101), A=1.0, E=2e11, I=1e-3)
    with pytest.raises(ModelError, match=r"element 50 is not horizontal"):
        Track(model, tags + [50])


def test_gap_between_elements_is_refused():
    model, tags = _chain()
    model.node(100, 10.5, 0.0)
    model.node(101, 12.0, 0.0)
    model.element("elasticBeamColumn", 50, (100, 101), A=1.0, E=2e11, I=1e-3)
    with pytest.raises(ModelError, match=r"elements 7 and 50 leave a gap or overlap between x = 10 and 10.5"):
        Track(model, tags + [50])


def test_overlapping_elements_are_refused():
    model, tags = _chain()
    model.node(100, 9.0, 0.0)
    model.node(101, 12.0, 0.0)
    model.element("elasticBeamColumn", 50, (100, 101), A=1.0, E=2e11, I=1e-3)
    with pytest.raises(ModelError, match=r"elements 7 and 50 leave a gap or overlap"):
        Track(model, tags + [50])


def test_unknown_element_is_refused():
    model, tags = _chain()
    with pytest.raises(ModelError, match=r"element 99 does not exist"):
        Track(model, tags + [99])


def test_non_beam_element_is_refused():
    model, tags = _chain()
    model.node(100, 12.0, 0.0)
    model.element("truss", 50, (len(NODE_X), 100), A=1.0, E=2e11)
    with pytest.raises(ModelError, match=r"element 50 \(truss\) is not a 2-node beam"):
        Track(model, tags + [50])


def test_empty_and_repeated_element_lists_are_refused():
    model, tags = _chain()
    with pytest.raises(ModelError, match="no elements"):
        Track(model, [])
    with pytest.raises(ModelError, match="listed twice"):
        Track(model, tags + [3])


def test_chain_is_sorted_along_x_whatever_the_input_order():
    """Elements listed in any order and defined right-to-left give the same track."""
    model, tags = _chain()
    ref = Track(model, tags)
    model2, _ = _chain(element_order=[4, 2, 7, 1, 3, 6, 5], reverse_nodes=(2, 5))
    shuffled = Track(model2, [5, 1, 7, 3, 2, 6, 4])
    assert shuffled.elements == tags
    assert np.array_equal(shuffled.x_start, NODE_X[:-1]) and np.allclose(shuffled.length, np.diff(NODE_X))
    x = np.linspace(-0.5, 10.5, 57)
    c1, v1, s1 = ref.rows(x)
    c2, v2, s2 = shuffled.rows(x)
    # same field -> same values, whatever the track-dof numbering
    w, dw = (lambda x: 1.0 + x - 0.2 * x ** 2 + 0.03 * x ** 3), (lambda x: 1.0 - 0.4 * x + 0.09 * x ** 2)
    u1, u2 = _track_field(model, ref, w, dw), _track_field(model2, shuffled, w, dw)
    assert np.allclose(_dense(ref, c1, v1) @ u1, _dense(shuffled, c2, v2) @ u2, rtol=0, atol=1e-12)
    assert np.allclose(_dense(ref, c1, s1) @ u1, _dense(shuffled, c2, s2) @ u2, rtol=0, atol=1e-12)


def test_fixed_dofs_are_dropped_from_the_rows():
    model, tags = _chain(fix_ends=True)
    track = Track(model, tags)
    assert track.dofs[0, 0] == -1 and track.dofs[-1, 2] == -1          # uy at both supports
    assert np.all(track.dofs[:, [1, 3]] >= 0)                           # rotations free
    assert track.n_track == 2 * len(NODE_X) - 2
    cols, vals, _ = track.rows(np.array([0.0, 0.4, 10.0]))
    asm = model.build()
    for i in range(3):
        used = cols[i][cols[i] >= 0]
        assert np.all(asm.free_of_full[asm.full_of_free[track.free_index[used]]] >= 0)
    # at a support the row is all zeros but for the rotation, which has value 0 there
    assert np.allclose(vals[0], 0.0) and np.allclose(vals[2], 0.0)


# -- host element ----------------------------------------------------------------------------
def test_host_element_search():
    x_start, length = NODE_X[:-1].copy(), np.diff(NODE_X)
    n = len(x_start)
    for e in range(n):
        assert host_element(x_start[e], x_start, length) == e           # a node: the element starting there
        assert host_element(x_start[e] + 0.5 * length[e], x_start, length) == e
        assert host_element(np.nextafter(x_start[e] + length[e], -np.inf), x_start, length) == e
    assert host_element(NODE_X[-1], x_start, length) == n - 1             # the last node: the last element
    assert host_element(np.nextafter(0.0, -1.0), x_start, length) == -1
    assert host_element(np.nextafter(NODE_X[-1], np.inf), x_start, length) == -1
    assert host_element(-5.0, x_start, length) == -1 and host_element(50.0, x_start, length) == -1


def test_rows_off_the_chain_are_zero():
    model, tags = _chain()
    track = Track(model, tags)
    cols, vals, slopes = track.rows(np.array([-3.0, -1e-9, 10.0 + 1e-9, 40.0]))
    assert np.all(cols == -1) and np.all(vals == 0.0) and np.all(slopes == 0.0)


def test_row_on_a_node_uses_the_element_starting_there():
    model, tags = _chain()
    track = Track(model, tags)
    cols, vals, slopes = track.rows(NODE_X)
    for k in range(len(NODE_X)):
        e = min(k, len(tags) - 1)
        assert set(cols[k][cols[k] >= 0]) == set(track.dofs[e][track.dofs[e] >= 0])


# -- Hermite rows ----------------------------------------------------------------------------
CUBIC = (lambda x: 0.3 - 0.7 * x + 0.11 * x ** 2 - 0.013 * x ** 3,
         lambda x: -0.7 + 0.22 * x - 0.039 * x ** 2,
         lambda x: 0.22 - 0.078 * x)


def test_hermite_rows_reproduce_a_cubic_field_and_its_slope():
    model, tags = _chain()
    track = Track(model, tags)
    w, dw, _ = CUBIC
    u = _track_field(model, track, w, dw)
    x = np.concatenate([np.linspace(0.0, 10.0, 301), NODE_X, NODE_X[1:] - 1e-7, NODE_X[:-1] + 1e-7])
    cols, vals, slopes = track.rows(x)
    assert np.allclose(_dense(track, cols, vals) @ u, w(x), rtol=0, atol=1e-13)
    assert np.allclose(_dense(track, cols, slopes) @ u, dw(x), rtol=0, atol=1e-12)


def test_uy_part_of_a_row_is_a_partition_of_unity():
    model, tags = _chain()
    track = Track(model, tags)
    uy = _uy_mask(model, track)
    x = np.linspace(0.0, 10.0, 401)
    cols, vals, slopes = track.rows(x)
    dense, dslope = _dense(track, cols, vals), _dense(track, cols, slopes)
    assert np.allclose(dense[:, uy].sum(axis=1), 1.0, rtol=0, atol=1e-14)
    assert np.allclose(dslope[:, uy].sum(axis=1), 0.0, rtol=0, atol=1e-12)
    # a rigid rotation about x = 0: uy = x, rz = 1 everywhere
    rot = np.where(uy, model.build().coords[model.build().full_of_free[track.free_index] // 3, 0], 1.0)
    assert np.allclose(dense @ rot, x, rtol=0, atol=1e-13)


# -- B-spline-smoothed rows ----------------------------------------------------------------
def _convolved(track, x, knot, slope=False):
    """Brute force: ∫ N(x − ξ) B₃(ξ/knot)/knot dξ by adaptive quadrature (scipy quad_vec), with
    the kernel knots and the element ends as break points."""
    ends = np.concatenate([track.x_start, [track.x_end]])
    which = 2 if slope else 1

    def integrand(xi):
        c, v, s = track.rows(np.array([x - xi]))
        return _dense(track, c, (v, s)[which - 1])[0] * bspline_kernel(xi / knot) / knot

    points = sorted(set([k * knot for k in (-1, 0, 1)] + [x - e for e in ends if abs(x - e) < 2 * knot]))
    value, err = quad_vec(integrand, -2 * knot, 2 * knot, points=points, epsabs=1e-14, epsrel=1e-13)
    return value


@pytest.mark.parametrize("knot", [0.23, 1.7])
def test_smoothed_rows_equal_a_numerical_convolution_of_the_hermite_rows(knot):
    """Near element ends, at the chain ends (where half the kernel is on rigid ground) and
    just off the chain (within 2 knot, the smoothed row is not zero yet)."""
    model, tags = _chain(fix_ends=True)
    track = Track(model, tags)
    x = np.array([-2.0 * knot - 0.01, -1.5 * knot, -1e-6, 0.0, 0.05, 1.3, 1.3 + 1e-9, 2.0 - 1e-9, 3.21,
                  5.0, 5.2, 5.4 + 0.5 * knot, 9.99, 10.0, 10.0 + 0.7 * knot, 10.0 + 2.0 * knot + 0.01])
    cols, vals, slopes = track.rows(x, knot)
    dense, dslope = _dense(track, cols, vals), _dense(track, cols, slopes)
    for i, xi in enumerate(x):
        ref = _convolved(track, xi, knot)
        ref_slope = _convolved(track, xi, knot, slope=True)
        assert np.max(np.abs(dense[i] - ref)) < 1e-10, (xi, dense[i] - ref)
        assert np.max(np.abs(dslope[i] - ref_slope)) < 1e-10, (xi, dslope[i] - ref_slope)
    assert np.all(dense[[0, -1]] == 0.0)      # beyond 2 knot off the chain: rigid ground
    assert np.any(dense[1] != 0.0) and np.any(dense[-2] != 0.0)


def test_smoothed_rows_of_a_cubic_field():
    """The kernel has unit mass, zero mean and variance knot²/3, so on a cubic field
    Ñ u = w + (knot²/6) w'' exactly (the accuracy statement Ñ − N = (h²/6) N̈ of
    docs/theory/constraints.md), and the slope row gives its derivative."""
    model, tags = _chain()
    track = Track(model, tags)
    w, dw, ddw = CUBIC
    u = _track_field(model, track, w, dw)
    knot = 0.4
    x = np.linspace(2 * knot, 10.0 - 2 * knot, 97)
    cols, vals, slopes = track.rows(x, knot)
    assert np.allclose(_dense(track, cols, vals) @ u, w(x) + knot ** 2 / 6.0 * ddw(x), rtol=0, atol=1e-13)
    assert np.allclose(_dense(track, cols, slopes) @ u, dw(x) + knot ** 2 / 6.0 * (-0.078), rtol=0, atol=1e-12)
    uy = _uy_mask(model, track)
    assert np.allclose(_dense(track, cols, vals)[:, uy].sum(axis=1), 1.0, rtol=0, atol=1e-14)


def test_smoothed_slope_is_the_derivative_of_the_smoothed_row():
    model, tags = _chain(fix_ends=True)
    track = Track(model, tags)
    knot, h = 0.6, 1e-5
    x = np.linspace(-1.5, 11.5, 53)
    c, v, s = track.rows(x, knot)
    cp, vp, _ = track.rows(x + h, knot)
    cm, vm, _ = track.rows(x - h, knot)
    fd = (_dense(track, cp, vp) - _dense(track, cm, vm)) / (2 * h)
    assert np.allclose(_dense(track, c, s), fd, rtol=0, atol=1e-8)


@pytest.mark.parametrize("knot", [0.0, 0.1, 0.4, 1.9])
def test_rows_have_a_fixed_width(knot):
    """The width depends on the shortest element and the knot only; sweeping wheels over the
    whole chain never needs more entries (an overflow would be silent in compiled code, so the
    entries used are counted and the row mass is checked)."""
    model, tags = _chain(fix_ends=False)
    track = Track(model, tags)
    width = row_width(track.length.min(), knot)
    x = np.linspace(-2 * knot - 0.1, 10.0 + 2 * knot + 0.1, 2001)
    cols, vals, slopes = track.rows(x, knot)
    assert cols.shape == vals.shape == slopes.shape == (len(x), width)
    assert track.rows(x[:3], knot)[0].shape == (3, width)
    used = (cols >= 0).sum(axis=1)
    assert used.max() <= width
    for i in range(len(x)):                 # no column twice in a row
        c = cols[i][cols[i] >= 0]
        assert len(np.unique(c)) == len(c)
    uy = _uy_mask(model, track)
    inside = (x >= 2 * knot) & (x <= 10.0 - 2 * knot)
    assert np.allclose(_dense(track, cols, vals)[inside][:, uy].sum(axis=1), 1.0, rtol=0, atol=1e-13)


# -- nothing is renumbered when a wheel moves ----------------------------------------------
@pytest.mark.parametrize("interpolation", ["hermite", "bspline"])
def test_a_run_renumbers_nothing(interpolation):
    from vtsi.constraint import MovingLoadConstraint
    from vtsi.coupled import CoupledAnalysis
    from vtsi.models.scenes import s3_model
    from vtsi.train import TrainSubdomain

    model = vtsi.Model()
    bridge, train, x_head0 = s3_model(model, 10, approach=2.0)
    asm = model.build()
    maps = [a.copy() for a in (asm.free_of_full, asm.full_of_free)]
    matrices = [m.copy() for m in (asm.K, asm.M, asm.C)]
    track = Track(model, bridge.elements)
    track_maps = [a.copy() for a in (track.free_index, track.dofs, track.x_start, track.length)]
    con = MovingLoadConstraint(track, TrainSubdomain(train, x_head0), interpolation=interpolation)
    analysis = CoupledAnalysis(model, con, "Newmark", 2e-3)
    analysis.static()
    analysis.run(350)                       # both wheels over the whole span and off it again
    assert model.build() is asm
    for before, after in zip(maps, (asm.free_of_full, asm.full_of_free)):
        assert np.array_equal(before, after)
    for before, after in zip(matrices, (asm.K, asm.M, asm.C)):
        assert (before != after).nnz == 0
    for before, after in zip(track_maps, (track.free_index, track.dofs, track.x_start, track.length)):
        assert np.array_equal(before, after)
    assert analysis._prepared is asm        # factored once, not again

"""The compiled axle sums of vtsi.influence (``_add_axle_loads``: per head, the axles on the track
only, each its element's Hermite row · the lines element by element) against the reference they
replaced: every position's Hermite row gathered through ``Track.rows`` (−N(x) · w, w = K⁻¹ e_d),
plus the moments' fixed-end share ``FixedEndMoments.at``, summed over every axle at every head,
a position within 1e-6 of the scan step of a track end put on it. Equal to 1e-12 of each output's
largest value: the lines, the train, LM71 and SW/0 envelopes, on a simply supported beam, a
3-span continuous deck, a deck with an overhang and a deck between approaches on zeroLength
springs, for deflections, rotations and bending moments."""
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import vtsi
from vtsi.bridge_file import load_bridge
from vtsi.influence import InfluenceLines
from vtsi.models import hslm_a
from vtsi.models.bridges import continuous_beam, simply_supported_beam
from vtsi.recorders.moment import fixed_end_moments, moment_rows
from vtsi.track import Track

E, I, MU = 3.5e10, 0.6948, 15000.0
OVERHANG = Path(__file__).parent / "scripts" / "overhang.py"   # a 20 m span, a 4 m overhang carrying the track


class Reference(InfluenceLines):
    """The lines and the axle sums as vtsi computed them before the compiled kernel."""

    def __init__(self, model, track, **responses):
        super().__init__(model, track, **responses)
        asm = model.build()
        if "moments" in responses:
            free, P = moment_rows(asm, track, responses["moments"])
            self._fixed_reference = fixed_end_moments(asm, track, responses["moments"])
        else:
            free = asm.free_of_full[[asm.full_dof(n, d) for n, d in responses["dofs"]]]
            P, self._fixed_reference = np.eye(len(free)), None
        rhs = np.zeros((asm.n_free, P.shape[1]))
        rhs[free] = P
        self._w = spla.splu(asm.K.tocsc()).solve(rhs)[track.free_index]

    def __call__(self, x):
        x = np.atleast_1d(np.asarray(x, dtype=float))
        cols, vals, _ = self.track.rows(x)
        w = self._w[np.maximum(cols, 0)]
        w[cols < 0] = 0.0
        il = np.einsum("ij,ijk->ik", -vals, w)
        if self._fixed_reference is not None:
            il += self._fixed_reference.at(x)
        return il

    def _train_response(self, heads, offsets, loads):
        x = heads[:, None] - np.asarray(offsets)[None, :]
        ends = np.array([self.track.x_begin, self.track.x_end])
        near = np.abs(x[..., None] - ends) <= 1e-6 * self.step
        x = np.where(near.any(axis=-1), ends[np.argmax(near, axis=-1)], x)
        return np.einsum("j,ijk->ik", loads, self(x.ravel()).reshape(x.shape + (self.n_responses,)))


def simple():
    model = vtsi.Model()
    b = simply_supported_beam(model, 20.0, 10, E, I, MU)
    return model, b.elements, b.nodes


def three_spans():
    model = vtsi.Model()
    b = continuous_beam(model, [30.0, 30.0, 30.0], 20, E, 7.0, MU)
    return model, b.elements, b.nodes


def script(text, name, tmp_path, nodes):
    (tmp_path / name).write_text(text)
    b = load_bridge(tmp_path / name)
    return b.model, b.track_elements, nodes


@pytest.fixture(params=["simple", "three spans", "overhang", "approaches"])
def bridge(request, tmp_path, approaches_tcl):
    if request.param == "simple":
        return simple()
    if request.param == "three spans":
        return three_spans()
    if request.param == "overhang":
        b = load_bridge(OVERHANG)
        return b.model, b.track_elements, list(range(1, 16))                      # its track's nodes
    return script(approaches_tcl, "approaches.tcl", tmp_path, list(range(1, 32)))


RESPONSES = {"deflection": lambda nodes: {"dofs": [(n, 2) for n in nodes]},
             "rotation": lambda nodes: {"dofs": [(n, 3) for n in nodes]},
             "moment": lambda nodes: {"moments": list(nodes)}}


def assert_same(new, reference):
    np.testing.assert_allclose(new, reference, rtol=1e-12, atol=1e-12 * np.abs(reference).max())


@pytest.mark.parametrize("response", RESPONSES)
def test_the_compiled_sums_are_the_reference(bridge, response):
    model, elements, nodes = bridge
    track = Track(model, elements)
    responses = RESPONSES[response](nodes)
    lines, reference = InfluenceLines(model, track, **responses), Reference(model, track, **responses)
    ends = np.array([track.x_begin, track.x_end])
    # on and 1e-14 m off the ends, on every node, and between
    x = np.concatenate([np.linspace(track.x_begin - 3.0, track.x_end + 3.0, 1001), track.x_start, ends,
                        ends + 1e-14, ends - 1e-14])
    assert np.abs(lines(x)).max() > 0.0
    assert_same(lines(x), reference(x))
    train = hslm_a(4, 1.0)
    offsets, loads = train.wheel_offsets, train.static_wheel_loads
    # a scan, and heads that put an axle a hair off a track end (put on it)
    heads = np.concatenate([np.arange(track.x_begin, track.x_end + offsets[-1], 0.37),
                            (ends[:, None] + offsets[None, ::7]).ravel() + 3e-15])
    assert_same(lines._train_response(heads, offsets, loads), reference._train_response(heads, offsets, loads))
    reversed_order = lines._train_response(heads, offsets[::-1], loads[::-1])        # axles in any order
    assert_same(reversed_order, reference._train_response(heads, offsets, loads))
    for axles in ((offsets, loads), ([0.0, 1.23], [200e3, 200e3])):
        assert_same(lines.train_envelope(*axles), reference.train_envelope(*axles))
    assert_same(lines.lm71_envelope(), reference.lm71_envelope())
    assert_same(lines.sw0_envelope(), reference.sw0_envelope())

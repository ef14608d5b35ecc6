"""The two recorder costs of a passage, made cheaper without changing a bit of what they give:
the envelope's compiled one-pass fold against the numpy fold it replaced (argmin/argmax along
time: first occurrence of ties, the first NaN, strict replacement across chunks), and the
bending-moment recorder's requests, resolved once per assembly (shared by a sweep's passages,
resolved anew for a changed model), against the closed-form Hermite curvature rows."""
import gc
import weakref

import numpy as np
import pytest

import vtsi
from vtsi.errors import ModelError
from vtsi.models.bridges import simply_supported_beam
from vtsi.recorders import Envelope
from vtsi.recorders.moment import BendingMomentRecorder
from vtsi.track import Track


def reference_update(env, times, values):
    """The numpy fold of ``Envelope.update`` before the compiled one (vtsi 53a42b5)."""
    m = len(times)
    if m == 0:
        return
    cols = np.arange(values.shape[1])
    absval = np.abs(values)
    candidates = (
        ("min", "time_of_min", np.argmin(values, axis=0), values, np.less),
        ("max", "time_of_max", np.argmax(values, axis=0), values, np.greater),
        ("absmax", "time_of_absmax", np.argmax(absval, axis=0), absval, np.greater),
    )
    for name, tname, idx, source, better in candidates:
        value, when = source[idx, cols], times[idx]
        current, current_time = getattr(env, name), getattr(env, tname)
        mask = np.ones(len(cols), dtype=bool) if env.n_records == 0 else better(value, current)
        current[mask], current_time[mask] = value[mask], when[mask]
        if env.concurrent:
            getattr(env, "concurrent_" + name)[mask] = values[idx[mask]]
    env.n_records += m


def assert_same_bits(a, b):
    assert a.n_records == b.n_records
    for name in a.fields:
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and np.array_equal(x.view(np.int64), y.view(np.int64)), name


@pytest.mark.parametrize("concurrent", [False, True])
def test_the_compiled_envelope_equals_the_numpy_fold_bit_for_bit(concurrent):
    """Small integers (many ties), NaN of either sign, -0.0 and -inf, in chunks of 0 to 6 steps:
    every extreme, its time and the concurrent rows equal to the bit, NaN and signed zeros too."""
    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(0, 7))
        new, old = Envelope(n, concurrent), Envelope(n, concurrent)
        t0 = 0.0
        for _ in range(int(rng.integers(1, 5))):
            m = int(rng.integers(0, 7))
            values = rng.integers(-3, 4, (m, n)).astype(float)
            for special, share in ((np.nan, 0.08), (-np.nan, 0.05), (-0.0, 0.2), (-np.inf, 0.05)):
                values[rng.random((m, n)) < share * rng.random()] = special
            times = t0 + 0.1 * np.arange(m)
            t0 += 0.1 * m
            new.update(times, values)
            reference_update(old, times, values)
            assert_same_bits(new, old)


def test_the_envelope_of_a_large_chunk_and_a_strided_one():
    """A viaduct's chunk (1615 steps × 401 columns, normal values with a NaN and a tie placed)
    in two chunks, the second given as a strided view: as the numpy fold."""
    rng = np.random.default_rng(3)
    values = rng.standard_normal((1615, 802))[:, ::2]
    values[900, 5] = np.nan
    values[[100, 200], 9] = 9.0
    times = 2e-3 * np.arange(1615)
    new, old = Envelope(401, concurrent=True), Envelope(401, concurrent=True)
    for part in (slice(0, 700), slice(700, None)):
        new.update(times[part], values[part])
        reference_update(old, times[part], values[part])
    assert_same_bits(new, old)
    assert not np.isnan(new.min[5]) and new.time_of_max[9] == times[100]   # the NaN in chunk 2 replaces nothing


def test_an_envelope_fed_values_of_another_width_is_a_model_error():
    env = Envelope(3)
    with pytest.raises(ModelError, match=r"^envelope: values of shape \(2, 4\) for 2 times and 3 columns; "
                                         r"\(2, 3\) expected$"):
        env.update(np.array([0.0, 0.1]), np.zeros((2, 4)))
    assert env.n_records == 0 and np.isnan(env.max).all()


def two_elements():
    """A 4 m simply supported span of two 2 m elements, EI = 1 N·m² (rows of exact binary numbers)."""
    model = vtsi.Model()
    b = simply_supported_beam(model, 4.0, 2, 1.0, 1.0, 1.0)
    return model, b, Track(model, b.elements)


def full_map(asm, rec, requests):
    """The recorder's moments as a map ``(n_free, n_nodes)`` of the free dofs."""
    out = np.zeros((asm.n_free, rec._projection.shape[1]))
    out[asm.free_of_full[[dof for _, dof in requests]]] = rec._projection
    return out


def test_the_moment_rows_are_the_hermite_curvatures_and_are_resolved_once_per_assembly():
    """M = EI w'' of the elements at a node, averaged: with ℓ = 2 m, w''(0) = [-1.5, -2, 1.5, -1]
    and w''(1) = [1.5, 1, -1.5, 2] on [v₁, θ₁, v₂, θ₂]. A second recorder (a sweep's next
    passage) reads the same arrays, not a copy."""
    model, b, track = two_elements()
    asm = model.build()
    first, mid, last = b.nodes
    rec = BendingMomentRecorder(track, [first, mid, last])
    requests = rec.requests(asm)
    free = {name: asm.free_of_full[asm.full_dof(node, dof)] for name, node, dof in
            (("t1", first, 3), ("v2", mid, 2), ("t2", mid, 3), ("t3", last, 3))}
    expected = np.zeros((asm.n_free, 3))
    expected[[free["t1"], free["v2"], free["t2"]], 0] = [-2.0, 1.5, -1.0]     # −w''(0) of element 1's start
    expected[[free["t1"], free["v2"], free["t3"]], 1] = [0.5, -1.5, -0.5]     # (w''(1) of 1 + w''(0) of 2) / 2
    expected[[free["v2"], free["t2"], free["t3"]], 2] = [1.5, 1.0, 2.0]       # w''(1) of element 2's end
    np.testing.assert_array_equal(full_map(asm, rec, requests), expected)
    again = BendingMomentRecorder(track, [first, mid, last])
    assert again.requests(asm) == requests
    assert again._projection is rec._projection and again._fixed is rec._fixed
    assert not rec._projection.flags.writeable


def test_a_changed_model_is_resolved_anew_and_its_old_assembly_released():
    """Fixing the mid node's rotation builds a new assembly: the recorder no longer reads θ₂, and
    the resolution cached for the old assembly goes with it."""
    model, b, track = two_elements()
    old = model.build()
    rec = BendingMomentRecorder(track, [b.nodes[1]])
    before = rec.requests(old)
    kept = {dof: c for dof, c in zip(before, rec._projection[:, 0])}
    theta = ("u", old.full_dof(b.nodes[1], 3))
    model.fix(b.nodes[1], 0, 0, 1)
    asm = model.build()
    after = rec.requests(asm)
    assert asm is not old and theta in before and theta not in after
    assert dict(zip(after, rec._projection[:, 0])) == {dof: c for dof, c in kept.items() if dof != theta}
    gone = weakref.ref(old)
    del old
    gc.collect()
    assert gone() is None


def test_a_node_off_the_track_is_named_at_every_request():
    model, b, track = two_elements()
    model.node(9, 1.0, 3.0)
    asm = model.build()
    for _ in range(2):
        with pytest.raises(ModelError, match=r"^bending moment: node 9 \(x = 1 m\) is not a node of the track$"):
            BendingMomentRecorder(track, [9]).requests(asm)

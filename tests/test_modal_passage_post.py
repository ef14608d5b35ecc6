"""A modal passage's post-processing (PassageRunner._modal_passage): the truncated modes'
static correction and the bending moments' fixed-end share added to every output's columns in
one piecewise-cubic pass (vtsi.modal_passage.add_quasi_static), the peaks taken once on all
columns. Against a straightforward path kept here: each output alone through the exact kernel,
its static correction as −Σ P N(x(t)) G sample by sample, its fixed-end share by
add_fixed_end_moments and its peaks column by column, as the runner took them before."""
import numpy as np
import pytest

from vtsi.bridge_file import load_bridge
from vtsi.modal_passage import peaks
from vtsi.passage import Output, PassageRunner, PassageSettings
from vtsi.recorders.moment import add_fixed_end_moments, fixed_end_moments, moment_rows
from vtsi.sweep import beam_bridge

OUTPUTS = (Output("deflection", "disp", history=True), Output("acceleration", "accel", cutoff="en", history=True),
           Output("end_rotation", "rotation", nodes="supports", history=True),
           Output("deck_moment", "moment", history=True), Output("pier_moment", "moment", nodes="piers", history=True),
           Output("midspan_deflection", "disp", nodes="midspan", cutoff=40.0),
           Output("contact_force", "contact_force"))


def bearings_script(path):
    """A 10 + 12 m continuous deck (2 m elements) on zeroLength bearings (kv 5 GN/m): the track's
    ends move, so the static correction jumps as an axle steps on or off."""
    lines = ["model basic -ndm 2 -ndf 3"] + [f"node {i + 1} {2.0 * i} 0.0" for i in range(12)]
    lines += ["node 101 0.0 0.0", "node 102 10.0 0.0", "node 103 22.0 0.0", "fix 101 1 1 1", "fix 102 1 1 1",
              "fix 103 1 1 1", "fix 1 1 0 0", "geomTransf Linear 1"]
    lines += [f"element elasticBeamColumn {i + 1} {i + 1} {i + 2} 5.0 3.5e10 1.2 1 -mass 15000.0" for i in range(11)]
    lines += ["uniaxialMaterial Elastic 1 5e9", "element zeroLength 201 101 1 -mat 1 -dir 2",
              "element zeroLength 202 102 6 -mat 1 -dir 2", "element zeroLength 203 103 12 -mat 1 -dir 2",
              "track 1 -eleRange 1 11"]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def bridges(tmp_path_factory):
    beam = beam_bridge([10.0, 14.0, 10.0], 3.5e10, 0.9, 15000.0, elements_per_span=4)
    on_bearings = load_bridge(str(bearings_script(tmp_path_factory.mktemp("bearings") / "deck.tcl")))
    return {"beam": beam, "bearings": on_bearings}


def straightforward_peaks(values, dt):
    """:func:`vtsi.modal_passage.peaks` column by column: the first extreme sample (numpy's
    argmin, argmax), refined by the parabola through it and its neighbours where the samples
    k − 2 … k + 2 bend as a smooth peak."""
    n, n_c = values.shape
    out = np.empty((6, n_c))
    for c in range(n_c):
        for r, k in enumerate((np.argmin(values[:, c]), np.argmax(values[:, c]), np.argmax(np.abs(values[:, c])))):
            y = values[:, c] if r < 2 else np.abs(values[:, c])
            value, shift = y[k], 0.0
            if 0 < k < n - 1 and (r < 2 or np.sign(values[k - 1, c]) == np.sign(values[k + 1, c])):
                den = y[k - 1] - 2.0 * y[k] + y[k + 1]
                vertex = 0.5 * (y[k - 1] - y[k + 1]) / den if den != 0.0 else 2.0
                smooth = all((y[j - 1] - 2.0 * y[j] + y[j + 1]) * den > 0.0 for j in (k - 1, k + 1) if 0 < j < n - 1)
                if abs(vertex) <= 1.0 and smooth:
                    shift = vertex
                    value = y[k] - 0.25 * (y[k - 1] - y[k + 1]) * shift
            out[r, c], out[r + 3, c] = value, (k + 1 + shift) * dt
    return out


def straightforward_static_correction(track, x0, loads, speed, t, G):
    """−Σ over the axles on the track of P N(x(t)) G at each time ``t``, N = [H₁, ℓH₂, H₃, ℓH₄]
    on the element under the axle (an axle on the track's end has left it)."""
    out = np.zeros((len(t), G.shape[1]))
    G = np.vstack([G, np.zeros((1, G.shape[1]))])                 # row -1: a fixed dof
    for x_axle, p in zip(x0, loads):
        x = x_axle + speed * t
        on = (x >= track.x_begin) & (x < track.x_end)
        e = np.searchsorted(track.x_start, x[on], side="right") - 1
        xi, ell = (x[on] - track.x_start[e]) / track.length[e], track.length[e]
        N = (1 - 3 * xi ** 2 + 2 * xi ** 3, ell * (xi - 2 * xi ** 2 + xi ** 3), 3 * xi ** 2 - 2 * xi ** 3,
             ell * (xi ** 3 - xi ** 2))
        for slot in range(4):
            out[on] -= p * N[slot][:, None] * G[track.dofs[e, slot]]
    return out


def straightforward_output(runner, train, o):
    """One output of an exact modal passage alone: its envelope and history."""
    s, modal, track = runner.settings, runner.modal, runner.track
    asm = runner.model.build()
    nodes = runner.output_nodes(o.nodes)
    output_map = np.zeros((asm.n_free, len(nodes)))
    if o.response == "moment":
        free, P = moment_rows(asm, track, nodes)
        output_map[free] = P
    else:
        for c, node in enumerate(nodes):
            f = asm.free_of_full[asm.full_dof(node, 3 if o.response == "rotation" else 2)]
            if f >= 0:
                output_map[f, c] = 1.0
    rows = np.zeros((3, modal.n_modes, len(nodes)))
    rows[2 if o.response == "accel" else 0] = modal.shapes[asm.full_of_free].T @ output_map
    if o.cutoff is not None:
        rows[:, modal.frequencies > runner.cutoff_hz(o.cutoff) * (1 + 1e-9)] = 0.0
    x_head0, n = runner.start_position(train), runner.n_steps(train)
    values = modal.passage(train.wheel_offsets, train.static_wheel_loads, train.speed, x_head0, n, s.dt, rows)
    t = s.dt * np.arange(1, n + 1)
    x0 = x_head0 - train.wheel_offsets
    if s.static_correction and o.cutoff is None and o.response != "accel":
        G = modal.residual_flexibility(output_map)
        values += straightforward_static_correction(track, x0, train.static_wheel_loads, train.speed, t, G)
    if o.response == "moment":
        add_fixed_end_moments(fixed_end_moments(asm, track, nodes), x0, train.static_wheel_loads, train.speed, t,
                              values)
    return straightforward_peaks(values, s.dt), values


@pytest.mark.parametrize("name", ["beam", "bearings"])
@pytest.mark.parametrize("static_correction", [True, False])
@pytest.mark.parametrize("dt", [2.3e-4, 1e-3, 4.1e-3])
def test_every_output_as_computed_alone(bridges, name, static_correction, dt):
    """Every node output's envelope and history (displacement, EN-filtered acceleration,
    rotation, moments at the deck's nodes and the piers, a displacement with a cut-off) equal
    the output computed alone to 1e-12 of its column's largest value (times of the peaks to
    1e-9 s), with and without the static correction, sampled finer and coarser than the axles
    cross the elements; the contact forces of moving forces are not produced. A column that is
    a rounding zero (the moment at a deck's free end, 1e-9 N·m) is held to 1e-12 of the
    output's largest value, its peaks' times (of noise) to nothing. Measured: 1e-14."""
    bridge = bridges[name]
    runner = PassageRunner(bridge.model, bridge.track_elements,
                           PassageSettings(damping=0.015, bridge="modal", dt=dt, static_correction=static_correction),
                           OUTPUTS)
    assert runner.pier_nodes
    for train_name, speed_kmh in (("HSLM-A1", 287.3), ("HSLM-A8", 163.9)):
        result = runner.run(train_name, speed_kmh)
        train = runner.train(train_name, speed_kmh / 3.6)
        assert list(result.envelopes) == [o.name for o in OUTPUTS if not o.vehicle]
        for o in OUTPUTS[:-1]:
            envelope, history = straightforward_output(runner, train, o)
            largest = np.abs(history).max(axis=0)
            real = largest >= 1e-9 * largest.max()        # not a rounding zero (the moment at a free end)
            scale = np.where(real, largest, largest.max())
            assert np.all(np.abs(result.envelopes[o.name][:3] - envelope[:3]) <= 1e-12 * scale), o.name
            assert np.all(np.abs(result.envelopes[o.name][3:, real] - envelope[3:, real]) <= 1e-9), o.name
            assert np.array_equal(result.columns[o.name], runner.output_nodes(o.nodes))
            if o.history:
                times, kept = result.histories[o.name]
                assert np.array_equal(times, dt * np.arange(1, len(history) + 1))
                assert np.all(np.abs(kept - history) <= 1e-12 * scale), o.name
                assert kept.base is None        # its own columns, not a view of every output's


def test_the_static_correction_and_fixed_end_share_matter(bridges):
    """The shares compared above are not negligible: on the deck on bearings (HSLM-A1, 287.3
    km/h) the static correction moves the largest deflection by more than 1e-4, and the axles'
    fixed-end share reaches more than 1 % of the largest moment at the deck's nodes."""
    bridge = bridges["bearings"]
    results = {sc: PassageRunner(bridge.model, bridge.track_elements,
                                 PassageSettings(damping=0.015, bridge="modal", dt=1e-3, static_correction=sc),
                                 OUTPUTS).run("HSLM-A1", 287.3) for sc in (True, False)}
    with_, without = (results[sc].envelopes["deflection"][2].max() for sc in (True, False))
    assert abs(with_ / without - 1) > 1e-4
    runner = PassageRunner(bridge.model, bridge.track_elements, PassageSettings(damping=0.015, bridge="modal", dt=1e-3))
    train = runner.train("HSLM-A1", 287.3 / 3.6)
    x_head0, n = runner.start_position(train), runner.n_steps(train)
    fixed = fixed_end_moments(runner.model.build(), runner.track, runner.output_nodes("deck"))
    share = add_fixed_end_moments(fixed, x_head0 - train.wheel_offsets, train.static_wheel_loads, train.speed,
                                  1e-3 * np.arange(1, n + 1), np.zeros((n, fixed.n_columns)))
    assert np.abs(share).max() > 1e-2 * np.abs(results[True].histories["deck_moment"][1]).max()


def test_peaks_of_all_columns_are_each_columns():
    """peaks on many columns at once: each column's envelope as computed alone, with ties (the
    first extreme sample), jumps and smooth peaks between samples (seeded)."""
    rng = np.random.default_rng(7)
    t = 1e-3 * np.arange(1, 2001)
    smooth = np.sin(2 * np.pi * rng.uniform(2, 40, 12)[None, :] * t[:, None] + rng.uniform(0, 6, 12))
    steps = np.round(rng.normal(size=(2000, 6)))                  # ties and jumps
    values = np.hstack([smooth * rng.uniform(0.1, 3, 12), steps, np.zeros((2000, 1))])
    assert np.array_equal(peaks(values, 1e-3), straightforward_peaks(values, 1e-3))
    assert np.array_equal(peaks(values[:0], 1e-3), np.full((6, values.shape[1]), np.nan), equal_nan=True)

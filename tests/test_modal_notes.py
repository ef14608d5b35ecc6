"""What a modal sweep and its check say of the modal bridge's basis (docs/modal.md), and the
modal bridge's own check of ``n_modes``.

- A ``modal_hz`` below the EN cut-off under-reads the deck acceleration; ``vtsi sweep`` printed
  it with no note (a 10 m span: 2.84 m/s² against 3.06) while the check refuses it: the summary
  now says so (``Sweep.resolution_note``).
- ``n_modes`` was checked by ``eigen`` (naming its own limit, the free dofs) or not at all (3.0
  crashed with a TypeError): the modal bridge now checks it, naming the most it takes.
- The check's text never named the bridge model (the report did): it now has a ``bridge model:``
  line, from the function the report's settings read; and its moment rows say when a modal
  basis stops below the moments' default (twice the trains' closest axles' frequency at the top
  speed, x 1.1: the modes the bogies drive to resonance, which the static correction misses).

A simply supported beam's frequencies are n_j = j² n₁ (Euler-Bernoulli; e.g. Frýba, Vibration of
Solids and Structures under Moving Loads, 1999, ch. 1), so the EN 1990 A2.4.4.2.1 cut-off
max(30 Hz, 1.5 n₀, n₃) of a 10 m span with n₁ = 12 Hz is n₃ = 108 Hz (the FE beam: 108.1)."""
import json
import math
import re
from pathlib import Path

import h5py
import numpy as np
import pytest

import vtsi
from vtsi.__main__ import main
from vtsi.bridge_file import load_bridge
from vtsi.check import check, stored_check
from vtsi.errors import ModelError
from vtsi.modal_bridge import ModalBridge
from vtsi.models.bridges import continuous_beam
from vtsi.passage import Output, PassageSettings
from vtsi.report import write_report
from vtsi.sweep import Sweep, beam_bridge
from vtsi.track import Track

DOCS = Path(__file__).resolve().parents[1] / "docs"
L10, F10, MU10 = 10.0, 12.0, 10000.0                       # the probe's 10 m span (n₁ = 12 Hz)
EI10 = MU10 * (2 * np.pi * F10 * (L10 / np.pi) ** 2) ** 2    # n₁ = (π/L)² √(EI/μ) / 2π
ACCEL = (Output("acceleration", "accel", cutoff="en"),)


def _span10():
    return beam_bridge([L10], EI10, 1.0, MU10, elements_per_span=10)


# -- 1. a modal_hz below the EN cut-off, noted under the sweep's table ---------------------------------
def test_a_modal_hz_below_the_cut_off_is_noted_with_the_frequencies_the_acceleration_counts():
    """HSLM-A1 at 250 km/h over the 10 m span: the modes up to 40 Hz (one mode, 12 Hz) read the
    deck acceleration lower than the default basis (1.1 × n₃: three modes); the note names 40 Hz
    and the cut-off the runner computed, and the default basis gives none."""
    settings = dict(damping=0.02, bridge="modal")                          # dt: the default, 0.25 ms
    low = Sweep(_span10(), ["HSLM-A1"], "250", PassageSettings(modal_hz=40.0, **settings), ACCEL)
    full = Sweep(_span10(), ["HSLM-A1"], "250", PassageSettings(**settings), ACCEL)
    cutoff = low.runner.en_cutoff_hz
    assert cutoff == pytest.approx(9 * F10, rel=2e-3)                       # n₃ = 9 n₁
    assert low.runner.modal.n_modes == 1 and full.runner.modal.n_modes == 3   # 12, 48, 108 Hz: j² n₁
    peak = {name: s.run(None, workers=1, progress=False).envelope("acceleration_absmax").max()
            for name, s in (("low", low), ("full", full))}
    assert peak["low"] < 0.95 * peak["full"]                                # the under-read the note warns of
    assert low.resolution_note() == (
        f"note: the modal bridge's modes stop at modal_hz = 40 Hz, below the EN cut-off {cutoff:.4g} Hz: the deck "
        f"accelerations count frequencies up to 40 Hz only and may read low (the design check refuses them); take "
        f"modal_hz >= {cutoff:.4g} Hz, or leave it unset (the default: 1.1 x the cut-off, or more with moment "
        "outputs)")
    assert full.resolution_note() == ""
    coarse = Sweep(_span10(), ["HSLM-A1"], "250", PassageSettings(modal_hz=40.0, dt=4e-3, **settings), ACCEL)
    lines = coarse.resolution_note().splitlines()             # with a coarse dt: both notes, one line each
    assert lines[0] == low.resolution_note()
    assert lines[1].startswith("note: dt = 4 ms samples the modal bridge's highest frequency, 40 Hz, 6.25 times a "
                               "period")                       # 1 / (40 Hz × 4 ms)


def test_vtsi_sweep_prints_the_note_under_its_table(tmp_path, capsys, beam_toml):
    """The command line's summary (where the sweep's other notes land) ends with it; exit 0."""
    path = beam_toml(tmp_path / "b10.toml", {"spans_m": [L10], "f1_Hz": F10, "mu_kg_m": MU10,
                                              "elements_per_span": 10})
    status = main(["sweep", str(path), "--trains", "A1", "--speeds", "250", "--bridge-model", "modal",
                   "--damping", "0.02", "--modal-hz", "40", "--workers", "1", "--quiet", "--out",
                   str(tmp_path / "s.h5")])
    out = capsys.readouterr().out.splitlines()
    cutoff = float(re.search(r"EN cut-off ([0-9.]+) Hz", out[1]).group(1))
    assert status == 0 and cutoff == pytest.approx(9 * F10, rel=2e-3)
    assert out[-1].startswith(f"note: the modal bridge's modes stop at modal_hz = 40 Hz, below the EN cut-off "
                              f"{cutoff:g} Hz: the deck accelerations count frequencies up to 40 Hz only")


# -- 2 and 3. n_modes checked by the modal bridge ------------------------------------------------------
def _beam(consistent_mass=True):
    model = vtsi.Model()
    deck = continuous_beam(model, [20.0], 10, 3.5e10, 1.9, 15000.0, consistent_mass=consistent_mass)
    return model, Track(model, deck.elements)


@pytest.mark.parametrize("n_modes", [0, -3, 2.5, math.nan, math.inf, True, "3", "ALL"])
def test_n_modes_that_is_not_a_count_is_named_by_the_modal_bridge(n_modes, one_line):
    model, track = _beam()
    with pytest.raises(ModelError) as excinfo:
        ModalBridge(model, track, n_modes=n_modes, zeta=0.02)
    assert one_line(excinfo) == f"modal bridge: n_modes must be an integer >= 1 or 'all', got {n_modes!r}"


def test_a_whole_float_n_modes_is_a_count_as_elsewhere_in_vtsi():
    """3.0 crashed (TypeError: slice indices); vtsi's counts take a whole float (``is_count``: a
    car count, a sink's flush_every), and so does eigen: the same three modes as n_modes=3."""
    model, track = _beam()
    by_float, by_int = ModalBridge(model, track, n_modes=3.0, zeta=0.02), ModalBridge(model, track, n_modes=3, zeta=0.02)
    assert by_float.n_modes == 3 and np.array_equal(by_float.frequencies, by_int.frequencies)


@pytest.mark.parametrize("consistent_mass", [True, False])
def test_too_many_modes_names_the_most_the_bridge_takes(consistent_mass, one_line):
    """A 20 m beam of 10 elements, pinned (ux, uy) at x = 0 and on a roller (uy) at 20 m: 30 free
    dofs. Consistent mass: every free dof has mass, 30 modes; the track's (uy, rz) make 20 (the
    10 ux dofs make axial modes, which load no wheel). Lumped mass (no rotary inertia): the 19
    translations carry mass, 19 modes, of which the 9 interior uy move the track. The most named
    is accepted, and is what 'all' keeps."""
    model, track = _beam(consistent_mass)
    asm = model.build()
    free = asm.n_free
    axial = 10                                                        # ux at nodes 2 … 11
    most = {True: (free - axial, free), False: (9, 19)}[consistent_mass]   # (with the track, without)
    assert free == 3 * 11 - 3
    for on_track, n in zip((track, None), most):
        with pytest.raises(ModelError) as excinfo:
            ModalBridge(model, on_track, n_modes=1000, zeta=0.02)
        message = one_line(excinfo)
        assert message.startswith("modal bridge: n_modes = 1000, but " + (f"only {n} modes of the model move the track"
                                                                          if on_track else f"the model has only {n} modes"))
        assert message.endswith(f": n_modes must be at most {n}")
        assert ModalBridge(model, on_track, n_modes=n, zeta=0.02).n_modes == n
        assert ModalBridge(model, on_track, n_modes="all", zeta=0.02).n_modes == n


# -- 4. the check states the bridge model; support moments below the recommended basis ---------------
def test_the_check_text_and_the_report_state_the_bridge_model_and_basis(tmp_path):
    """The 10 m span's default basis, 1.1 × the cut-off: the three modes n₁, 4 n₁, 9 n₁; the text's
    line and the report's setting are the same words, the stored check's too; FE says so."""
    path = tmp_path / "m.h5"
    sweep = Sweep(_span10(), ["HSLM-A1"], "250", PassageSettings(dt=1e-3, damping=0.02, bridge="modal"))
    results = sweep.run(path, workers=1, progress=False)
    result = check(results)
    cutoff, top = sweep.runner.en_cutoff_hz, sweep.runner.modal.frequencies.max()
    assert top == pytest.approx(9 * F10, rel=2e-3)
    words = (f"modal: 3 modes up to {1.1 * cutoff:.4g} Hz (1.1 × the EN cut-off {cutoff:.4g} Hz, the default; the "
             f"highest at {top:.4g} Hz), exact passages of moving forces, cars time-stepped")
    assert result.bridge_model == words
    lines = result.text().splitlines()
    assert lines[2] == f"bridge model: {words}" and lines[1].startswith("check settings: ")
    result.store(path)
    assert stored_check(path).text() == result.text()
    report = write_report(path, tmp_path / "rep")["markdown"].read_text(encoding="utf-8")
    assert f"| bridge model | {words} |" in report
    fe = check(Sweep(_span10(), ["HSLM-A1"], "250", PassageSettings(dt=1e-3, damping=0.02)).run(
        None, workers=1, progress=False))
    assert "bridge model: FE model, time-stepped" in fe.text().splitlines()


BEARINGS = """model basic -ndm 2 -ndf 3
geomTransf Linear 1
uniaxialMaterial Elastic 1 2.0e9
uniaxialMaterial Elastic 2 1.0e12
""" + "".join(f"node {i + 1} {2.0 * i} 0.0\n" for i in range(21)) + "".join(
    f"element elasticBeamColumn {i + 1} {i + 1} {i + 2} 8.0 3.5e10 1.5 1 -mass 18000.0 -cMass\n" for i in range(20)) + "".join(
    f"node {201 + j} {2.0 * (n - 1)} 0.0\nnode {301 + j} {2.0 * (n - 1)} -8.0\nfix {301 + j} 1 1 1\n"
    f"element zeroLength {101 + j} {201 + j} {n} -mat 1 2 -dir 2 1\n"
    f"element elasticBeamColumn {401 + j} {301 + j} {201 + j} 6.0 3.5e10 4.0 1 -mass 15000.0 -cMass\n"
    for j, n in enumerate((1, 11, 21))) + "track 1 -eleRange 1 20\n"


@pytest.fixture(scope="module")
def on_bearings(tmp_path_factory):
    """A 2 × 20 m continuous deck (EI 5.25e10 N·m², 18 t/m) on 2 GN/m bearings on 8 m piers with
    mass (a probe's; modes 6.47, 8.14, 18.3, 22.9, 33.9, 43.1, 58.0 … Hz, EN cut-off 30 Hz),
    HSLM-A2 and A7 at 380–420 km/h (d = 3.5 and 2.0 m: v/d up to 58.3 Hz), ζ 1 %, swept on the
    modal bridge with the default basis, the cut-off's (33 Hz, the default before) and 400 Hz
    (the reference), and checked."""
    path = tmp_path_factory.mktemp("bearings") / "deck.tcl"
    path.write_text(BEARINGS)
    out = {}
    for label, modal_hz in (("default", None), ("cut-off", 33.0), ("400 Hz", 400.0)):
        sweep = Sweep(load_bridge(path), ["HSLM-A2", "HSLM-A7"], "380:420:5",
                      PassageSettings(damping=0.01, bridge="modal", modal_hz=modal_hz))
        results = sweep.run(None, workers=1, progress=False)
        out[label] = (sweep, results, check(results))
    return out


def test_the_default_basis_holds_the_modes_the_bogies_drive_for_the_moments(on_bearings):
    """The cut-off's basis leaves out the 33.9 and 58.0 Hz modes, which the bogies drive to
    resonance and the static correction, quasi-static, does not put back: it reads the hogging
    moment over the pier and the mid-span moment more than 10 % low against 400 Hz (measured
    13.7 % and 12.7 %). The default, 1.1 × 2 v/d = 128.3 Hz for a 2.0 m gap at 420 km/h, reads
    both within 1 %."""
    sweep, _, _ = on_bearings["default"]
    assert sweep.settings.modal_hz == pytest.approx(1.1 * 2 * (420 / 3.6) / 2.0, rel=1e-12)
    assert sweep.runner.modal.frequencies.max() < sweep.settings.modal_hz
    reference = on_bearings["400 Hz"][1]
    for name, extreme in (("support_moment_min", np.min), ("bending_moment_max", np.max)):
        exact = float(extreme(reference.envelope(name)))
        low = {k: 1.0 - float(extreme(r.envelope(name))) / exact for k, (_, r, _) in on_bearings.items()}
        assert low["cut-off"] > 0.10 and abs(low["default"]) < 0.01, (name, low)


def test_the_moment_rows_say_when_the_basis_stops_below_the_moments_default(on_bearings):
    """The cut-off's check says on every moment row (mid-span and over the pier) that its modes
    stop below the moments' default, and to take it; the default's and 400 Hz's say nothing of
    it; the bridge-model line says what set the default."""
    _, _, result = on_bearings["cut-off"]
    said = ("; the modal bridge's modes stop at 33 Hz, below the 128.3 Hz that holds the modes the trains' closest "
            "axles drive at 420 km/h: the static correction puts back only the higher modes' quasi-static share, and "
            "the moments may read low (over the pier of a 2 x 20 m deck on bearings and piers, modes to 33 Hz: 6.3 % "
            "low); sweep with modal_hz >= 128.3 Hz (the default) or the FE bridge")
    moment_rows = [r for r in result.rows if r.criterion.endswith("_moment")]
    assert {r.criterion for r in moment_rows} >= {"dynamic_increment_moment", "dynamic_vs_lm71_moment",
                                                  "dynamic_increment_support_moment", "dynamic_vs_lm71_support_moment"}
    assert all(said in r.note for r in moment_rows)
    assert not any(said in r.note for r in result.rows if not r.criterion.endswith("_moment"))
    for other in ("default", "400 Hz"):
        assert not any("below the 128.3 Hz" in r.note for r in on_bearings[other][2].rows)
    assert ("modes up to 128.3 Hz (4.28 × the EN cut-off 30 Hz, the default for the moments: 1.1 × twice the 58.33 Hz at which the "
            "trains' closest axles pass at 420 km/h; the highest at") in on_bearings["default"][2].bridge_model


def test_an_older_file_s_default_basis_is_named_to_continue_it(on_bearings, tmp_path, one_line):
    """A results file of an older vtsi stored modal_hz None (its default, 1.1 × the cut-off); today's
    sweep sets it: the refusal to continue names the value of the file, and that value, given,
    continues it (a probe: it named one that was refused again)."""
    bridge = on_bearings["cut-off"][0].bridge
    path = tmp_path / "old.h5"
    Sweep(bridge, ["HSLM-A2"], "400", PassageSettings(damping=0.01, bridge="modal", modal_hz=33.0)).run(
        path, workers=1, progress=False)
    with h5py.File(path, "r+") as f:
        identity = json.loads(f.attrs["identity"])
        identity["settings"]["modal_hz"] = None
        f.attrs["identity"] = json.dumps(identity)
    with pytest.raises(vtsi.errors.VtsiError) as excinfo:
        Sweep(bridge, ["HSLM-A2"], "400:410:10", PassageSettings(damping=0.01, bridge="modal")).run(
            path, workers=1, progress=False, resume=True)
    message = one_line(excinfo)
    given = float(re.search(r"give its modal_hz = ([0-9.]+) Hz\)", message).group(1))
    assert "it differs in settings.modal_hz (" in message and given == pytest.approx(33.0, rel=1e-9), message
    resumed = Sweep(bridge, ["HSLM-A2"], "400", PassageSettings(damping=0.01, bridge="modal", modal_hz=given)).run(
        path, workers=1, progress=False, resume=True)           # the value named continues the file
    assert resumed.n_done == 1

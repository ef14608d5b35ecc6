"""What a modal sweep and its check say of the modal bridge's basis (docs/modal.md), and the
modal bridge's own check of ``n_modes``.

- A ``modal_hz`` below the EN cut-off under-reads the deck acceleration; ``vtsi sweep`` printed
  it with no note (a 10 m span: 2.84 m/s² against 3.06) while the check refuses it: the summary
  now says so (``Sweep.resolution_note``).
- ``n_modes`` was checked by ``eigen`` (naming its own limit, the free dofs) or not at all (3.0
  crashed with a TypeError): the modal bridge now checks it, naming the most it takes.
- The check's text never named the bridge model (the report did): it now has a ``bridge model:``
  line, from the function the report's settings read; and its support-moment rows say when a
  modal basis stops below the one docs/modal.md recommends for support moments.

A simply supported beam's frequencies are n_j = j² n₁ (Euler-Bernoulli; e.g. Frýba, Vibration of
Solids and Structures under Moving Loads, 1999, ch. 1), so the EN 1990 A2.4.4.2.1 cut-off
max(30 Hz, 1.5 n₀, n₃) of a 10 m span with n₁ = 12 Hz is n₃ = 108 Hz (the FE beam: 108.1)."""
import math
import re
from pathlib import Path

import numpy as np
import pytest

import vtsi
from vtsi.__main__ import main
from vtsi.check import bridge_model_text, check, stored_check
from vtsi.errors import ModelError
from vtsi.modal_bridge import SUPPORT_MOMENT_HZ, ModalBridge
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
        f"modal_hz >= {cutoff:.4g} Hz, or leave it unset (1.1 x the cut-off)")
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
    assert bridge_model_text({"bridge": "fe"}, results.bridge()) == "FE model, time-stepped"


@pytest.fixture(scope="module")
def two_spans():
    """A 2 × 20 m continuous deck (the probe's; EN cut-off 30 Hz: n₀ 6.7 Hz, n₃ 26.8 Hz), swept
    on the modal bridge with the default basis, 60 Hz and 400 Hz (the reference), and checked."""
    spans, EI, mu = [20.0, 20.0], 3.5e10 * 1.5, 18000.0
    out = {}
    for label, modal_hz in (("default", None), ("60 Hz", 60.0), ("400 Hz", 400.0)):
        sweep = Sweep(beam_bridge(spans, EI, 1.0, mu, elements_per_span=10), ["HSLM-A1", "HSLM-A4", "HSLM-A9"],
                      "200:360:20", PassageSettings(damping=0.01, bridge="modal", modal_hz=modal_hz))
        results = sweep.run(None, workers=1, progress=False)
        out[label] = (sweep, results, check(results))
    return out


def test_support_moment_rows_say_when_the_basis_stops_below_the_recommended_one(two_spans):
    """The default basis (1.1 × 30 Hz) reads the hogging moment over the pier low against the
    modes up to 400 Hz, the 60 Hz basis closer: the default's support-moment rows say so, with
    the basis and the recommendation; the 60 Hz and 400 Hz checks do not, nor the mid-span rows."""
    hogging = {k: float(results.envelope("support_moment_min").min()) for k, (_, results, _) in two_spans.items()}
    low = {k: 1.0 - v / hogging["400 Hz"] for k, v in hogging.items()}
    assert low["default"] > 0.005 and abs(low["60 Hz"]) < low["default"]     # a fact of the run: ~1.0 %, 0.2 %
    sweep, _, result = two_spans["default"]
    basis = 1.1 * sweep.runner.en_cutoff_hz
    assert sweep.runner.en_cutoff_hz == pytest.approx(30.0) and basis < SUPPORT_MOMENT_HZ
    said = (f"; the modal bridge's modes stop at {basis:.4g} Hz, below the {SUPPORT_MOMENT_HZ:g} Hz docs/modal.md "
            f"recommends for support moments, which many modes make: the hogging moment may read low; sweep with "
            f"modal_hz >= {SUPPORT_MOMENT_HZ:g} Hz or the FE bridge")
    for criterion in ("dynamic_increment_support_moment", "dynamic_vs_lm71_support_moment"):
        assert said in result.row(criterion).note
        for other in ("60 Hz", "400 Hz"):
            assert "docs/modal.md recommends" not in two_spans[other][2].row(criterion).note
    assert not any("docs/modal.md recommends" in r.note for r in result.rows if not r.criterion.endswith("support_moment"))


def test_the_recommended_basis_is_the_one_docs_modal_md_gives():
    """One number: docs/modal.md's recommendation and docs/check.md's row are SUPPORT_MOMENT_HZ."""
    modal = " ".join((DOCS / "modal.md").read_text().split())
    assert f"For support moments take `modal_hz` of {SUPPORT_MOMENT_HZ:g} Hz or more, or the FE bridge" in modal
    check_md = (DOCS / "check.md").read_text()
    assert f"below the {SUPPORT_MOMENT_HZ:g} Hz `docs/modal.md` recommends for support moments" in check_md

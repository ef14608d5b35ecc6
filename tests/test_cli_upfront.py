"""Inputs refused before anything runs: what the check would refuse after the sweep (a modal
bridge whose modes stop below the EN cut-off), a deck mass typed in t/m whichever way the bridge
comes, and the sweep's note of a Δt its check would call unconverged."""
import os
import re

import pytest

import vtsi
from vtsi.__main__ import main
from vtsi.errors import BridgeModelError, BridgeSweepError, SweepError
from vtsi.passage import PassageSettings
from vtsi.sweep import Sweep, SweepBridge, beam_bridge

CUTOFF = "below the EN 1990 A2.4.4.2.1(4)P cut-off 45.82 Hz"
TONNES = "the deck weighs 15 kg/m along its track, below 500 kg/m (no railway deck is that light)"


@pytest.fixture
def bridge(tmp_path, beam_toml):
    return beam_toml(tmp_path / "bridge.toml", damping=0.0125)


def test_check_refuses_modal_hz_below_the_cutoff_before_the_sweep(tmp_path, bridge, capsys, monkeypatch):
    """It ran the whole sweep, wrote the results and an empty report folder, then exited 3 ('a
    passage failed')."""
    monkeypatch.chdir(tmp_path)
    status = main(["check", str(bridge), "--trains", "HSLM-A1", "--speeds", "300", "--bridge-type", "steel",
                   "--bridge-model", "modal", "--modal-hz", "20", "--out", "m20.h5", "--workers", "1", "--quiet"])
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert status == 2
    assert len(lines) == 1 and lines[0].startswith("vtsi check: the deck acceleration output 'acceleration' "
                                                   "counts frequencies up to 20 Hz, " + CUTOFF), err
    assert "take modal_hz >= 45.82 Hz" in lines[0]
    assert sorted(os.listdir(tmp_path)) == ["bridge.toml"]          # no .h5, no report folder


def test_design_check_refuses_before_running(tmp_path, monkeypatch):
    from vtsi.workflow import design_check

    def no_run(*args, **kwargs):
        raise AssertionError("the sweep ran")

    monkeypatch.setattr(Sweep, "run", no_run)
    EI = 15000.0 * (2 * 3.141592653589793 * 5.0 * (20.0 / 3.141592653589793) ** 2) ** 2
    sweep = Sweep(beam_bridge([20.0], EI, 1.0, 15000.0, elements_per_span=4), ["HSLM-A1"], "300",
                  PassageSettings(damping=0.0125, bridge="modal", modal_hz=20.0))
    with pytest.raises(SweepError, match=r"counts frequencies up to 20 Hz, below the EN 1990 A2\.4\.4\.2\.1\(4\)P "
                                         r"cut-off 45\.82 Hz"):
        design_check(sweep, tmp_path / "d.h5")
    assert os.listdir(tmp_path) == []


def test_design_check_refuses_an_acceleration_output_off_the_deck_before_running(tmp_path, monkeypatch):
    from vtsi.passage import Output
    from vtsi.workflow import design_check

    monkeypatch.setattr(Sweep, "run", lambda *args, **kwargs: pytest.fail("the sweep ran"))
    bridge = beam_bridge([20.0], 3.5e10, 1.9, 15000.0, elements_per_span=4)
    bridge.model.node(99, 10.0, -5.0)                       # a pier's foot: no deck node
    bridge.model.fix(99, 1, 1, 1)
    sweep = Sweep(bridge, ["HSLM-A1"], "300", PassageSettings(damping=0.0125),
                  outputs=[Output("a", "accel", nodes=(99,))])
    with pytest.raises(SweepError, match=r"^check: the deck acceleration output 'a' holds no deck node \(nodes 99\)"):
        design_check(sweep, tmp_path / "d.h5")
    assert os.listdir(tmp_path) == []


def test_beam_bridge_in_tonnes_per_metre_is_refused():
    """beam_bridge([20.0], E=3.5e10, I=0.6948, mu=15.0) ran: n0 158 Hz, cut-off 1424 Hz, 23.5 m/s²."""
    with pytest.raises(BridgeSweepError, match=r"^sweep: bridge: " + re.escape(TONNES) + r"; .*typed in t/m \(15 t/m is "
                                               r"15000 kg/m\)"):
        Sweep(beam_bridge([20.0], E=3.5e10, I=0.6948, mu=15.0), ["HSLM-A1"], "300")
    # a laboratory model, knowingly light: the opt-out
    Sweep(beam_bridge([20.0], E=3.5e10, I=0.6948, mu=15.0, min_mass_per_metre=0), ["HSLM-A1"], "300")


@pytest.mark.parametrize("spans, words", [([25000.0], "a span of 25000 m is not a railway span (1 to 1000 m); is "
                                                      "spans in mm?"),
                                          ([20.0, 0.025], "a span of 0.025 m is not a railway span (1 to 1000 m); "
                                                          "is spans in km?")])
def test_beam_bridge_in_mm_is_refused_as_a_bridge_file_is(spans, words):
    """beam_bridge([25000.0], E=3.5e10, I=3.0, mu=18000.0) was accepted, and the Sweep then blamed
    E, I or the mass; a bridge file's spans_m = [25000.0] says 'is spans_m in mm?'."""
    with pytest.raises(BridgeModelError) as excinfo:
        beam_bridge(spans, E=3.5e10, I=3.0, mu=18000.0, elements_per_span=10)
    assert str(excinfo.value) == "beam_bridge: spans: " + words
    assert beam_bridge([1.0, 1000.0], E=3.5e10, I=3.0, mu=18000.0).description["spans_m"] == [1.0, 1000.0]


def _user_deck(rho):
    model = vtsi.Model()
    for i in range(11):
        model.node(i + 1, 2.0 * i, 0.0)
    model.fix(1, 1, 1, 0)
    model.fix(11, 0, 1, 0)
    for e in range(1, 11):
        model.element("elasticBeamColumn", e, (e, e + 1), A=5.0, E=3.5e10, I=0.6948, rho=rho)
    return model


def test_a_user_model_in_tonnes_per_metre_is_refused():
    with pytest.raises(BridgeSweepError, match=r"^sweep: bridge: " + re.escape(TONNES)):
        Sweep(SweepBridge(_user_deck(15.0), list(range(1, 11)), {"kind": "user"}), ["HSLM-A1"], "300")
    with pytest.raises(BridgeSweepError, match=r"above 1e\+06 kg/m \(no railway deck is that heavy\)"):
        Sweep(SweepBridge(_user_deck(1.5e7), list(range(1, 11)), {"kind": "user"}), ["HSLM-A1"], "300")
    Sweep(SweepBridge(_user_deck(15000.0), list(range(1, 11)), {"kind": "user"}), ["HSLM-A1"], "300")


def test_a_bridge_file_in_tonnes_per_metre_is_refused_with_the_same_words(tmp_path, bridge, beam_toml, capsys):
    beam_toml(bridge, {"f1_Hz": None, "I_m4": 0.6948, "mu_kg_m": 15.0}, damping=0.0125)
    status = main(["sweep", str(bridge), "--trains", "HSLM-A1", "--speeds", "300", "--out", str(tmp_path / "s.h5")])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err
    assert err.startswith(f"vtsi sweep: bridge file {bridge}: {TONNES}; ") and "typed in t/m" in err, err
    assert not (tmp_path / "s.h5").exists()


@pytest.mark.parametrize("dt, noted", [("0.002", True), (None, False)])
def test_sweep_notes_a_dt_coarser_than_the_check_resolves(tmp_path, bridge, capsys, dt, noted):
    """vtsi check called dt = 2 ms 'not converged' on the docs' own example; vtsi sweep said nothing."""
    status = main(["sweep", str(bridge), "--trains", "HSLM-A1", "--speeds", "300", "--out", str(tmp_path / "s.h5"),
                   "--workers", "1", "--quiet", *(["--dt", dt] if dt else [])])
    out = capsys.readouterr().out
    assert status == 0
    notes = [line for line in out.splitlines() if line.startswith("note: ")]
    if noted:
        assert notes == ["note: dt = 2 ms steps the EN cut-off, 45.82 Hz, 10.9 times a period (Newmark's period error "
                         "there, (2 pi f dt)^2/12 = 2.8 %, is 2.2 x the damping ratio (1.25 %): a mode there resonates at "
                         "a speed 2.8 % off, and its share of a peak at one speed may be off by up to 59 % either way): "
                         "the deck accelerations are not converged in dt; take dt <= 0.4 ms (the default's rule: 20 "
                         "steps a period and Newmark's period error at most 0.1 x the damping ratio (1.25 %), dt <= "
                         "sqrt(1.2 zeta) / (2 pi f); a dt left unset keeps it)"]
    else:
        assert notes == []


def test_approaches_on_the_ground_do_not_dilute_the_deck_mass():
    """The deck mass per metre is read over the decks, not the whole track: a 4 t/m, 12 m deck with
    60 m of rail (120 kg/m) on ground springs at each end read 472.7 kg/m over the 132 m track and
    was refused as 'typed in t/m'; over its 12 m deck it reads 5200 kg/m (the rail's 14.4 t counted
    with the deck's 48 t) and is accepted."""
    import numpy as np

    import vtsi
    from vtsi.units import deck_mass_per_length

    m = vtsi.Model()
    xs = np.arange(-60.0, 72.0 + 1e-9, 2.0)
    for i, x in enumerate(xs):
        m.node(i + 1, float(x), 0.0)
        if x < -1e-9 or x > 12.0 + 1e-9:                      # the approaches: rail on ground springs
            m.node(1000 + i, float(x), 0.0)
            m.fix(1000 + i, 1, 1, 1)
            m.element("zeroLength", 1000 + i, (i + 1, 1000 + i), ky=1e8)
        elif abs(x) < 1e-9 or abs(x - 12.0) < 1e-9:
            m.fix(i + 1, int(abs(x) < 1e-9), 1, 0)
    for e in range(1, len(xs)):
        deck = 0.0 <= 0.5 * (xs[e - 1] + xs[e]) <= 12.0
        m.element("elasticBeamColumn", e, (e, e + 1), A=1.0, E=2.1e11, I=0.05 if deck else 3e-5,
                  rho=4000.0 if deck else 120.0)
    track = list(range(1, len(xs)))
    assert deck_mass_per_length(m, track) == pytest.approx((12 * 4000.0 + 120 * 120.0) / 12.0, rel=1e-12)
    sweep = Sweep(SweepBridge(m, track, {"kind": "script"}), ["HSLM-A1"], "300", PassageSettings(dt=2e-3, damping=0.02))
    assert sweep.runner.span_lengths == pytest.approx([12.0])

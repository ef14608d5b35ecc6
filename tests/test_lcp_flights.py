"""Raw wheel flights on a deck (contact='lcp'): counted per case, kept in the results file and
read by the check's wheel-unloading and contact-loss rows (docs/check.md, Limits).

The case: an ICE3 (cars='full') at 360 km/h over a 15 m simply supported span, n0 = 5.5 Hz,
12 t/m, ζ = 1.35 %, smooth rail, Δt = 0.4 ms. Its wheels fly where the rail kinks at the span's
ends; with 'bspline' rows the flight and the unloading depend on Δt (ΔQ/Q 0.26, 0.31, 0.39, 0.42
at Δt 0.8, 0.4, 0.2, 0.1 ms, 12 of its 32 wheels flying at 0.4 ms) against 0.45 with 'hermite'
rows and exact events (measured, /tmp/lf/measure.py of the change that added the count).
"""
import shutil

import h5py
import numpy as np
import pytest

import vtsi.passage as passage
from vtsi.check import CheckSettings, check
from vtsi.passage import Output, PassageSettings
from vtsi.sweep import Sweep, beam_bridge
from vtsi.errors import ModelError
from vtsi.sweep_results import SweepResults

L, F1, MU, ZETA, DT = 15.0, 5.5, 12000.0, 0.0135, 4e-4
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
FLIGHT = "had a wheel fly on a deck"


def _sweep(speeds="360", **settings):
    settings = {"contact": "lcp", **settings}
    return Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=10), ["ICE3"], speeds,
                 PassageSettings(cars="full", damping=ZETA, dt=DT, **settings))


@pytest.fixture(scope="module")
def bspline(tmp_path_factory):
    path = str(tmp_path_factory.mktemp("lcp_flights") / "bspline.h5")
    return path, _sweep().run(path, workers=1, progress=False)


def _flights_by_hand(sweep, speed_kmh):
    """The wheels that flew on a deck, from the analysis's own gap record and the contact-force
    envelope's window (PassageRunner.counted), outside the code under test."""
    kept = []

    class Kept(passage.CoupledAnalysis):
        def run(self, *args, **kwargs):
            kept.append(self)
            return super().run(*args, **kwargs)

    original, passage.CoupledAnalysis = passage.CoupledAnalysis, Kept
    try:
        result = sweep.runner.run("ICE3", speed_kmh)
    finally:
        passage.CoupledAnalysis = original
    analysis = kept[-1]
    train = sweep.runner.train("ICE3", speed_kmh / 3.6)
    counted = sweep.runner.counted(Output("f", "contact_force"), train, result.x_head0, np.asarray(analysis.time))
    flying = np.asarray(analysis.gap) > analysis.gap_tol
    return result, int(np.sum(np.any(flying & counted, axis=0)))


def test_the_flights_on_a_deck_are_counted_written_and_read(bspline):
    path, res = bspline
    result, by_hand = _flights_by_hand(_sweep(), 360.0)
    assert result.deck_flights == by_hand == 12                 # 12 of the 32 wheels, at the span's ends
    with h5py.File(path, "r") as f:
        stored = f["cases/deck_flights"][()]
        speeds = f["cases/speed_kmh"][()]
    assert stored.dtype == np.int64
    assert speeds.tolist() == [360.0] and stored.tolist() == [12]
    assert SweepResults(path).deck_flights().tolist() == [[[12.0]]]
    slow = _sweep("160").run(None, workers=1, progress=False)
    assert slow.deck_flights().tolist() == [[[0.0]]]
    bilateral = _sweep(contact="bilateral", integrator="HHT(0.9)").run(None, workers=1, progress=False)
    assert np.all(np.isnan(bilateral.deck_flights()))           # not counted: -1 in the file


def test_a_flight_on_bspline_rows_leaves_a_pass_not_checked_and_a_fail_standing(bspline):
    """exact_events on 'bspline' rows would do nothing (a probe's PASS of 0.31 stood with no
    note, its file saying exact events): refused; with cars it takes 'hermite' rows by default."""
    _, res = bspline
    result = check(res)
    row, loss = result.row("wheel_unloading"), result.row("contact_loss")
    assert row.value == pytest.approx(0.308, abs=0.005) and row.value < row.limit
    assert row.status == "info" and "wheel_unloading" in result.unchecked
    assert f"1 of 1 passages {FLIGHT}" in row.note
    assert "not checked: with 'bspline' rows such a flight" in row.note
    assert "interpolation='hermite' with exact_events=True" in row.note and "--interpolation hermite" in row.note
    assert loss.status == "pass" and loss.value == 0.0         # the mean never reaches zero
    assert "1 of 1 passages had a wheel fly on a deck for less than the 10 ms mean shows" in loss.note
    failed = check(res, CheckSettings(unloading_limit=0.3)).row("wheel_unloading")
    assert failed.status == "fail" and FLIGHT in failed.note and "not checked" not in failed.note
    with pytest.raises(ModelError, match=r"exact_events takes the kinks of 'hermite' rows; 'bspline' rows smooth "
                                         r"them and take none: take interpolation='hermite'"):
        _sweep(exact_events=True, interpolation="bspline")            # it would do nothing (a probe's PASS of 0.31)
    assert PassageSettings(cars="full", exact_events=True).interpolation == "hermite"
    deck = result.row("deck_acceleration")       # touch-downs excite the deck: not converged in dt (probe M3)
    assert "1 of 1 passages had a wheel fly on a deck (contact='lcp'), and each touch-down" in deck.note
    assert "read it from a sweep with bilateral contact or moving forces" in deck.note
    assert deck.status == ("fail" if deck.value > deck.limit else "info")
    passing = check(_sweep("200", interpolation="hermite").run(None, workers=1, progress=False))
    row = passing.row("deck_acceleration")          # 1.46 m/s^2, 28 wheels flew: a PASS is not sure
    assert row.value < row.limit and row.status == "info" and "deck_acceleration" in passing.unchecked
    assert "; not checked: 1 of 1 passages had a wheel fly on a deck (contact='lcp')" in row.note
    deck_only = Sweep(beam_bridge([L], EI, 1.0, MU, elements_per_span=10), ["ICE3"], "200",
                      PassageSettings(cars="full", damping=ZETA, dt=DT, contact="lcp", interpolation="hermite"),
                      outputs=(Output("acceleration", "accel", cutoff="en"),)).run(None, workers=1, progress=False)
    assert deck_only.deck_flights().tolist() == [[[28.0]]]        # counted without a contact-force output
    assert check(deck_only).row("deck_acceleration").status == "info"


def test_no_note_without_a_flight_with_exact_events_or_bilateral_contact():
    slow = check(_sweep("160").run(None, workers=1, progress=False))
    exact = check(_sweep("360", interpolation="hermite", exact_events=True).run(None, workers=1, progress=False))
    bilateral = check(_sweep("360", contact="bilateral", integrator="HHT(0.9)").run(None, workers=1, progress=False))
    assert "fly on a deck" not in slow.row("deck_acceleration").note + bilateral.row("deck_acceleration").note
    for result in (slow, exact, bilateral):
        assert "fly on a deck" not in result.row("wheel_unloading").note
        assert result.row("wheel_unloading").status == "pass"
    assert "fly on a deck" not in slow.row("contact_loss").note + bilateral.row("contact_loss").note
    assert "1 of 1 passages had a wheel fly on a deck for less" in exact.row("contact_loss").note   # a fact, on any rows
    assert exact.row("wheel_unloading").value == pytest.approx(0.452, abs=0.005)   # the converged ~0.45
    hermite = check(_sweep("360", interpolation="hermite").run(None, workers=1, progress=False))
    row = hermite.row("wheel_unloading")
    assert row.status == "pass" and FLIGHT in row.note and "exact_events=True takes each kink" in row.note


def test_a_file_without_the_count_reads_as_before(bspline, tmp_path):
    path = str(tmp_path / "older.h5")
    shutil.copy(bspline[0], path)
    with h5py.File(path, "r+") as f:
        del f["cases/deck_flights"]
    older = SweepResults(path)
    assert older.deck_flights() is None
    result = check(older)
    row, loss = result.row("wheel_unloading"), result.row("contact_loss")
    assert row.status == "pass" and row.value == pytest.approx(0.308, abs=0.005)
    assert "fly on a deck" not in row.note and "fly on a deck" not in loss.note


def test_an_older_file_resumed_counts_only_its_new_cases(tmp_path):
    path = str(tmp_path / "resumed.h5")
    _sweep("160,360").run(path, workers=1, progress=False)
    with h5py.File(path, "r+") as f:         # an older vtsi's file, interrupted after its first case
        cases = f["cases"]
        del cases["deck_flights"]
        for name in [k for k in cases if isinstance(cases[k], h5py.Dataset)]:
            cases[name].resize(1, axis=0)
    resumed = _sweep("160,360").run(path, workers=1, progress=False, resume=True)
    assert resumed.n_done == 2
    np.testing.assert_array_equal(resumed.deck_flights().ravel(), [np.nan, 12.0])   # the old case: not counted


def test_the_command_line_takes_exact_events(tmp_path, beam_toml, capsys):
    """--exact-events (the flight note's remedy, with --interpolation hermite) reaches the sweep's
    settings; left out, the bridge file's [analysis] exact_events stands, and absent both, off."""
    from vtsi.__main__ import main

    def ran(*options, **analysis):
        path = beam_toml(tmp_path / "b.toml", **analysis)
        out = tmp_path / f"s{len(list(tmp_path.iterdir()))}.h5"
        assert main(["sweep", str(path), "--trains", "ICE3", "--speeds", "200", "--cars", "full", "--contact", "lcp",
                     "--interpolation", "hermite", "--workers", "1", "--quiet", "--out", str(out), *options]) == 0
        return SweepResults(out).identity["settings"]["exact_events"]

    assert ran("--exact-events") is True and ran(exact_events=True) is True and ran() is False
    args = ["sweep", str(beam_toml(tmp_path / "c.toml")), "--trains", "ICE3", "--speeds", "200", "--cars", "full",
            "--contact", "lcp", "--workers", "1", "--quiet", "--out", str(tmp_path / "c.h5")]
    assert main(args + ["--exact-events"]) == 0 and main(args + ["--resume"]) == 2
    assert "differs in settings.exact_events (false here, true in the file) (to continue that file, give " \
           "--exact-events or [analysis] exact_events = true)" in capsys.readouterr().err
    on = beam_toml(tmp_path / "on.toml", exact_events=True)            # --no-exact-events over the file's
    out = tmp_path / "off.h5"
    assert main(["sweep", str(on), "--trains", "ICE3", "--speeds", "200", "--cars", "full", "--contact", "lcp",
                 "--no-exact-events", "--workers", "1", "--quiet", "--out", str(out)]) == 0
    assert SweepResults(out).identity["settings"]["exact_events"] is False

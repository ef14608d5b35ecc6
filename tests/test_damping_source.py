"""Where ``vtsi check``'s damping came from, when the bridge is an OpenSees script with damping
of its own (``rayleigh``, ``modalDamping``): the check's ratio (EN 1991-2 Table 6.6 for
``--bridge-type``, ``--damping``, a bridge file's ``[analysis] damping``) replaces it, as a sweep
with a damping ratio replaces the model's own (vtsi.passage.PassageRunner). Before, the check
stored only where its ratio came from, and nobody was told that the script's damping was
dropped; now ``damping_source`` (stored with the check, printed in the report) names what it
replaced, a line on standard error says so, and a check without a ratio says that it does not
take the script's."""
import math

import pytest

import vtsi.workflow
from vtsi.__main__ import main
from vtsi.bridge_file import script_bridge
from vtsi.check import stored_check
from vtsi.damping import bridge_frequencies
from vtsi.errors import SweepError
from vtsi.passage import PassageSettings
from vtsi.sweep import Sweep

RAYLEIGH_LINE = "rayleigh 0.1 0.0 0.002 0.0\n"          # the Tcl deck's damping, after deck_tcl's lines
# the deck's n0 = 5 Hz and EN cut-off 45.02 Hz (its n3), and the ratio ζ(f) = αM / (4π f) + π βK f
# of the script's rayleigh there: test_the_ratios_named_are_the_rayleigh_factors_at_n0_and_the_cutoff
N0, CUTOFF = "5", "45.02"
AT = f"at n0 = {N0} Hz, {{}} at the EN cut-off {CUTOFF} Hz"
RAYLEIGH = f"the bridge script's rayleigh αM = 0.1 1/s, βK = 0.002 s (ζ = 3.3 % {AT.format('28.3 %')})"
# EN 1991-2 Table 6.6, lower limits for spans L >= 20 m: prestressed concrete 1.0 %, steel 0.5 %
PRESTRESSED = "EN 1991-2 Table 6.6, prestressed concrete, longest span L = 20 m: 1 %"
CHECK = ["--trains", "HSLM-A1", "--speeds", "300", "--dt", "0.005", "--workers", "1"]


@pytest.fixture
def stopped_after_preparing(monkeypatch):
    """vtsi check stopped at its up-front refusal (exit 2, nothing run): ``damping_sources`` holds
    the damping_source of the settings the check would have stored."""
    sources = []

    def stop(sweep, settings=None):
        sources.append(settings.damping_source)
        raise SweepError("check: stopped by the test")

    monkeypatch.setattr(vtsi.workflow, "refuse_before_sweep", stop)
    return sources


def test_bridge_type_replaces_a_tcl_scripts_rayleigh_stored_and_reported(tmp_path, deck_tcl, capsys, monkeypatch):
    pytest.importorskip("tkinter")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(vtsi.workflow, "rendering_available", lambda: (False, "test: no scene"))
    (tmp_path / "deck.tcl").write_text(deck_tcl(RAYLEIGH_LINE))
    assert main(["check", "deck.tcl", *CHECK, "--bridge-type", "prestressed_concrete"]) in (0, 1)
    source = f"{PRESTRESSED}; it replaces {RAYLEIGH} (deck.tcl)"
    assert (f"vtsi check: --bridge-type prestressed_concrete replaces {RAYLEIGH} (deck.tcl) by ζ = 1 %: {PRESTRESSED}"
            in capsys.readouterr().err.splitlines())
    assert stored_check(tmp_path / "check.h5").settings.damping_source == source
    report = (tmp_path / "check_report" / "report.md").read_text(encoding="utf-8")
    assert f"| damping from | {source} |" in report


def test_the_ratios_named_are_the_rayleigh_factors_at_n0_and_the_cutoff(tmp_path, deck_script):
    """The ζ named beside a script's rayleigh factors is αM / (4π f) + π βK f at the bridge's n0
    and at its EN cut-off max(30 Hz, 1.5 n0, n3), as a sweep reads them: the deck's n0 is the
    5 Hz its I was chosen for, its n3 the beam's 9 n0 (to 0.1 %); the ratios of this file's three
    rayleigh cases to three significant digits."""
    (tmp_path / "deck.py").write_text(deck_script(0.6948))
    bridge = script_bridge(tmp_path / "deck.py")
    f = bridge_frequencies(bridge.model, bridge.track_elements)
    n0, n3 = f.deck_hz[0, 0], f.deck_hz[0, 2]
    assert n0 == pytest.approx(5.0, rel=1e-3) and n3 == pytest.approx(9 * n0, rel=1e-3)
    assert f.cutoff_hz == max(30.0, 1.5 * n0, n3)
    assert (f"{n0:.4g}", f"{f.cutoff_hz:.4g}") == (N0, CUTOFF)
    ratio = (lambda alpha, beta, hz: f"{100 * (alpha / (4 * math.pi * hz) + math.pi * beta * hz):.3g} %")
    assert [(ratio(a, b, n0), ratio(a, b, f.cutoff_hz)) for a, b in ((0.1, 0.002), (0.0, 0.002), (0.1, 0.0))] == [
        ("3.3 %", "28.3 %"), ("3.14 %", "28.3 %"), ("0.159 %", "0.0177 %")]


def test_what_the_damping_replaces_is_true(tmp_path, deck_script):
    """The sweep's damping ratio replaces the script's rayleigh: the passages' model has the same
    Rayleigh factors as the script's model without it."""
    (tmp_path / "damped.py").write_text(deck_script(0.6948, "ops.rayleigh(0.1, 0.0, 0.002, 0.0)\n"))
    (tmp_path / "bare.py").write_text(deck_script(0.6948))
    factors = [Sweep(script_bridge(tmp_path / name), ["HSLM-A1"], "300", PassageSettings(damping=0.01))
               .runner.model.rayleigh_factors for name in ("damped.py", "bare.py")]
    assert factors[0] == factors[1] != (0.1, 0.002)


@pytest.mark.parametrize("tail, options, source, note", [
    ("ops.rayleigh(0.1, 0.0, 0.002, 0.0)\n", ["--damping", "0.02"],
     f"--damping 0.02; it replaces {RAYLEIGH} (deck.py)", f"vtsi check: --damping 0.02 replaces {RAYLEIGH} (deck.py) by ζ = 2 %"),
    ("ops.rayleigh(0.0, 0.0, 0.001, 0.001)\n", ["--damping", "0.02"],          # βK: the sum of the three
     f"--damping 0.02; it replaces the bridge script's rayleigh αM = 0 1/s, βK = 0.002 s (ζ = 3.14 % "
     f"{AT.format('28.3 %')}) (deck.py)", "βK = 0.002 s"),
    ("ops.eigen(4)\nops.modalDamping(0.02)\n", ["--damping", "0.015", "--bridge-model", "modal"],
     "--damping 0.015; it replaces the bridge script's modalDamping 0.02 on modes 1-4 of its eigen (deck.py)",
     "vtsi check: --damping 0.015 replaces the bridge script's modalDamping 0.02 on modes 1-4 of its eigen (deck.py) "
     "by ζ = 1.5 %"),
    ("ops.rayleigh(0.1, 0.0, 0.0, 0.0)\nops.eigen(2)\nops.modalDamping(0.02, 0.01)\n", ["--bridge-type", "steel"],
     "EN 1991-2 Table 6.6, steel, longest span L = 20 m: 0.5 %; it replaces the bridge script's rayleigh αM = 0.1 1/s, "
     f"βK = 0 s (ζ = 0.159 % {AT.format('0.0177 %')}) and modalDamping 0.02 0.01 on modes 1-2 of its eigen (deck.py)",
     "by ζ = 0.5 %: EN 1991-2 Table 6.6"),
    ("", ["--bridge-type", "steel"], "EN 1991-2 Table 6.6, steel, longest span L = 20 m: 0.5 %", None),
], ids=["--damping over rayleigh", "betaK summed", "--damping over modalDamping",
        "--bridge-type over rayleigh and modalDamping", "no damping of its own"])
def test_a_python_scripts_own_damping_named_as_replaced(tmp_path, deck_script, capsys, monkeypatch,
                                                         stopped_after_preparing, tail, options, source, note):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "deck.py").write_text(deck_script(0.6948, tail))
    assert main(["check", "deck.py", *CHECK, *options]) == 2
    assert stopped_after_preparing == [source]
    err = capsys.readouterr().err
    assert (note in err) if note else ("replaces" not in err)
    assert main(["check", "deck.py", *CHECK, *options, "--quiet"]) == 2        # --quiet: no note
    assert "replaces" not in capsys.readouterr().err


def test_a_bridge_files_damping_over_a_script(tmp_path, deck_tcl, capsys, monkeypatch, stopped_after_preparing):
    """A bridge file naming a script, with [analysis] damping: its ratio replaces the script's
    rayleigh (named in the source; no note: the file is the bridge's own description), and
    --damping replaces both."""
    pytest.importorskip("tkinter")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "deck.tcl").write_text(deck_tcl(RAYLEIGH_LINE))
    (tmp_path / "b.toml").write_text('[bridge]\nkind = "script"\npath = "deck.tcl"\n[analysis]\ndamping = 0.02\n')
    assert main(["check", "b.toml", *CHECK]) == 2
    assert main(["check", "b.toml", *CHECK, "--damping", "0.013"]) == 2
    assert stopped_after_preparing == [
        f"the bridge file's [analysis] damping = 0.02 (b.toml); it replaces {RAYLEIGH} (deck.tcl)",
        f"--damping 0.013; it replaces the bridge file's [analysis] damping = 0.02 (2 %) and {RAYLEIGH} (deck.tcl)"]
    err = capsys.readouterr().err.splitlines()
    assert f"vtsi check: --damping 0.013 replaces {RAYLEIGH} (deck.tcl) by ζ = 1.3 %" in err
    assert sum("replaces" in line for line in err) == 1


def test_a_check_without_a_ratio_says_it_does_not_take_the_scripts(tmp_path, deck_script, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "deck.py").write_text(deck_script(0.6948, "ops.rayleigh(0.1, 0.0, 0.002, 0.0)\n"))
    assert main(["check", "deck.py", *CHECK]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "vtsi check: the bridge's damping is needed: --bridge-type TYPE (EN 1991-2 Table 6.6) or --damping ZETA; a "
        f"check does not take {RAYLEIGH} (deck.py)"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deck.py"]

"""What ``vtsi sweep --help`` and ``vtsi check --help`` say of their shared passage settings,
against the code that decides them (vtsi.passage's time-step rule, the check's damping), and
docs/cli.md's ``[analysis]`` table against vtsi.bridge_file.ANALYSIS_KEYS."""
import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from vtsi.__main__ import main
from vtsi.bridge_file import ANALYSIS_KEYS, read_bridge_file
from vtsi.models.irregularity import WAVELENGTH_BAND
from vtsi.passage import MIN_STEP_DAMPING, PERIOD_ERROR_SHARE, STEPS_PER_CUTOFF_PERIOD, dt_resolving

CLI_MD = Path(__file__).parent.parent / "docs" / "cli.md"


def option_help(command, option, capsys, monkeypatch):
    """The help paragraph of ``option`` in ``vtsi COMMAND --help``, on one line."""
    monkeypatch.setenv("COLUMNS", "1000")          # argparse wraps at the terminal: one line per option
    with pytest.raises(SystemExit) as stop:
        main([command, "--help"])
    assert stop.value.code == 0
    text = capsys.readouterr().out
    match = re.search(rf"^  {re.escape(option)}\b(.*?)(?=^  -|^\S|\Z)", text, re.M | re.S)
    assert match, f"vtsi {command} --help has no {option}"
    return " ".join(match.group(1).split())


def test_check_damping_help_says_it_is_required_and_sweep_keeps_the_bridge_as_built(capsys, monkeypatch):
    """A check without --damping, --bridge-type or the file's damping exits 2 (test_cli_check);
    its help says so, where the sweep's gives the bridge as built as the default."""
    check = option_help("check", "--damping", capsys, monkeypatch)
    sweep = option_help("sweep", "--damping", capsys, monkeypatch)
    assert "required unless --bridge-type or the bridge file's [analysis] damping gives it" in check
    assert "the bridge as built" not in check
    assert "default: the bridge as built (a beam: undamped)" in sweep
    assert "required" not in sweep


@pytest.mark.parametrize("command", ["sweep", "check"])
def test_dt_help_states_the_rule_of_dt_resolving(command, capsys, monkeypatch):
    """The --dt help names the rule vtsi.passage applies: its constants, the sampling-only rule
    of exact modal passages, the rail's shortest wavelength for cars on an irregular rail, and
    the mantissas dt_resolving rounds down to (found by running it over 1-1000 Hz and ζ)."""
    text = option_help(command, "--dt", capsys, monkeypatch)
    assert f"{STEPS_PER_CUTOFF_PERIOD} steps a period of the EN cut-off" in text
    assert f"at most {PERIOD_ERROR_SHARE:g} zeta, dt <= sqrt({12 * PERIOD_ERROR_SHARE:g} zeta)/(2 pi f)" in text
    assert f"at least {MIN_STEP_DAMPING:g}" in text
    assert f"exact modal passages of moving forces take the {STEPS_PER_CUTOFF_PERIOD} samples a period only" in text
    assert f"--cars full on an irregular rail also {STEPS_PER_CUTOFF_PERIOD} steps a period of its shortest " \
           f"wavelength, {WAVELENGTH_BAND[0]:g} m, passed at the top speed" in text
    mantissas = set()
    for f in np.geomspace(1.0, 1000.0, 400):
        for zeta in (None, 0.005, 0.0125, 0.04):
            dt = dt_resolving(f, zeta)
            mantissas.add(round(dt / 10.0 ** math.floor(math.log10(dt) + 1e-9), 6))
    assert mantissas == {1.0, 2.0, 2.5, 4.0, 5.0}
    assert "rounded down to 1, 2, 2.5, 4 or 5 x 10^k s" in text


def test_quiet_help_names_what_it_silences(capsys, monkeypatch):
    """--quiet drops the progress bar, the axle tables' D lines (test_train_signature), the
    closing line and, in a check, the line of what its damping replaces (test_report_provenance)."""
    sweep = option_help("sweep", "--quiet", capsys, monkeypatch)
    check = option_help("check", "--quiet", capsys, monkeypatch)
    for text in (sweep, check):
        assert "no progress bar" in text and "axle table's D" in text and "no closing 'results in' line" in text
    assert "what the damping replaces" in check and "what the damping replaces" not in sweep


def test_cli_md_analysis_table_names_every_key_and_reads_as_a_bridge_file(tmp_path):
    """docs/cli.md's [analysis] example names every key ANALYSIS_KEYS accepts (and seeds), each
    as 'key = value'; with the comment marks removed it is a bridge file whose settings are
    every field of ANALYSIS_KEYS."""
    text = CLI_MD.read_text()
    start = text.index("[analysis]                # optional defaults")
    block = text[start:text.index("```", start)]
    lines = [m.group(1) for m in re.finditer(r"^(?:# )?(\w+ = \S.*?)\s+#", block, re.M)]
    named = [line.split(" = ")[0] for line in lines]
    assert sorted(named) == sorted([*ANALYSIS_KEYS, "seeds"])
    tomllib.loads("\n".join(lines))                # each value is TOML
    path = tmp_path / "b.toml"
    path.write_text('[bridge]\nkind = "beam"\nspans_m = [20.0]\nE_Pa = 3.5e10\nI_m4 = 1.9\nmu_kg_m = 15000.0\n'
                    "[analysis]\n" + "\n".join(lines) + "\n")
    source = read_bridge_file(path)
    assert set(source.settings) == set(ANALYSIS_KEYS.values())
    assert source.seeds == (0, 1, 2)

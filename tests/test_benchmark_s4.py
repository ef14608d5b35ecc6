"""Benchmark scene S4 (benchmarks/run.py S4): the HSLM-A sweep against OpenSeesPy, its JSON
contract and the agreement of the two codes.

Speed is shown by the benchmark, never asserted here beyond vtsi being the faster of the two.
"""
import json
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
RUN = ROOT / "benchmarks" / "run.py"

KEYS = {"passages", "vtsi_s", "passages_per_s", "peer_s_per_passage", "speedup", "max_acc", "max_acc_peer"}
CONTRACT_KEYS = {"scene", "steps", "vtsi_us_per_step", "peer", "peer_s", "peer_us_per_step", "max_rel_diff", "cases"}
ICE3_KEYS = {"passages", "vtsi_s", "passages_per_s", "max_acc", "contact_force_min", "contact_force_max"}


@pytest.fixture(scope="module")
def quick_result():
    pytest.importorskip("openseespy.opensees")
    proc = subprocess.run([sys.executable, str(RUN), "S4", "--json", "--quick"], capture_output=True, text=True,
                          cwd=ROOT, timeout=600)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)            # stdout holds the JSON object and nothing else


def test_s4_quick_json_keys(quick_result):
    r = quick_result
    assert KEYS | CONTRACT_KEYS <= set(r)
    assert r["scene"] == "S4" and r["peer"] == "openseespy" and r["quick"] is True
    assert r["passages"] == 10 and len(r["cases"]) == 4
    assert r["vtsi_s"] > 0 and r["peer_s_per_passage"] > 0 and r["passages_per_s"] > 0
    assert {"vtsi", "peer", "reference"} <= set(r["settings"])
    assert ICE3_KEYS <= set(r["ice3_full"]) and r["ice3_full"]["passages"] == 3
    assert r["ice3_full"]["contact_force_min"] < r["ice3_full"]["contact_force_max"]
    assert {"workers", "vtsi_s", "gain"} <= set(r["pool"])


def test_s4_quick_vtsi_and_opensees_agree(quick_result):
    r = quick_result
    assert r["max_acc"] > 0
    assert abs(r["max_acc_peer"] / r["max_acc"] - 1.0) <= 1e-6     # same FE model, same settings
    assert r["max_rel_diff"] <= 1e-6                                 # every passage of the subset
    assert len(r["peer_subset"]) == 2
    crit = r["critical"]
    assert any(c["train"] == crit["train"] and c["speed_kmh"] == crit["speed_kmh"] for c in r["peer_subset"])
    assert r["pool"]["same_envelope"]                                # the pool computes the same numbers


def test_s4_quick_settings_near_the_reference(quick_result):
    """vtsi's settings give the reference envelope maximum within the scene's tolerance."""
    r = quick_result
    assert abs(r["reference"]["settings_rel_err"]) <= r["settings"]["tolerance"]


def test_s4_quick_vtsi_is_faster(quick_result):
    assert quick_result["speedup"] > 1.0


def test_s4_modal_section(quick_result):
    """The exact modal passages: modes kept, their envelope against the 200 Hz modal reference
    within 0.5 %, and a positive rate."""
    modal = quick_result["modal"]
    assert modal["modes"] >= 2 and modal["reference_modes"] > modal["modes"]
    assert modal["max_acc_rel_err"] < 5e-3 and modal["passages_per_s"] > 0

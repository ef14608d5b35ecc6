"""An axle table named by another path when a sweep is resumed ('x.csv', then '../x.csv' from a
folder below): the design check records the governing cases' histories under the file's name,
the name its rows give (they were dropped: the rows' 'x.csv' is not the sweep's '../x.csv', and
the report lacked the governing histories). And a modal passage's kept history owns its columns
(it was a view of every node output's columns, which it kept alive)."""
import os
import re

import numpy as np
import pytest

from vtsi.errors import SweepError
from vtsi.passage import Output, PassageSettings
from vtsi.sweep import Sweep, beam_bridge
from vtsi.sweep_results import ResultsFileRefused, SweepResults, case_key
from vtsi.workflow import design_check

L, F1, MU = 20.0, 5.0, 15000.0
EI = MU * (2 * np.pi * F1 * (L / np.pi) ** 2) ** 2
FAST = PassageSettings(dt=5e-3, damping=0.0125)
AXLES = "position_m,load_kN\n0,170\n3.0,170\n14.0,170\n"


def bridge():
    return beam_bridge([L], EI, 1.0, MU, elements_per_span=4)


def test_the_check_of_a_resume_by_another_path_records_the_governing_histories(tmp_path, monkeypatch):
    (tmp_path / "x.csv").write_text(AXLES)
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path)
    Sweep(bridge(), ["x.csv"], "200,250", FAST).run("r.h5", workers=1, progress=False)
    monkeypatch.chdir(tmp_path / "sub")
    sweep = Sweep(bridge(), ["../x.csv"], "200,250", FAST)
    result, paths = design_check(sweep, "../r.h5", resume=True, workers=1, progress=False)
    governing = sorted({case_key(r.train, r.speed_kmh, r.seed) for r in result.rows if np.isfinite(r.speed_kmh)})
    assert governing == ["x.csv/250kmh/smooth"]
    results = SweepResults(tmp_path / "r.h5")
    assert results.trains == ["x.csv"] and results.histories() == governing
    recorded = results.history("x.csv", 250.0)
    assert recorded["attrs"]["train"] == "x.csv" and recorded["deck_acceleration"][1].shape[0] > 100
    assert "no time histories" not in open(paths["markdown"]).read()
    # record_histories takes the table by the file's name or by the sweep's, and stores the file's
    sweep.record_histories("../r.h5", [("x.csv", 200.0, -1), ("../x.csv", 250.0, -1)])
    assert SweepResults(tmp_path / "r.h5").histories() == ["x.csv/200kmh/smooth", "x.csv/250kmh/smooth"]
    with pytest.raises(SweepError, match=re.escape("record_histories: case ('y.csv', 200, -1): train 'y.csv' is not "
                                                   "in the sweep; its trains: ../x.csv")):
        sweep.record_histories("../r.h5", [("y.csv", 200, -1)])


def test_record_histories_refuses_a_missing_file_and_writes_nothing(tmp_path):
    """It added to a file it created: a results file of no case holding histories only."""
    sweep = Sweep(bridge(), ["HSLM-A1"], "200", FAST)
    with pytest.raises(ResultsFileRefused, match=re.escape(f"results file {tmp_path / 'none.h5'} does not exist: "
                                                           "record_histories adds to the file of a sweep that ran")):
        sweep.record_histories(tmp_path / "none.h5", [("HSLM-A1", 200.0, -1)])
    assert os.listdir(tmp_path) == []


def test_a_modal_history_owns_its_columns(tmp_path):
    """The kept midspan deflection (one column) was a view of the 6 columns of both node
    outputs, which it kept alive: 6 times its own bytes. It equals the same output run alone."""
    settings = PassageSettings(dt=2e-3, damping=0.0125, bridge="modal")
    kept = Output("deflection", "disp", "midspan", history=True)
    both = Sweep(bridge(), ["HSLM-A1"], "300", settings, outputs=[kept, Output("acceleration", "accel", "deck")])
    alone = Sweep(bridge(), ["HSLM-A1"], "300", settings, outputs=[kept])
    for sweep in (both, alone):
        sweep.prepare()
    time, history = both.runner.run("HSLM-A1", 300.0).histories["deflection"]
    assert history.shape == (len(time), 1)
    assert history.base is None or history.base.nbytes == history.nbytes
    np.testing.assert_array_equal(history, alone.runner.run("HSLM-A1", 300.0).histories["deflection"][1])

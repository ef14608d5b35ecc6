"""A bridge script that defines its own element type: the sweep's process pool receives it.

``vtsi sweep SCRIPT.py`` runs the script as ``__main__``; a class it defines would be pickled by
reference to vtsi's own ``__main__`` and fail to reach the workers. The loader gives the script's
classes and functions a module of their own (``vtsi.bridge_file._script_module``)."""
import os
import pickle
import subprocess
import sys

import h5py
import numpy as np

from vtsi.bridge_file import load_bridge


def test_the_scripts_classes_and_functions_pickle_by_a_module_of_their_own(tmp_path, own_element_script):
    path = tmp_path / "bridge.py"
    path.write_text(own_element_script("ScriptBeam", "scriptBeam"))
    bridge = load_bridge(str(path))
    etype = bridge.model.build().blocks[0][0]
    cls = etype if isinstance(etype, type) else type(etype)
    module = sys.modules[cls.__module__]
    assert cls.__name__ == "ScriptBeam" and cls.__module__.startswith("vtsi_bridge_script_")
    assert module.__name__ == cls.__module__ and module.deck_mass.__module__ == cls.__module__
    copy = pickle.loads(pickle.dumps(bridge))
    assert np.array_equal(copy.model.build().K.toarray(), bridge.model.build().K.toarray())


def test_a_sweep_of_a_script_with_its_own_element_type_runs_in_the_pool(tmp_path, own_element_script):
    """`vtsi sweep` with two workers, as it runs by default, in a process of its own: the same
    envelopes as in one process."""
    path = tmp_path / "bridge.py"
    path.write_text(own_element_script("ScriptBeam", "scriptBeam"))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    maxima = {}
    for workers in ("1", "2"):
        out = tmp_path / f"workers{workers}.h5"
        run = subprocess.run([sys.executable, "-m", "vtsi", "sweep", str(path), "--trains", "HSLM-A1,HSLM-A2",
                              "--speeds", "280,300", "--workers", workers, "--quiet", "--out", str(out)],
                             capture_output=True, text=True, env=env, timeout=600)
        assert run.returncode == 0, run.stderr[-2000:]
        with h5py.File(out, "r") as f:
            maxima[workers] = {name: f["envelopes"][name][...] for name in f["envelopes"]}
    assert maxima["1"].keys() == maxima["2"].keys() and maxima["1"]
    for name, values in maxima["1"].items():
        assert np.array_equal(maxima["2"][name], values, equal_nan=True), name

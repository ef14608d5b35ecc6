"""A bridge script that defines its own element type: the sweep's process pool receives it.

``vtsi sweep SCRIPT.py`` runs the script as ``__main__``; a class it defines would be pickled by
reference to vtsi's own ``__main__`` and fail to reach the workers. The loader gives the script's
classes and functions a module of their own (``vtsi.bridge_file._script_module``)."""
import os
import pickle
import subprocess
import sys
import textwrap

import h5py
import numpy as np

from vtsi.bridge_file import load_bridge

SCRIPT = """
import vtsi.opensees as ops
from vtsi.elements import register
from vtsi.elements.beam_column import ElasticBeamColumn2d


@register
class ScriptBeam(ElasticBeamColumn2d):
    '''The elastic beam under a name of the script's: element scriptBeam tag i j A E I -mass rho.'''
    name = "scriptBeam"
    command_args = ("A", "E", "I")
    command_options = {"-mass": "rho"}


def deck_mass(span):
    return 15000.0


ops.model("basic", "-ndm", 2, "-ndf", 3)
for i in range(11):
    ops.node(i + 1, 2.0 * i, 0.0)
ops.fix(1, 1, 1, 0)
ops.fix(11, 0, 1, 0)
ops.geomTransf("Linear", 1)
for i in range(10):
    if ELEMENT == "scriptBeam":
        ops.element(ELEMENT, i + 1, i + 1, i + 2, 5.0, 3.5e10, 1.9, "-mass", deck_mass(20.0))
    else:
        ops.element(ELEMENT, i + 1, i + 1, i + 2, 5.0, 3.5e10, 1.9, 1, "-mass", deck_mass(20.0))
ops.track(1, "-eleRange", 1, 10)
"""


def _script(tmp_path, element):
    path = tmp_path / f"{element}.py"
    path.write_text(textwrap.dedent(SCRIPT).replace("ELEMENT", repr(element)))
    return path


def test_the_scripts_classes_and_functions_pickle_by_a_module_of_their_own(tmp_path):
    bridge = load_bridge(str(_script(tmp_path, "scriptBeam")))
    etype = bridge.model.build().blocks[0][0]
    cls = etype if isinstance(etype, type) else type(etype)
    assert cls.__name__ == "ScriptBeam"
    module = sys.modules[cls.__module__]
    assert cls.__module__.startswith("vtsi_bridge_script_") and module.deck_mass.__module__ == cls.__module__
    copy = pickle.loads(pickle.dumps(bridge))
    K = bridge.model.build().K.toarray()
    assert np.array_equal(copy.model.build().K.toarray(), K)


def test_a_sweep_of_a_script_with_its_own_element_type_runs_in_the_pool(tmp_path):
    """Two workers, as `vtsi sweep` runs by default: the same envelopes as the built-in element."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    maxima = {}
    for element in ("scriptBeam", "elasticBeamColumn"):
        out = tmp_path / f"{element}.h5"
        run = subprocess.run([sys.executable, "-m", "vtsi", "sweep", str(_script(tmp_path, element)),
                              "--trains", "HSLM-A1,HSLM-A2", "--speeds", "280,300", "--workers", "2",
                              "--quiet", "--out", str(out)], capture_output=True, text=True, env=env, timeout=600)
        assert run.returncode == 0, run.stderr[-2000:]
        with h5py.File(out, "r") as f:
            maxima[element] = {name: f["envelopes"][name][...] for name in f["envelopes"]}
    assert maxima["scriptBeam"].keys() == maxima["elasticBeamColumn"].keys()
    for name, values in maxima["elasticBeamColumn"].items():
        assert np.array_equal(maxima["scriptBeam"][name], values, equal_nan=True), name

"""The LCP contact path allocates no memory per step (vtsi/lcp.py ``_solve_free``, run several
times a step by ``solve_lcp``, writes into the workspace only).

Counted with numba's runtime statistics (``numba.core.runtime.rtsys.get_allocation_stats()``,
enabled by the environment variable ``NUMBA_NRT_STATS=1`` before numba starts, hence the
subprocess): the compiled allocations of one ``CoupledAnalysis(contact='lcp').run`` over the same
passage at Δt and Δt/2, each run one chunk. What is allocated per run or per chunk is the same in
both; anything allocated per step would double. Before this was fixed, ``_solve_free`` allocated
two arrays per call (about 1.4 allocations per step here, 2 per step in an ICE3 passage).
"""
import json
import os
import subprocess
import sys

import pytest

SCRIPT = r"""
import json
import numpy as np
from numba.core.runtime import rtsys
import vtsi
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.integrators import HHT
from vtsi.models import Irregularity, Train, four_dof_car
from vtsi.models.bridges import simply_supported_beam
from vtsi.track import Track
from vtsi.train import TrainSubdomain


def passage(dt, t_end):
    # S3's 4-dof car (docs/scenes.md) at 300 km/h over a 30 m span with a 10 mm, 3 m cos^4 bump
    # at x = 25 m: the front wheel lifts off and lands again, so the LCP's free set changes
    model = vtsi.Model()
    bridge = simply_supported_beam(model, 30.0, 6, 3.5e10, 7.0, 30000.0)
    car = four_dof_car(47800.0, 1957888.0, 7100.0, 1.4e6, 8.0e4, 17.375)
    x = np.linspace(-10.0, 100.0, 1101)
    bump = np.where(np.abs(x - 25.0) < 1.5, 0.01 * np.cos(np.pi * (x - 25.0) / 3.0) ** 4, 0.0)
    con = MovingLoadConstraint(Track(model, bridge.elements), TrainSubdomain(Train([car], [0.0], 300 / 3.6), 20.0),
                               irregularity=Irregularity(x, bump))
    n = int(round(t_end / dt))
    analysis = CoupledAnalysis(model, con, HHT(0.9), dt=dt, contact="lcp", chunk_steps=n)
    analysis.static()
    before = rtsys.get_allocation_stats().alloc
    analysis.run(n)
    allocations = rtsys.get_allocation_stats().alloc - before
    kinds = [event.kind for event in analysis.contact_events()]
    return {"steps": n, "allocations": allocations, "events": kinds}


passage(1e-3, 0.05)          # compiled (or loaded from the cache) before counting
print(json.dumps([passage(dt, 0.5) for dt in (1e-3, 5e-4)]))
"""


@pytest.mark.skipif(os.environ.get("NUMBA_DISABLE_JIT") == "1", reason="no compiled code: nothing to count")
def test_lcp_passage_allocations_do_not_grow_with_the_steps():
    env = dict(os.environ, NUMBA_NRT_STATS="1")
    proc = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    coarse, fine = json.loads(proc.stdout.strip().splitlines()[-1])
    assert (coarse["steps"], fine["steps"]) == (500, 1000)
    # a lift-off and a landing in both runs: the LCP's active set changed, not only its warm start
    for run in (coarse, fine):
        assert {"lift-off", "landing"} <= set(run["events"]), run
    assert fine["allocations"] == coarse["allocations"], (coarse, fine)

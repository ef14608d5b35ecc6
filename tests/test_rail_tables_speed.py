"""The rail tables of a run (``r_table``, ``rate_table``: the rail's position [m] and rate [m/s]
under the contact wheels at each stage time, less the deck's self-weight sag) are evaluated for
all wheels and stage times of a block in one compiled pass, from a smoothed profile tabulated once
per node in a run (SmoothedProfile.grow). They equal, to the bit, the tables evaluated stage by
stage from a profile tabulated afresh over each block's range: B-spline and Hermite rows, an
irregular and a smooth rail, with and without the self-weight sag.
"""
import numpy as np
import pytest

import vtsi
from vtsi.constraint import TABLE_MARGIN, MovingLoadConstraint, SmoothedProfile
from vtsi.coupled import CoupledAnalysis, _CoupledPlan
from vtsi.models import Irregularity, Train, four_dof_car
from vtsi.models.bridges import simply_supported_beam
from vtsi.track import Track
from vtsi.train import TrainSubdomain

DT, SPEED, CHUNK = 1e-3, 40.0, 300     # [s], [m/s], chunk_steps


def wavy_rail():
    """A sampled rail of 3 m and 0.7 m waves of 2 mm and 0.5 mm [m]."""
    x = np.linspace(-40.0, 80.0, 4801)
    return Irregularity(x, 2e-3 * np.sin(2.0 * np.pi * x / 3.0) + 5e-4 * np.cos(2.0 * np.pi * x / 0.7))


def analysis(interpolation, rail, self_weight):
    """Two four-dof cars entering a 20 m span from the ground (Bathe: two stages a step)."""
    model = vtsi.Model()
    bridge = simply_supported_beam(model, 20.0, 10, 3.0e10, 0.6, 1.2e4)
    car = four_dof_car(3.0e4, 1.5e6, 1.5e3, 1.0e6, 2.0e4, 8.0)
    sub = TrainSubdomain(Train([car, car], [0.0, 12.0], SPEED), -1.0)
    con = MovingLoadConstraint(Track(model, bridge.elements), sub, rail, interpolation)
    out = CoupledAnalysis(model, con, "Bathe", DT, contact="lcp", chunk_steps=CHUNK, bridge_self_weight=self_weight)
    out.static()
    return out


def stage_by_stage(a, starts, nu):
    """The tables as evaluated before: per stage, from a profile tabulated over the block's range."""
    con, knot = a.constraint, a.constraint.knot(a.dt)
    stages = []
    for th in a.stage_theta:
        t = starts + th * a.dt
        x = con.positions(t)
        if con.irregularity is None:
            r = np.zeros_like(x)
        elif knot == 0.0:
            r = con.irregularity(x, nu=nu) * SPEED ** nu
        else:
            profile = SmoothedProfile(con.irregularity, knot, con.track.x_begin,
                                      x.min() - TABLE_MARGIN * knot, x.max() + TABLE_MARGIN * knot)
            r = profile(x, nu) * SPEED ** nu
        stages.append(r - a._rail_sag(t, nu))
    return np.stack(stages, axis=1)


@pytest.mark.parametrize("interpolation", ["bspline", "hermite"])
@pytest.mark.parametrize("rail", ["wavy", "smooth"])
@pytest.mark.parametrize("self_weight", [False, True])
def test_the_tables_of_a_run_are_the_stage_by_stage_tables(monkeypatch, interpolation, rail, self_weight):
    a = analysis(interpolation, wavy_rail() if rail == "wavy" else None, self_weight)
    blocks = []
    rows_of = _CoupledPlan.rows_of

    def kept(plan, t_c, i, n, chunk_steps):
        out = rows_of(plan, t_c, i, n, chunk_steps)
        blocks.append((t_c, plan.block[1], plan.block[3].copy(), plan.block[4].copy()))
        return out

    monkeypatch.setattr(_CoupledPlan, "rows_of", kept)
    a.run(700)                  # three chunks: blocks over 2 m, 12 m and 12 m of travel
    assert len(blocks) >= 3
    for t_c, i, r_table, rate_table in blocks:
        starts = t_c + a.dt * np.arange(i, i + len(r_table), dtype=float)
        assert r_table.flags.c_contiguous and rate_table.flags.c_contiguous
        assert np.array_equal(r_table, stage_by_stage(a, starts, 0))
        assert np.array_equal(rate_table, stage_by_stage(a, starts, 1))
    if rail == "wavy" or self_weight:
        assert np.abs(blocks[-1][2]).max() > 1e-4       # something under the wheels
    if rail == "wavy" and interpolation == "bspline":
        assert a.constraint._smoothed.x_hi - a.constraint._smoothed.x_lo > 25.0     # one table, grown


def test_a_grown_table_is_the_table_over_the_whole_range():
    """Grown below and above its range, a table holds the node values and coefficients of one
    built over the whole range at once, to the bit."""
    rail, knot = wavy_rail(), 2.0 * SPEED * DT
    grown = SmoothedProfile(rail, knot, -1.0, 4.0, 6.0)
    grown.grow(rail, 5.0, 9.0)
    grown.grow(rail, -3.0, 2.0)
    whole = SmoothedProfile(rail, knot, -1.0, -3.0, 9.0)
    assert (grown.first, grown.last) == (whole.first, whole.last)
    assert np.array_equal(grown.values, whole.values) and np.array_equal(grown.coef, whole.coef)
    at = np.linspace(-3.0, 9.0, 1001)
    for nu in (0, 1, 2):
        assert np.array_equal(grown(at, nu), whole(at, nu))
        assert np.abs(whole(at, nu)).max() > 1e-4

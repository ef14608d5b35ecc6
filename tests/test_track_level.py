"""The track's level (vtsi.track.LEVEL_TOLERANCE): a track element's ends may lie 1e-9 of the
model's size apart in y (its length, or its largest coordinate), where coordinate round-off is;
a real gradient is refused saying what to do, with what leaving it out costs: a gradient g
changes the vertical dynamics by about g². Before, the tolerance was 1e-9 of the element's
length: a model with y = 1e-9 x (coordinate noise) was refused, 'track: element 3 is not
horizontal (y from 5e-09 to 7.5e-09)', and a gradient's refusal gave no hint."""
import numpy as np
import pytest

import vtsi.opensees as ops
from vtsi.analysis import eigen
from vtsi.errors import BridgeModelError
from vtsi.model import Model
from vtsi.track import LEVEL_TOLERANCE, Track


def _chain(y, x0=0.0, n=32, dx=2.5):
    """A chain of ``n`` beam elements along x from ``x0``, node i at (x_i, y(x_i - x0))."""
    model = Model()
    for i in range(n + 1):
        model.node(i + 1, x0 + dx * i, y(dx * i))
    model.fix(1, 1, 1, 0)
    model.fix(n + 1, 0, 1, 0)
    for i in range(n):
        model.element("elasticBeamColumn", i + 1, (i + 1, i + 2), A=7.2, E=3.6e10, I=5.8)
    return model, list(range(1, n + 1))


@pytest.mark.parametrize("y, x0", [(lambda x: 1e-9 * x, 0.0),                     # the probe's 'slope_noise'
                                   (lambda x: 123.456 + 1e-12 * x * x, 0.0),       # a level far from y = 0
                                   (lambda x: 1e-9 * x, 1.0e5)],                   # at a chainage of 100 km
                         ids=["noise", "high level", "far from the origin"])
def test_coordinate_noise_passes(y, x0):
    """Rises of 1e-9 of the element's length, far below 1e-9 of the model's size (the 80 m
    track, or its coordinates up to 1e5 m): the track is built, its elements as given."""
    model, tags = _chain(y, x0)
    track = Track(model, tags)
    assert track.x_begin == x0 and track.x_end == pytest.approx(x0 + 80.0, rel=1e-15)
    np.testing.assert_allclose(track.length, 2.5, rtol=1e-9)


def test_a_rise_above_the_tolerance_is_refused():
    """1e-9 of the 80 m track is 8e-8 m: an element rising 1.2 times that is refused."""
    model, tags = _chain(lambda x: 1.2 * LEVEL_TOLERANCE * 80.0 * (x >= 40.0))
    with pytest.raises(BridgeModelError, match=r"^track: element 16 is not horizontal \(y from 0 to 9\.6e-08 m over "
                                               r"x = 37\.5 to 40 m, a gradient of 3\.84e-06 %\)"):
        Track(model, tags)


@pytest.mark.parametrize("g", [1e-3, 0.025])
def test_a_gradient_is_refused_saying_what_leaving_it_out_costs(g):
    """A gradient of 0.1 % (2.5 mm over an element of 2.5 m) or 2.5 %: the refusal names the
    gradient, says to give the nodes one level and how much that changes: about g² (1e-6 at
    0.1 %, 6.25e-4 at 2.5 %)."""
    model, tags = _chain(lambda x: g * x)
    with pytest.raises(BridgeModelError) as info:
        Track(model, tags)
    text = str(info.value)
    assert text.startswith(f"track: element 1 is not horizontal (y from 0 to {2.5 * g:g} m over x = 0 to 2.5 m, "
                           f"a gradient of {100 * g:g} %); vtsi's track is level: give its nodes one level y")
    assert f"by about g², here {g * g:.1e}" in text and "\n" not in text


def test_the_gradients_effect_on_the_frequencies_is_about_its_square():
    """What the refusal states, computed: a 30 m simply supported deck (pin and horizontal
    rollers, 24 elements) laid at a gradient g has its first two vertical frequencies lowered
    by g² within 10 % (the refusal's numbers: -1.0e-6 at 0.1 %, -6.3e-4 at 2.5 %); a gradient
    of 1e-6 changes them by less than 1e-11."""
    def frequencies(g):
        ops.wipe()
        ops.model("basic", "-ndm", 2, "-ndf", 3)
        for i in range(25):
            ops.node(i + 1, 1.25 * i, g * 1.25 * i)
        ops.fix(1, 1, 1, 0)
        ops.fix(25, 0, 1, 0)
        ops.geomTransf("Linear", 1)
        for i in range(24):
            ops.element("elasticBeamColumn", i + 1, i + 1, i + 2, 7.2, 36e9, 5.8, 1, "-mass", 24000.0)
        return np.sqrt(eigen(ops.session.domain, 2)[0])

    level = frequencies(0.0)
    for g in (1e-3, 0.025):
        change = frequencies(g) / level - 1.0
        np.testing.assert_allclose(change, -g * g, rtol=0.1)
    assert round(float(frequencies(1e-3)[0] / level[0] - 1.0), 7) == -1.0e-6
    assert round(float(frequencies(0.025)[0] / level[0] - 1.0), 5) == -6.3e-4
    assert np.max(np.abs(frequencies(1e-6) / level - 1.0)) < 1e-11

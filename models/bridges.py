"""Ready-made bridge models (2-D Euler-Bernoulli beams on the x axis, y up; SI units).

Each builder adds nodes and ``elasticBeamColumn`` elements to a :class:`vtsi.Model` and returns
a :class:`BeamBridge` record with the tags a scene needs (track elements, midspan node...).
"""
from dataclasses import dataclass

import numpy as np

from vtsi.damping import rayleigh_damping
from vtsi.errors import ModelError, as_number, as_positive, is_count

MAX_ELEMENTS_PER_SPAN = 1000    # a beam's elements per span: finer than any deck needs (dofs, time)


@dataclass
class BeamBridge:
    """Tags of a beam bridge: ``nodes`` and ``elements`` in x order, ``supports`` (node tags),
    ``midspan_nodes`` (one per span), ``span_lengths`` [m]."""

    nodes: list
    elements: list
    supports: list
    midspan_nodes: list
    span_lengths: list

    @property
    def length(self):
        return float(sum(self.span_lengths))


def continuous_beam(model, spans, elements_per_span, E, I, mu, A=1.0, consistent_mass=True, x0=0.0,
                    first_node=1, first_element=1, damping=None, damping_hz=None):
    """A continuous beam over ``len(spans)`` spans [m] on pin (first support) and rollers.

    Parameters
    ----------
    model : vtsi.Model
    spans : sequence of span lengths [m].
    elements_per_span : int, even (so that a node sits at each midspan), at most MAX_ELEMENTS_PER_SPAN.
    E [Pa], I [m⁴], mu [kg/m], A [m²] (axial only).
    consistent_mass : True for the consistent mass matrix of each ``elasticBeamColumn`` (cubic
        Hermite bending, linear axial; ``cmass`` 1), False for the lumped one (μL/2 on ux and uy
        of each node, no rotary inertia; ``cmass`` 0).
    x0 : x of the first support [m]; the deck runs from ``x0`` to ``x0 + sum(spans)`` along
        +x at y = 0.
    first_node, first_element : tags of the first node and element; the nodes
        (``len(spans) * elements_per_span + 1``) and elements (one fewer) are numbered
        consecutively from them in x order, and must not exist in ``model`` yet (ModelError).
    damping : None (undamped) or a damping ratio ζ [-] (e.g. from
        :func:`vtsi.codes.en1991_2.damping_lower_bound`), given to the model as Rayleigh damping
        through ``damping_hz`` = (f_a, f_b) [Hz], by default the first vertical frequency and the
        EN 1990 A2 cut-off (:func:`vtsi.damping.rayleigh_damping`: what it does to the other modes).
    """
    if isinstance(spans, (str, bytes)) or not np.iterable(spans):
        raise ModelError(f"continuous_beam: spans must be a sequence of span lengths [m], got {spans!r}")
    spans = [as_number(s, "continuous_beam", "a span length [m]") for s in spans]
    if not spans or any(not (0 < s < np.inf) for s in spans):
        raise ModelError(f"continuous_beam: spans must be positive and finite, got {spans}")
    if not (is_count(elements_per_span, 2) and elements_per_span % 2 == 0
            and elements_per_span <= MAX_ELEMENTS_PER_SPAN):
        raise ModelError(f"continuous_beam: elements_per_span must be an even integer from 2 to "
                         f"{MAX_ELEMENTS_PER_SPAN}, got {elements_per_span!r}")
    n = int(elements_per_span)
    x0 = as_number(x0, "continuous_beam", "x0 [m]")
    if not np.isfinite(x0):
        raise ModelError(f"continuous_beam: x0 must be finite [m], got {x0}")
    xs = [x0]
    for s in spans:
        xs.extend(xs[-1] + s * np.arange(1, n + 1) / n)
    nodes = list(range(first_node, first_node + len(xs)))
    for tag, x in zip(nodes, xs):
        model.node(tag, float(x), 0.0)
    supports = nodes[::n]
    model.fix(supports[0], 1, 1, 0)
    for tag in supports[1:]:
        model.fix(tag, 0, 1, 0)
    elements = list(range(first_element, first_element + len(nodes) - 1))
    for e, (i, j) in zip(elements, zip(nodes[:-1], nodes[1:])):
        model.element("elasticBeamColumn", e, (i, j), A=A, E=E, I=I, rho=mu, cmass=1 if consistent_mass else 0)
    midspan = [nodes[k * n + n // 2] for k in range(len(spans))]
    if damping is not None:
        rayleigh_damping(model, damping, damping_hz)
    return BeamBridge(nodes, elements, supports, midspan, spans)


def simply_supported_beam(model, L, n_elements, E, I, mu, **kwargs):
    """One simply supported span (see :func:`continuous_beam`)."""
    return continuous_beam(model, [L], n_elements, E, I, mu, **kwargs)


def first_frequency(L, E, I, mu):
    """f₁ = (π/L)² √(EI/μ) / 2π [Hz] of a simply supported Euler-Bernoulli beam (L [m], E [Pa],
    I [m⁴], μ [kg/m] > 0 and finite, else a ModelError naming the one at fault)."""
    L, E, I, mu = (as_positive(value, "first_frequency", name) for name, value in zip("L E I mu".split(), (L, E, I, mu)))
    return (np.pi / L) ** 2 * np.sqrt(E * I / mu) / (2.0 * np.pi)

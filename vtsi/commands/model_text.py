"""``printModel``'s readable text of a model: nodes, elements, patterns, damping and time."""
import numpy as np

from vtsi.timeseries import Constant, Linear, Path, Pulse, Rectangular, Triangle, Trig


def _numbers(values, fmt="{:.6g}"):
    return " ".join(fmt.format(float(v)) for v in np.ravel(values))


def _periodic_text(kind, s, width=""):
    return (f"{kind} Series\n\tFactor: {s.factor:g}\n\ttStart: {s.t_start:g}\n\ttFinish: {s.t_end:g}\n"
            f"\tPeriod: {s.period:g}\n{width}\tPhase Shift: {s.shift:g}\n\tZero Shift: {s.zero_shift:g}")


OPENSEES_SERIES_TEXT = {
    Constant: lambda s: f"Constant Series: factor: {s.factor:g}",
    Linear: lambda s: f"Linear Series: constant factor: {s.factor:g}",
    Rectangular: lambda s: f"Linear Series: constant factor: {s.factor:g}  tStart: {s.t_start:g}  tFinish: {s.t_end:g}",
    Trig: lambda s: _periodic_text("Trig", s),
    Triangle: lambda s: _periodic_text("Triangle", s),
    Pulse: lambda s: _periodic_text("Pulse", s, f"\tPulse Width: {s.width:g}\n"),
    Path: lambda s: "" if s.dt is not None else f"Path Time Series: constant factor: {s.factor:g}",
}
"""What OpenSees's ``printModel`` prints of a series of each type, a function of the series
(``<Type>Series::Print`` at flag 0, numbers as C++'s stream writes them: ``%g``): a Rectangular
series calls itself ``Linear Series``, and a Path of ``-dt`` (``PathSeries``) prints nothing, as
OpenSees's; a Path of ``-time`` (``PathTimeSeries``) its factor."""


def model_text(model, state=None, nodes=None, elements=None):
    """The text of ``model`` (a :class:`vtsi.Model`), with the committed ``state`` (or None);
    ``nodes``/``elements``: only those tags (None: all when neither is given, none otherwise)."""
    everything = nodes is None and elements is None
    nodes = sorted(model.nodes) if everything else (nodes or [])
    elements = model.element_tags() if everything else (elements or [])
    lines = []
    if everything:
        n_el = len(model.element_tags())
        time = f", time {state.time:.6g} s" if state is not None else ""
        lines.append(f"Model: 2-D, {model.ndf} dofs per node, {len(model.nodes)} nodes, {n_el} elements, "
                     f"{len(model.patterns)} load patterns{time}")
    asm = model.build() if model.nodes else None
    if nodes:
        lines.append("Nodes (x y; fixed dofs 1 = fixed; nodal mass; committed displacements)")
        for tag in nodes:
            x, y = model.nodes[tag]
            fix = model.fixities.get(tag, np.zeros(model.ndf, dtype=int))
            mass = model.nodal_mass.get(tag, np.zeros(model.ndf))
            line = f"  node {tag}: x {x:.6g} y {y:.6g}  fix {_numbers(fix, '{:.0f}')}  mass {_numbers(mass)}"
            if state is not None:
                i = asm.node_index[tag] * asm.ndf
                line += f"  disp {_numbers(state.u[i: i + asm.ndf])}"
            lines.append(line)
    if elements:
        lines.append("Elements (type, nodes, parameters)")
        for tag in elements:
            etype = model._element_owner[tag]
            k = etype.tags.index(tag)
            params = ", ".join(f"{name} {value:.6g}" for name, value in zip(etype.param_names, etype.params[k]))
            lines.append(f"  element {tag}: {etype.name}, nodes {' '.join(map(str, etype.nodes[k]))}, {params}")
    if everything:
        if model.patterns:
            lines.append("Load patterns (series, factor, nodal loads; below, the series as OpenSees prints it)")
        for tag, p in model.patterns.items():
            s = p.series
            series = f"{type(s).__name__} {s.tag if s.tag is not None else '(inline)'}"
            frozen = f", constant since t = {p.constant_time:.6g} s" if p.constant_time is not None else ""
            kind = f"ground acceleration along dof {p.ground_direction}" if p.ground_direction else \
                "; ".join(f"node {n}: {_numbers(v)}" for n, v in p.nodal.items()) or "no loads"
            lines.append(f"  pattern {tag}: series {series}, factor {p.factor:.6g}{frozen}, {kind}")
            if p.ground_direction is None:      # (OpenSees prints no series of a UniformExcitation)
                text = OPENSEES_SERIES_TEXT.get(type(s), lambda _: "")(s)
                lines += [f"    {line}" for line in text.splitlines()]
        alpha_m, beta_k = model.rayleigh_factors
        lines.append(f"Rayleigh damping: alphaM {alpha_m:.6g}, betaK {beta_k:.6g}")
    return "\n".join(lines)

"""OpenSees's layouts of element responses: how the columns OpenSees returns or records for an
element response are built from vtsi's (``eleResponse``, ``eleForce``, ``recorder Element``)."""
import numpy as np

from vtsi.errors import CommandError

ELEMENT_RESPONSE_ALIASES = {
    "forces": "force", "globalForces": "globalForce", "localForces": "localForce",
    "basicForces": "basicForce", "deformations": "deformation", "basicDeformations": "basicDeformation",
    "axialForces": "axialForce",
}


def element_response_word(command, words, answered):
    """The response name of ``words``, what follows the elements in ``eleResponse`` or ``recorder
    Element``: one name; several (OpenSees's ``section 1 force``, ``material 1 stress``: a response
    of a part of the element) raise a CommandError naming them, ``command`` and the names the
    elements answer, ``answered()`` (called only then: :func:`accepted_responses`)."""
    if len(words) == 1 and isinstance(words[0], str):
        return words[0]
    names = answered()
    raise CommandError(f"{command}: response {' '.join(map(str, words))!r} is not supported: vtsi's elements are "
                       "elastic, with no sections or materials to query" + (f"; supported: {', '.join(names)}"
                                                                            if names else ""))


def opensees_layout(etype, kind, ndf, materials=None):
    """How to build OpenSees's columns of an element response from vtsi's, or None when they
    agree: ``(source kind, [(index or -1, coefficient on the value, coefficient on its rate)],
    uses rates)``. A truss's ``force``/``localForce`` spans every dof of its nodes (rotations
    read 0); a zeroLength's basic forces and deformations come one per material, in ``-dir``
    order (a material's force: ``E δ + eta δ̇``), its ``basicStiffness`` the n×n ``diag(E)`` of
    its n materials row by row (each material's E, its share of its direction's spring); a
    beam's ``basicForce`` (N, M1, M2) comes from its ``localForce``. A registered type's own
    ``command_layouts`` come first. ``materials``: a zeroLength's ``[(dir, E, eta)]`` as its
    command gave them."""
    per_node = len(etype.node_dofs)
    if kind in etype.command_layouts:
        return etype.command_layouts[kind]
    if etype.name == "elasticBeamColumn" and kind == "basicForce":   # (N, M1, M2) from the end forces
        return ("localForce", [(3, 1.0, 0.0), (2, 1.0, 0.0), (5, 1.0, 0.0)], False)
    if etype.name == "zeroLength" and materials is not None:
        if kind in ("basicForce", "localForce"):
            return ("deformation", [(d - 1, E, eta) for d, E, eta in materials], True)
        if kind in ("deformation", "basicDeformation"):
            return ("deformation", [(d - 1, 1.0, 0.0) for d, _E, _eta in materials], False)
        if kind == "basicStiffness":    # diagonal entries of the spring diag(kx, ky, krz) (9 values)
            spring = {d: sum(E for dd, E, _ in materials if dd == d) for d, _E, _eta in materials}
            return ("basicStiffness", [(4 * (d - 1), E / spring[d], 0.0) if i == j and spring[d] != 0.0
                                       else (-1, 0.0, 0.0)
                                       for i, (d, E, _eta) in enumerate(materials) for j in range(len(materials))],
                    False)
    if kind in ("force", "globalForce", "localForce") and per_node < ndf:
        columns = [(-1, 0.0, 0.0)] * (etype.n_nodes * ndf)
        for n in range(etype.n_nodes):
            for k, d in enumerate(etype.node_dofs):
                columns[n * ndf + d] = (n * per_node + k, 1.0, 0.0)
        return (kind, columns, False)
    return None


def accepted_responses(etype, ndf, materials=None):
    """Every response name the command layer answers for an element of ``etype`` (its own
    kinds, the OpenSees layouts built from them and their plural aliases), in a stable order."""
    names = list(etype.response_kinds) + list(etype.command_layouts)
    names += ["force", "globalForce", "localForce", "basicForce", "deformation", "basicDeformation"]
    names += list(ELEMENT_RESPONSE_ALIASES)
    out = []
    for name in dict.fromkeys(names):
        kind = ELEMENT_RESPONSE_ALIASES.get(name, name)
        layout = opensees_layout(etype, kind, ndf, materials)
        if (layout[0] if layout is not None else kind) in etype.response_kinds:
            out.append(name)
    return out


def apply_layout(layout, values, rates=None):
    """Columns ``(n, len(columns))`` of a :func:`opensees_layout` from ``values (n, width)`` (and
    their rates, the same response evaluated on velocities)."""
    _source, columns, _uses_rates = layout
    out = np.zeros((values.shape[0], len(columns)))
    for j, (src, cu, cv) in enumerate(columns):
        if src >= 0:
            out[:, j] = cu * values[:, src] + (cv * rates[:, src] if cv else 0.0)
    return out

"""OpenSees's layouts of element responses: how the columns OpenSees returns or records for an
element response are built from vtsi's (``eleResponse``, ``eleForce``, ``recorder Element``)."""
import numpy as np

from vtsi.errors import CommandError

TYPE_RESPONSE_ALIASES = {
    "elasticBeamColumn": {"xlocal": "xaxis", "ylocal": "yaxis", "zlocal": "zaxis", "deformatons": "basicDeformation"},
    "ElasticTimoshenkoBeam": {"xlocal": "xaxis", "ylocal": "yaxis", "zlocal": "zaxis"},
    "truss": {"defo": "deformation", "basicDefo": "basicDeformation"},
    "zeroLength": {"defo": "deformation", "globalforces": "force"},
}
"""The other names OpenSees's element of each type gives a response vtsi computes (its
``setResponse``, and for the beams their ``CrdTransf::setResponse``, OpenSees 3.7.1; measured on
OpenSeesPy 3.7.1, tests/test_command_aliases.py): a beam's ``xlocal`` is its ``xaxis``,
``deformatons`` (sic) its ``basicDeformation``; a zeroLength's ``xlocal`` is no response. Each
type answers only its own."""

PLURAL_ALIASES = {
    "forces": "force", "globalForces": "globalForce", "localForces": "localForce",
    "basicForces": "basicForce", "deformations": "deformation", "basicDeformations": "basicDeformation",
    "axialForces": "axialForce",
}
"""The plural of a response, which every type answers (where OpenSees's does not, it answers the
singular: docs/commands.md)."""

ELEMENT_RESPONSE_ALIASES = {**PLURAL_ALIASES, **{alias: kind for aliases in TYPE_RESPONSE_ALIASES.values()
                                                 for alias, kind in aliases.items()}}
"""The response each alias names: :data:`PLURAL_ALIASES` and :data:`TYPE_RESPONSE_ALIASES` (an
alias names one response whatever the type; which types answer it: :func:`accepted_responses`)."""


OPENSEES_ONLY_RESPONSES = {
    "elasticBeamColumn": {"RayleighForces": 1, "rayleighForces": 1, "offsets": 1, "rigidOffsets": 1},
    "ElasticTimoshenkoBeam": {"offsets": 1, "rigidOffsets": 1},
    "truss": {"energy": 1, "material": 2, "-material": 2},
    "zeroLength": {"rayleighForces": 1, "dampingForces": 1, "defoANDforce": 1, "deformationANDforces": 1,
                   "deformationsANDforces": 1, "materials": 1, "directions": 1, "material": 3},
}
"""The responses OpenSees answers with values for an element of vtsi's types and vtsi does not:
per type, the response's first word and the fewest words OpenSees answers it with (a truss's
``material stress`` or ``material 1 stress`` and a zeroLength's ``material 1 stress`` are
responses of its material; a beam's ``offsets``, six zeros, those of its ``geomTransf``). Read
in the types' ``setResponse`` (OpenSees 3.7.1) and measured on OpenSeesPy 3.7.1
(tests/test_command_cm.py, tests/test_command_aliases.py); any other response an element lacks,
OpenSees answers with nothing."""

PART_WORDS = ("section", "material", "-material")
"""The first words by which OpenSees's elements name a response of one of their parts
(``section 1 force``, ``material 1 stress``)."""


def element_answers(command, tag, etype, words, valid):
    """Whether element ``tag`` of ``etype``, which answers the names ``valid``
    (:func:`accepted_responses`), answers the response ``words`` (the words after the element
    in ``eleResponse`` or ``recorder Element``: one name, or several for a response of a part
    of it, ``section 1 force``). False when OpenSees's element has no such response either:
    OpenSees answers nothing (``eleResponse`` returns ``[]``, a recorder gives it no columns).
    A response OpenSees answers with values that vtsi does not compute
    (:data:`OPENSEES_ONLY_RESPONSES`), and a name the element answers followed by more words
    (OpenSees ignores them), raise a CommandError naming ``command``, the element and the words."""
    asked = " ".join(map(str, words))
    if len(words) == 1 and asked in valid:
        return True
    need = OPENSEES_ONLY_RESPONSES.get(etype.name, {}).get(words[0])
    if need is not None and len(words) >= need:
        raise CommandError(f"{command}: response {asked!r} of element {tag} ({etype.name}) is not supported: "
                           f"OpenSees answers it with values vtsi does not compute; supported: {', '.join(valid)}")
    if words[0] in valid:
        raise CommandError(f"{command}: response {asked!r} of element {tag} ({etype.name}): {words[0]} takes no "
                           f"more words, got {' '.join(map(str, words[1:]))!r} (OpenSees ignores them)")
    return False


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
    kinds, the OpenSees layouts built from them, their plural aliases and the other names its
    OpenSees type gives them, :data:`TYPE_RESPONSE_ALIASES`), in a stable order."""
    names = list(etype.response_kinds) + list(etype.command_layouts)
    names += ["force", "globalForce", "localForce", "basicForce", "deformation", "basicDeformation"]
    names += list(PLURAL_ALIASES) + list(TYPE_RESPONSE_ALIASES.get(etype.name, ()))
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

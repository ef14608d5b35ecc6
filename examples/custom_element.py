"""A user-defined element type, registered without touching vtsi: a 2-D Timoshenko beam.

The Euler-Bernoulli beam (``elasticBeamColumn``) neglects shear deformation, which is fine for
slender members and not for deep ones (short spans, transfer girders, pier heads). This script
adds a shear-flexible beam as a new element type: subclass :class:`vtsi.elements.ElementType`,
declare the parameters, write the local stiffness as a numba kernel and register the class.
``Model.element('timoshenkoBeam', ...)`` then works everywhere, batched and assembled like the
shipped elements, and the contract tests (``tests/test_element_contract.py``) check it too (it
has a sample there; a type without one is skipped, not failed). Every build checks what the
kernels return, once per type (``elements/base.py``, "What is checked where"): numpy arrays
``(n_el, 6, 6)`` of real numbers, finite, symmetric, no negative diagonal entry, mass and damping
positive semi-definite; anything else is a ModelError naming the type and the element. The
kernels run once per build: element recorders reuse the matrices.
Declaring ``command_args``/``command_options`` gives it an ``element`` command in
:mod:`vtsi.opensees` and in Tcl files (``element timoshenkoBeam 1 1 2 $A $E $I $G $kappa -mass
$rho``); the script builds a cantilever that way. (vtsi also ships OpenSees's own
``ElasticTimoshenkoBeam``; this example shows how a type of one's own is added.)

Element (dofs ``[ux1, uy1, rz1, ux2, uy2, rz2]``, global axes): the exact two-node stiffness of a
uniform Timoshenko beam, with ``φ = 12 EI / (κ G A L²)`` (φ → 0 gives back Euler-Bernoulli),

    k_bending = EI / ((1 + φ) L³) · [[ 12,   6L,        −12,  6L       ],
                                     [ 6L,   (4 + φ)L², −6L,  (2 − φ)L²],
                                     [−12,  −6L,         12, −6L       ],
                                     [ 6L,   (2 − φ)L², −6L,  (4 + φ)L²]]

plus the axial bar ``EA/L``; lumped mass ``ρL/2`` on each node's translations (no rotary
inertia, as OpenSees's lumped ``elasticBeamColumn``).

The script compares the first frequency of a simply supported beam modelled with both
elements against the closed forms (no rotary inertia, mode n, ``k = nπ/L``, mass per length μ):

    Euler-Bernoulli  ω² = EI k⁴ / μ
    with shear       ω² = EI k⁴ / (μ (1 + EI k² / (κ G A)))

Slender beam: both agree (shear adds ~0.05 %). Deep beam: the Timoshenko beam is softer and
its frequency lower; the Euler-Bernoulli beam overestimates it.

On a track (``vtsi.track.Track``, the wheels of a train) this beam is taken like any 2-node
(ux, uy, rz) element, but the wheel rows are the Euler-Bernoulli cubic Hermite interpolation of
its end dofs, whatever the element: between the nodes a wheel sees that interpolation, not the
Timoshenko field (refine the mesh under the track).

Run: ``python examples/custom_element.py``.

References
----------
Przemieniecki, J.S. (1968) Theory of Matrix Structural Analysis, McGraw-Hill, §5.6 (beam
stiffness including shear deformation).
Timoshenko, S.P. (1921) On the correction for shear of the differential equation for transverse
vibrations of prismatic bars, Phil. Mag. 41, 744-746.
OpenSees ``SRC/element/elasticBeamColumn/ElasticTimoshenkoBeam2d.cpp`` (``setUp``: the same stiffness
and lumped mass; OpenSees takes the shear area ``Avy`` = κA).
"""
import numpy as np
from numba import njit

import vtsi
from vtsi.elements import ElementType, register, rotate_to_global, rotation_2d
from vtsi.tcl import Interpreter


# No on-disk cache (cache=True) here: this file runs as a script and is imported by the tests
# under another module name, and numba keys its cache by the file alone.
@njit
def timoshenko_local_stiffness(A, E, I, G, kappa, L):
    """``(n_el, 6, 6)`` local stiffness [N/m, N, N·m] of uniform Timoshenko beams."""
    n = A.shape[0]
    k = np.zeros((n, 6, 6))
    for e in range(n):
        l1 = L[e]
        l2 = l1 * l1
        phi = 12.0 * E[e] * I[e] / (kappa[e] * G[e] * A[e] * l2)
        b = E[e] * I[e] / ((1.0 + phi) * l2 * l1)
        ea = E[e] * A[e] / l1
        k[e, 0, 0] = k[e, 3, 3] = ea
        k[e, 0, 3] = k[e, 3, 0] = -ea
        k[e, 1, 1] = k[e, 4, 4] = 12.0 * b
        k[e, 1, 4] = k[e, 4, 1] = -12.0 * b
        k[e, 1, 2] = k[e, 2, 1] = k[e, 1, 5] = k[e, 5, 1] = 6.0 * l1 * b
        k[e, 4, 2] = k[e, 2, 4] = k[e, 4, 5] = k[e, 5, 4] = -6.0 * l1 * b
        k[e, 2, 2] = k[e, 5, 5] = (4.0 + phi) * l2 * b
        k[e, 2, 5] = k[e, 5, 2] = (2.0 - phi) * l2 * b
    return k


@register
class TimoshenkoBeam2d(ElementType):
    """Elastic Timoshenko beam: area ``A`` [m²], Young's modulus ``E`` [Pa], inertia ``I`` [m⁴],
    shear modulus ``G`` [Pa], shear coefficient ``kappa`` (5/6 for a rectangle), mass per length
    ``rho`` [kg/m] (lumped)."""

    name = "timoshenkoBeam"
    param_names = ("A", "E", "I", "G", "kappa", "rho")
    positive = ("A", "E", "I", "G", "kappa")
    non_negative = ("rho",)
    defaults = {"rho": 0.0}
    # the element command of vtsi.opensees and Tcl files: element timoshenkoBeam tag i j A E I G kappa [-mass rho]
    command_args = ("A", "E", "I", "G", "kappa")
    command_options = {"-mass": "rho"}

    def stiffness(self, coords, params):
        c, s, L = rotation_2d(coords)
        A, E, I, G, kappa = (np.ascontiguousarray(params[:, i]) for i in range(5))
        return rotate_to_global(timoshenko_local_stiffness(A, E, I, G, kappa, L), c, s, 2, 3)

    def mass(self, coords, params):
        _, _, L = rotation_2d(coords)
        m = np.zeros((len(params), 6, 6))
        for d in (0, 1, 3, 4):      # lumped translations: invariant under rotation
            m[:, d, d] = 0.5 * params[:, 5] * L
        return m


def rectangular_steel_section(depth, width=0.5, E=210e9, nu=0.3, density=7850.0):
    """Element parameters of a solid steel rectangle ``width × depth`` [m]."""
    A = width * depth
    return dict(A=A, E=E, I=width * depth ** 3 / 12.0, G=E / (2.0 * (1.0 + nu)), kappa=5.0 / 6.0,
                rho=density * A)


def simply_supported_first_frequency(element, span, section, n_elements=40):
    """First natural frequency [Hz] of a pinned-pinned beam of ``element`` type."""
    m = vtsi.Model()
    for i in range(n_elements + 1):
        m.node(i + 1, span * i / n_elements, 0.0)
    m.fix(1, 1, 1, 0)
    m.fix(n_elements + 1, 1, 1, 0)
    params = section if element == "timoshenkoBeam" else {k: section[k] for k in ("A", "E", "I", "rho")}
    for i in range(n_elements):
        m.element(element, i + 1, (i + 1, i + 2), **params)
    omega2, _ = vtsi.eigen(m, 1)
    return float(np.sqrt(omega2[0]) / (2.0 * np.pi))


def closed_form_first_frequency(span, section, shear):
    """First frequency [Hz] of a simply supported beam, with or without shear deformation."""
    k = np.pi / span
    ei = section["E"] * section["I"]
    flexibility = ei * k * k / (section["kappa"] * section["G"] * section["A"]) if shear else 0.0
    return float(np.sqrt(ei * k ** 4 / (section["rho"] * (1.0 + flexibility))) / (2.0 * np.pi))


TCL_CANTILEVER = """
model basic -ndm 2 -ndf 3
node 1 0.0 0.0
node 2 $L 0.0
fix 1 1 1 1
element timoshenkoBeam 1 1 2 $A $E $I $G $kappa -mass $rho
timeSeries Constant 1
pattern Plain 1 1 { load 2 0.0 [expr {-$P}] 0.0 }
analysis Static
analyze 1
"""


def tcl_cantilever_tip_deflection(section, length=4.0, load=2e5):
    """Tip deflection [m] (downwards negative) of a one-element cantilever under a tip load
    ``load`` [N], built by a Tcl model script that uses the new type's ``element`` command."""
    tcl = Interpreter()
    values = dict(section, L=length, P=load)
    script = "".join(f"set {name} {value!r}\n" for name, value in values.items()) + TCL_CANTILEVER
    tcl.eval(script)
    return float(tcl.session.nodeDisp(2, 2))


def main(span=10.0, cases=(("slender", 50.0), ("deep", 4.0)), n_elements=40):
    """Compare the two beams on each ``(label, span/depth)`` case; print and return the table
    as ``{label: {'euler_bernoulli': f, 'timoshenko': f, 'euler_bernoulli_exact': f,
    'timoshenko_exact': f}}`` [Hz]."""
    results = {}
    print(f"Simply supported steel beam, span {span:g} m, {n_elements} elements, lumped mass: first frequency [Hz]")
    print(f"{'case':>8} {'L/h':>5} {'Euler-Bernoulli':>16} {'Timoshenko':>11} {'T/EB':>7} "
          f"{'EB exact':>9} {'T exact':>9}")
    for label, slenderness in cases:
        section = rectangular_steel_section(span / slenderness)
        row = {
            "euler_bernoulli": simply_supported_first_frequency("elasticBeamColumn", span, section, n_elements),
            "timoshenko": simply_supported_first_frequency("timoshenkoBeam", span, section, n_elements),
            "euler_bernoulli_exact": closed_form_first_frequency(span, section, shear=False),
            "timoshenko_exact": closed_form_first_frequency(span, section, shear=True),
        }
        results[label] = row
        print(f"{label:>8} {slenderness:5g} {row['euler_bernoulli']:16.4f} {row['timoshenko']:11.4f} "
              f"{row['timoshenko'] / row['euler_bernoulli']:7.4f} {row['euler_bernoulli_exact']:9.4f} "
              f"{row['timoshenko_exact']:9.4f}")
    section = rectangular_steel_section(1.5)
    tip = tcl_cantilever_tip_deflection(section)
    exact = -(2e5 * 4.0 ** 3 / (3 * section["E"] * section["I"]) + 2e5 * 4.0 / (section["kappa"] * section["G"]
                                                                                  * section["A"]))
    print(f"Tcl script, 'element timoshenkoBeam': cantilever 4 m, depth 1.5 m, tip load 200 kN: tip deflection "
          f"{tip * 1e3:.6f} mm (closed form {exact * 1e3:.6f} mm)")
    return results


if __name__ == "__main__":
    main()

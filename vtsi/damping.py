"""Damping of a bridge model by a ratio: Rayleigh damping fitted to two frequencies, and the
bending frequencies it is fitted to.

With C = α M + β K a mode of frequency f has the damping ratio ζ(f) = α / (4π f) + π β f: equal
to ζ at the two fitting frequencies f_a < f_b, smaller between them (its minimum, at √(f_a f_b),
is 2ζ√(f_a f_b)/(f_a + f_b)), and growing without bound above f_b (β's share) and below f_a (α's).
Fitted through the first frequency n₀ and the EN 1990 A2 cut-off, every mode that counts gets
at most ζ (the lower bound of EN 1991-2 Table 6.6 is therefore not exceeded there) and the modes
above the cut-off are damped more. An exact ratio on every mode needs a modal model.
"""
import numpy as np

from vtsi.analysis import eigen
from vtsi.codes.en1990_a2 import acceleration_cutoff_hz
from vtsi.errors import ModelError


def vertical_frequencies(model, n=3):
    """The first ``n`` vertical (bending) natural frequencies [Hz] and mode shapes of a model:
    the modes whose mass-weighted uy motion exceeds their ux motion (a beam's axial modes are
    skipped)."""
    asm = model.build()
    M = asm.M_full
    on = lambda dof: np.arange(asm.n_full) % asm.ndf == dof
    for k in (min(asm.n_free, max(3 * n, 12)), asm.n_free):
        omega2, shapes = eigen(model, k)
        motion = lambda mask: np.einsum("ij,ij->j", shapes * mask[:, None], M @ (shapes * mask[:, None]))
        keep = np.flatnonzero(motion(on(1)) > motion(on(0)))[:n]
        if len(keep) == n:
            break
    return np.sqrt(np.maximum(omega2[keep], 0.0)) / (2 * np.pi), shapes[:, keep]


def rayleigh_coefficients(zeta, f_a, f_b):
    """α [1/s], β [s] of C = α M + β K with damping ratio ``zeta`` at f_a and f_b [Hz]."""
    w_a, w_b = 2 * np.pi * f_a, 2 * np.pi * f_b
    return 2 * zeta * w_a * w_b / (w_a + w_b), 2 * zeta / (w_a + w_b)


def rayleigh_ratio(f, alpha, beta):
    """The damping ratio ζ(f) = α / (4π f) + π β f [-] that C = α M + β K gives a mode of
    frequency ``f`` [Hz] (see the module docstring)."""
    f = np.asarray(f, dtype=float)
    return alpha / (4 * np.pi * f) + np.pi * beta * f


def rayleigh_damping(model, zeta, frequencies_hz=None):
    """Give ``model`` the damping ratio ``zeta`` [-] by Rayleigh damping through
    ``frequencies_hz`` = (f_a, f_b) [Hz], by default the first vertical frequency n₀ and the
    EN 1990 A2 cut-off max(30 Hz, 1.5 n₀, n₃). Returns (α, β)."""
    try:
        zeta = float(zeta)
    except (TypeError, ValueError):
        raise ModelError(f"damping: the ratio must be a number, got {zeta!r}") from None
    if not 0.0 <= zeta < 1.0:
        raise ModelError(f"damping: the ratio must be in [0, 1) (0.01 for 1 %), got {zeta}")
    if frequencies_hz is None:
        f = vertical_frequencies(model, 3)[0]
        frequencies_hz = (f[0], acceleration_cutoff_hz(f))
    alpha, beta = rayleigh_coefficients(zeta, *frequencies_hz)
    model.rayleigh(alpha, beta)
    return alpha, beta

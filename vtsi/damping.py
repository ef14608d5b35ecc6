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
from vtsi.errors import ModelError, as_number
from vtsi.model import Model


def vertical_frequencies(model, n=3, ground=()):
    """The first ``n`` (an integer >= 1) vertical (bending) natural frequencies [Hz] and mode
    shapes of a model: the modes whose mass-weighted uy motion exceeds their ux motion (a
    beam's axial modes are skipped) and, with ``ground`` (node tags: a track's stretches on the
    ground, :mod:`vtsi.deck`), whose vertical kinetic energy lies at most half at those nodes
    (a mode of an approach on springs is not the bridge's: it read a 20 m deck's n₃ = 74.5 Hz as
    the approach's 36.2 Hz). As many modes are computed as needed, at most one per dof with mass
    (lumped mass leaves rotations without). A ModelError says how many the model has if fewer
    than ``n``."""
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or n < 1:
        raise ModelError(f"vertical frequencies: the count must be an integer >= 1, got {n!r}")
    if not isinstance(model, Model):
        raise ModelError(f"vertical frequencies: model must be a vtsi.Model, got {model!r}")
    asm = model.build()
    M = asm.M_full
    on = lambda dof: np.arange(asm.n_full) % asm.ndf == dof
    on_ground = np.zeros(asm.n_full, dtype=bool)
    for node in ground:
        on_ground[asm.full_dof(node, 2)] = True
    n_mass = int(np.count_nonzero(asm.M.diagonal() > 0.0))     # at most that many modes of finite frequency
    if n_mass == 0:
        raise ModelError("vertical frequencies: no dof carries mass")
    k = min(n_mass, max(3 * n, 12))
    while True:
        omega2, shapes = eigen(model, "all" if k == n_mass < asm.n_free else k)
        motion = lambda mask: np.einsum("ij,ij->j", shapes * mask[:, None], M @ (shapes * mask[:, None]))
        vertical = motion(on(1))
        keep = np.flatnonzero((vertical > motion(on(0))) & ~(motion(on_ground) > 0.5 * vertical))[:n]
        if len(keep) == n or k >= n_mass:
            break
        k = min(n_mass, 2 * k)
    if len(keep) < n:
        approach = int(np.sum((vertical > motion(on(0))) & (motion(on_ground) > 0.5 * vertical)))
        raise ModelError(f"vertical frequencies: {n} asked, the model has {len(keep)} vertical modes"
                         + (f" besides {approach} of its approaches" if approach else "")
                         + (f" (only {n_mass} of its {asm.n_free} free dofs carry mass: mesh the deck finer, or "
                            "give it mass)" if n_mass < asm.n_free else ""))
    return np.sqrt(np.maximum(omega2[keep], 0.0)) / (2 * np.pi), shapes[:, keep]


def rayleigh_coefficients(zeta, f_a, f_b):
    """α [1/s], β [s] of C = α M + β K with damping ratio ``zeta`` [-] (in [0, 1)) at the
    distinct frequencies f_a and f_b [Hz] (> 0)."""
    zeta = _ratio(zeta)
    f_a, f_b = _frequencies((f_a, f_b))
    w_a, w_b = 2 * np.pi * f_a, 2 * np.pi * f_b
    return 2 * zeta * w_a * w_b / (w_a + w_b), 2 * zeta / (w_a + w_b)


def rayleigh_ratio(f, alpha, beta):
    """The damping ratio ζ(f) = α / (4π f) + π β f [-] that C = α M + β K gives a mode of
    frequency ``f`` [Hz] (> 0; see the module docstring)."""
    try:
        f = np.asarray(f, dtype=float)
    except (TypeError, ValueError):
        raise ModelError(f"rayleigh ratio: frequencies must be numbers [Hz], got {f!r}") from None
    alpha, beta = as_number(alpha, "rayleigh ratio", "alpha"), as_number(beta, "rayleigh ratio", "beta")
    if not np.all(np.isfinite(f) & (f > 0.0)):
        raise ModelError(f"rayleigh ratio: frequencies must be > 0 and finite [Hz], got {f.tolist()}")
    return alpha / (4 * np.pi * f) + np.pi * beta * f


def rayleigh_damping(model, zeta, frequencies_hz=None):
    """Give ``model`` the damping ratio ``zeta`` [-] by Rayleigh damping through
    ``frequencies_hz`` = (f_a, f_b) [Hz], by default the first vertical frequency n₀ and the
    EN 1990 A2 cut-off max(30 Hz, 1.5 n₀, n₃). Returns (α, β)."""
    if not isinstance(model, Model):
        raise ModelError(f"damping: model must be a vtsi.Model, got {model!r}")
    zeta = _ratio(zeta)
    if frequencies_hz is None:
        f = vertical_frequencies(model, 3)[0]
        frequencies_hz = (f[0], acceleration_cutoff_hz(f))
    alpha, beta = rayleigh_coefficients(zeta, *_frequencies(frequencies_hz))
    model.rayleigh(alpha, beta)
    return alpha, beta


def _ratio(zeta):
    """The damping ratio ``zeta`` as a float in [0, 1), or a ModelError naming the value."""
    zeta = as_number(zeta, "damping", "the ratio")
    if not 0.0 <= zeta < 1.0:
        raise ModelError(f"damping: the ratio must be in [0, 1) (0.01 for 1 %), got {zeta}")
    return zeta


def _frequencies(frequencies_hz):
    """Two distinct fitting frequencies (f_a, f_b) [Hz] > 0 and finite, or a ModelError naming them."""
    if isinstance(frequencies_hz, (str, bytes)) or np.ndim(frequencies_hz) != 1 or len(frequencies_hz) != 2:
        raise ModelError(f"damping: give two frequencies (f_a, f_b) [Hz], got {frequencies_hz!r}")
    f_a, f_b = (as_number(f, "damping", "a frequency [Hz]") for f in frequencies_hz)
    for f in (f_a, f_b):
        if not (np.isfinite(f) and f > 0.0):
            raise ModelError(f"damping: frequencies must be > 0 and finite [Hz], got ({f_a:g}, {f_b:g})")
    if f_a == f_b:
        raise ModelError(f"damping: the two frequencies must differ, got ({f_a:g}, {f_b:g})")
    return f_a, f_b

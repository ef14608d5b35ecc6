"""A modal bridge: the first modes of a FE bridge, each with its own damping ratio.

With the mass-normalised shapes Φ (Φᵀ M Φ = I) of the kept modes, u ≈ Φ q and

    q̈_j + 2 ζ_j ω_j q̇_j + ω_j² q_j = φ_jᵀ P(t)

one uncoupled equation per mode: true modal damping (EN 1991-2 gives a ratio per mode, which
Rayleigh damping gives to two modes only). The time loops step it through the same bridge
subdomain contract as the FE bridge (:mod:`vtsi.subdomain`): its matrices are diagonal (half
bandwidth 0), a load is projected on the modes, a recorded dof is read back through its row of Φ,
and a wheel's constraint row over the track dofs becomes that row times Φ on the track dofs
(:class:`ModalStages`). Exact passages of moving forces: :meth:`ModalBridge.passage`
(:mod:`vtsi.modal_passage`).

What is left out is the truncated modes' response: accelerations above the kept frequency (the
EN 1990 A2 cut-off by construction) and their quasi-static share of a displacement or a bending
moment. That share is small for a deflection and not for a moment (a simply supported span's mode
j carries 1/j⁴ of the static mid-span deflection under a central force but 1/j² of the moment:
with modes 1 and 2 kept, 1.2 % and 11 % are missing), so exact passages add it back by default:
the static correction (K⁻¹ − Φ Ω⁻² Φᵀ) P(t), the residual flexibility of the truncated modes times
the axle loads where they stand (:meth:`ModalBridge.static_correction`), exact for the part of
the response the truncated modes give quasi-statically (their frequencies far above the loading's). With every mode kept, the modal bridge
steps exactly the FE bridge's equations (tests: to 1e-9 with the same integrator and Δt) when
its damping is classical (ΦᵀCΦ diagonal, e.g. Rayleigh).
"""
import math

import numpy as np
import scipy.sparse as sp

from vtsi.analysis import eigen, lowest_modes_until, modes_up_to
from vtsi.banded import inverse_columns, ldl_band
from vtsi.damping import bridge_frequencies
from vtsi.errors import (AnalysisError, BridgeModelError, ModelError, as_number, as_numbers, as_positive, is_count,
                         is_int)
from vtsi.modal_passage import add_static_correction, exact_response, first_bad_axle, shape_polynomials
from vtsi.subdomain import BridgeStages, factor, rows_times
from vtsi.track import Track

CUTOFF_MARGIN = 1.1     # modes up to 1.1 × the cut-off: a mode that sits on the cut-off stays in


def _moving(asm, track, shapes):
    """The columns of ``shapes`` that move ``track`` (all without one): a straight beam's axial
    modes load no wheel."""
    if track is None:
        return np.arange(shapes.shape[1])
    on_track = np.abs(shapes[asm.full_of_free[track.free_index]])
    return np.flatnonzero(np.max(on_track, axis=0) > 1e-9 * np.max(on_track))


def _mode_count(n_modes):
    """``n_modes`` as an int >= 1 (a whole float such as 3.0 too, as vtsi's other counts:
    :func:`~vtsi.errors.is_count`) or 'all', else a ModelError naming it."""
    if isinstance(n_modes, str) and n_modes == "all":
        return n_modes
    if not is_count(n_modes, 1):
        raise ModelError(f"modal bridge: n_modes must be an integer >= 1 or 'all', got {n_modes!r}")
    return int(n_modes)


def _lowest_modes(model, asm, track, n_modes):
    """``(frequencies [Hz], shapes, keep)``: the lowest ``n_modes`` (an int >= 1, or 'all':
    every mode) modes that move ``track`` (``keep`` their columns), asking
    :func:`~vtsi.analysis.lowest_modes_until` for twice as many until there are enough; a
    ModelError naming the most there are when the model has fewer."""
    if n_modes == "all":
        omega2, shapes = eigen(model, n_modes)
        return np.sqrt(np.maximum(omega2, 0.0)) / (2 * np.pi), shapes, _moving(asm, track, shapes)
    omega2, shapes = lowest_modes_until(model, n_modes, lambda _, shapes: len(_moving(asm, track, shapes)) >= n_modes)
    keep = _moving(asm, track, shapes)
    if len(keep) < n_modes:                 # every mode computed: len(keep) is the most there are
        which = (f"only {len(keep)} modes of the model move the track (of {shapes.shape[1]}: the others, a straight "
                 "beam's axial modes, load no wheel)" if len(keep) < shapes.shape[1] else
                 f"the model has only {len(keep)} modes (one per dof with mass)")
        raise ModelError(f"modal bridge: n_modes = {n_modes}, but {which}: n_modes must be at most {len(keep)}")
    return np.sqrt(np.maximum(omega2, 0.0)) / (2 * np.pi), shapes, keep[:n_modes]


class ModalBridge:
    """The modes of a FE bridge model, mass-normalised, with a damping ratio per mode.

    Parameters
    ----------
    model : vtsi.Model (built as it is now: a later change of the model needs a new ModalBridge).
    track : vtsi.track.Track or None. With a track, modes that do not move it (a straight beam's
        axial modes) are left out: no wheel loads them.
    f_max : highest frequency kept [Hz]; default (and ``n_modes`` None): the EN 1990 A2
        acceleration cut-off max(30 Hz, 1.5 n₀, n₃) × 1.1 (CUTOFF_MARGIN, so that a mode sitting
        on the cut-off stays in), n₀, n₃ each deck's own along the track and the cut-off the
        largest of the decks' (:func:`~vtsi.damping.bridge_frequencies`, as a sweep's default
        ``modal_hz``: two 15 m decks on one pier keep their modes up to 105.6 Hz, not the 46.9
        Hz of the model's first three frequencies); without a track the model is read as one
        deck (its first three vertical frequencies).
    zeta : damping ratio [-] (>= 0; < 1 for exact passages) of every mode, a sequence (one per kept mode) or a function of the
        frequency [Hz] -> ratio. None: the model's own damping, ζ_j = φ_jᵀ C φ_j / (2 ω_j), which
        must be classical (ΦᵀCΦ diagonal, e.g. Rayleigh).
    n_modes : keep the lowest ``n_modes`` modes instead of a frequency bound (with a track: the
        lowest that move it): an integer >= 1 (a whole float such as 3.0 too), at most the modes
        the model has (one per dof with mass; with a track, those that move it); 'all': every
        mode of finite frequency (with every dof carrying mass, the FE model's own equations).

    Attributes
    ----------
    frequencies (n,) [Hz], omega (n,) [rad/s], zeta (n,) (read-only: :meth:`add_ratios`),
    shapes (n_full, n) mass-normalised, assembly (the model version the modes belong to),
    track_modes (n_track, n) and track_shapes (n_el, n, 4)
    (:func:`~vtsi.modal_passage.shape_polynomials`) with a track; truncated (whether fewer
    modes are kept than the model has).
    """

    def __init__(self, model, track=None, f_max=None, zeta=None, n_modes=None):
        if track is not None and not isinstance(track, Track):
            raise ModelError(f"modal bridge: track must be a vtsi.track.Track or None, got {track!r}")
        asm = model.build()
        if asm.transformation is not None:
            raise BridgeModelError("modal bridge: the model has equalDOF/rigidLink constraints, which the modal bridge does "
                             "not take; model the connections with elements (zeroLength, stiff beams)")
        if n_modes is not None:
            if f_max is not None:
                raise ModelError("modal bridge: give f_max or n_modes, not both")
            f, shapes, keep = _lowest_modes(model, asm, track, _mode_count(n_modes))
        else:
            if f_max is None:
                f_max = CUTOFF_MARGIN * bridge_frequencies(model, track).cutoff_hz
            f_max = _positive_hz(f_max)
            f, shapes = modes_up_to(model, f_max)
            if f[0] > f_max:
                raise ModelError(f"modal bridge: f_max = {f_max:g} Hz is below the first mode ({f[0]:.4g} Hz): "
                                 "no mode to keep")
            keep = _moving(asm, track, shapes)
        if len(keep) == 0:
            raise BridgeModelError(f"modal bridge: no mode up to {f[-1]:g} Hz moves the track")
        self.assembly, self.track = asm, track
        self.frequencies, self.shapes = f[keep], np.ascontiguousarray(shapes[:, keep])
        self.off_track = np.ascontiguousarray(np.delete(shapes, keep, axis=1))   # computed, moving no track dof
        self.omega = 2 * np.pi * self.frequencies
        if not np.all(self.omega > 0):
            raise BridgeModelError("modal bridge: a kept mode has zero frequency (a mechanism)")
        self._set_ratios(self._ratios(zeta))
        if track is not None:
            self.track_modes = np.ascontiguousarray(self.shapes[asm.full_of_free[track.free_index]])
            self.track_shapes = shape_polynomials(self.track_modes, track.dofs, track.length)

    def __repr__(self):
        z, f = self._zeta, self.frequencies
        ratios = f"ζ = {z[0]:.3g}" if np.all(z == z[0]) else f"ζ = {z.min():.3g} to {z.max():.3g}"
        kept = "truncated" if self.truncated else "every mode"
        track = f"track x = {self.track.x_begin:g} to {self.track.x_end:g} m" if self.track is not None else "no track"
        return f"ModalBridge({self.n_modes} modes, {f[0]:.4g} to {f[-1]:.4g} Hz, {ratios}, {kept}, {track})"

    def _ratios(self, zeta):
        n = self.n_modes
        if zeta is None:
            phi = self.shapes[self.assembly.full_of_free]
            modal_c = phi.T @ (self.assembly.C @ phi)
            diagonal = np.diag(modal_c).copy()
            off = np.abs(modal_c - np.diag(diagonal)).max(initial=0.0)
            if off > 1e-8 * max(np.abs(diagonal).max(initial=0.0), 1e-300) and off > 0.0:
                raise BridgeModelError("modal bridge: the model's damping is not classical (ΦᵀCΦ has off-diagonal terms "
                                 f"up to {off:.3g}); give the damping ratios: zeta=... (a sweep: its damping ratio, "
                                 "PassageSettings(damping=...), --damping)")
            ratios = diagonal / (2.0 * self.omega)
        elif callable(zeta):
            ratios = np.array([_ratio_of(zeta, fi) for fi in self.frequencies])
        else:
            ratios = as_numbers(zeta, "modal bridge", "damping ratios")
            ratios = np.broadcast_to(ratios, (n,)).copy() if ratios.ndim == 0 else ratios
        if ratios.shape != (n,) or not np.all((ratios >= 0) & np.isfinite(ratios)):
            given = "a function giving " + str(ratios.tolist()) if callable(zeta) else np.asarray(zeta).tolist()
            raise ModelError(f"modal bridge: damping ratios must be finite and >= 0, one per kept mode ({n}), got {given}")
        return ratios

    @property
    def n_modes(self):
        return len(self.frequencies)

    @property
    def truncated(self):
        """Whether a mode that the loads can excite is left out: fewer modes are kept and
        ``off_track`` than the model has (one per free dof with mass; a dof without mass follows
        the others statically). Then a response made of the stiffness, K Φ q (a reaction), leaves
        out the other modes' share. The ``off_track`` modes (computed and dropped because they do not
        move the track: a straight beam's axial modes) take no wheel force, and a pattern load
        that would excite them is refused (:meth:`ModalStages.loads`), so they leave out nothing."""
        kept = self.n_modes + self.off_track.shape[1]
        return kept < int(np.count_nonzero(self.assembly.M.diagonal() > 0.0))

    @property
    def zeta(self):
        """The damping ratio of each kept mode [-] (read-only: :meth:`add_ratios` adds to it)."""
        view = self._zeta.view()
        view.flags.writeable = False
        return view

    def _set_ratios(self, ratios):
        self._zeta = np.array(ratios, dtype=float)
        over = np.flatnonzero(self._zeta >= 1.0)
        self._overdamped = int(over[0]) if len(over) else -1      # an exact passage needs ζ < 1

    def add_ratios(self, ratios):
        """Add damping ratios [-] to the lowest ``len(ratios)`` modes (OpenSees ``modalDamping``
        on top of the model's own damping)."""
        ratios = as_numbers(ratios, "modal bridge", "added ratios")
        if ratios.ndim != 1 or len(ratios) > self.n_modes or not np.all((ratios >= 0) & np.isfinite(ratios)):
            raise ModelError(f"modal bridge: added ratios must be finite, >= 0 and at most one per mode "
                             f"({self.n_modes}), got {ratios.tolist()}")
        zeta = self._zeta.copy()
        zeta[: len(ratios)] += ratios
        self._set_ratios(zeta)

    def check_underdamped(self):
        """Raise unless every mode has ζ < 1, as an exact passage needs (naming the first that has not)."""
        if self._overdamped >= 0:
            j = self._overdamped
            raise BridgeModelError(f"modal bridge: mode {j + 1} ({self.frequencies[j]:.4g} Hz) has ζ = {self.zeta[j]:.4g} >= 1; "
                             "an exact passage needs underdamped modes (lower f_max or give the ratios)")

    def stages(self, integrator, dt, track=None, self_weight_load=None):
        """The bridge subdomain for ``integrator`` and ``dt`` [s] (:class:`ModalStages`)."""
        return ModalStages(self, integrator, dt, track, self_weight_load)

    def check_model(self, model):
        """Raise unless ``model`` is still the version the modes were computed for."""
        if model.build() is not self.assembly:
            raise AnalysisError("modal bridge: the model changed after its modes were computed; "
                                "build a new ModalBridge")

    def residual_flexibility(self, output_map):
        """``G (n_track, n_columns)``: the truncated modes' static response (K⁻¹ − Φ Ω⁻² Φᵀ) of
        the outputs ``output_map (n_free, n_columns)`` (a free-dof response per column: a
        selection for a displacement, moment rows for a bending moment) to a unit force on each
        track dof."""
        asm, track = self.assembly, self.track
        if track is None:
            raise ModelError("modal bridge: a residual flexibility needs the bridge's track "
                             "(ModalBridge(model, track, ...))")
        output_map = as_numbers(output_map, "modal bridge", "output map")
        if output_map.ndim != 2 or output_map.shape[0] != asm.n_free:
            raise ModelError(f"modal bridge: the output map must be (n_free = {asm.n_free}, n_columns), "
                             f"got {output_map.shape}")
        k_inv = inverse_columns(factor(asm, asm.K, "bridge stiffness K"), track.free_index)    # (n_free, n_track)
        phi = self.shapes[asm.full_of_free]
        return k_inv.T @ output_map - (self.track_modes / self.omega ** 2) @ (phi.T @ output_map)

    def static_correction(self, G, offsets, loads, speed, x_head0, n_samples, dt):
        """The truncated modes' quasi-static part (n_samples, n_columns) of the outputs of
        :meth:`residual_flexibility` ``G`` in a passage (arguments as :meth:`passage`)."""
        x0, loads, speed, n_samples, dt = self._axles(offsets, loads, speed, x_head0, n_samples, dt)
        G = as_numbers(G, "modal bridge", "residual flexibility G")
        if G.ndim != 2 or G.shape[0] != self.track.n_track:
            raise ModelError(f"modal bridge: the residual flexibility G must be (n_track = {self.track.n_track}, "
                             f"n_columns), got {G.shape}")
        out = np.zeros((n_samples, G.shape[1]))
        add_static_correction(x0, loads, speed, self.track.x_start, self.track.length, self.track.dofs,
                              G, dt, out)
        return out

    def passage(self, offsets, loads, speed, x_head0, n_samples, dt, rows):
        """Output columns of a passage of downward axle ``loads`` [N] at ``offsets`` [m] behind the
        head (at ``x_head0`` [m] at t = 0), ``speed`` [m/s], from rest, exact
        (:mod:`vtsi.modal_passage`): ``(n_samples, n_columns)`` at t = dt, 2 dt, … (the analyses'
        output times), column c = Σ_j rows[0, j, c] q_j + rows[1, j, c] q̇_j + rows[2, j, c] q̈_j
        (``rows (3, n_modes, n_columns)``: a node response is its row of Φ on q, q̇ or q̈)."""
        x0, loads, speed, n_samples, dt = self._axles(offsets, loads, speed, x_head0, n_samples, dt)
        self.check_underdamped()
        rows = as_numbers(rows, "modal bridge", "passage rows")
        if rows.ndim != 3 or rows.shape[:2] != (3, self.n_modes):
            raise ModelError(f"modal bridge: passage rows must be (3, {self.n_modes}, n_columns), got {rows.shape}")
        out = np.zeros((n_samples, rows.shape[2]))
        exact_response(x0, loads, speed, self.track.x_start, self.track.length, self.track_shapes, self.omega,
                       self._zeta, dt, rows, out)
        return out

    def _axles(self, offsets, loads, speed, x_head0, n_samples, dt):
        """The checked arguments of a passage: ``(x0, loads, speed, n_samples, dt)``, x0 the
        axles' positions at t = 0 [m] (decreasing), contiguous."""
        if self.track is None:
            raise ModelError("modal bridge: a passage needs the bridge's track (ModalBridge(model, track, ...))")
        offsets = as_numbers(offsets, "modal bridge", "axle offsets")
        loads = as_numbers(loads, "modal bridge", "axle loads")
        if offsets.ndim != 1 or loads.shape != offsets.shape or offsets.size == 0:
            raise ModelError(f"modal bridge: a passage needs as many axle loads as axle offsets (1-D, at least one), "
                             f"got {loads.shape} loads and {offsets.shape} offsets")
        bad = first_bad_axle(offsets, loads)
        if bad >= 0 and not (math.isfinite(offsets[bad]) and math.isfinite(loads[bad])):
            raise ModelError(f"modal bridge: axle {bad}: offset {offsets[bad]} m and load {loads[bad]} N must be finite")
        if bad >= 0:
            raise ModelError(f"modal bridge: axle {bad}: offset {offsets[bad]} m is ahead of axle {bad - 1}'s "
                             f"{offsets[bad - 1]} m; offsets behind the head increase (the train's order)")
        speed = as_positive(speed, "modal bridge", "passage speed")
        dt = as_positive(dt, "modal bridge", "passage dt")
        if not math.isfinite(as_number(x_head0, "modal bridge", "passage x_head0 [m]")):
            raise ModelError(f"modal bridge: passage x_head0 must be a finite position [m], got {x_head0!r}")
        if not (is_int(n_samples) and n_samples >= 0):
            raise ModelError(f"modal bridge: passage n_samples must be an integer >= 0, got {n_samples!r}")
        return float(x_head0) - offsets, loads, speed, int(n_samples), dt

    def coordinates(self, offsets, loads, speed, x_head0, n_samples, dt):
        """``(q, q̇, q̈)`` of a passage (arguments as :meth:`passage`), each (n_samples, n_modes)."""
        n = self.n_modes
        rows = np.zeros((3, n, 3 * n))
        for order in range(3):
            rows[order, :, order * n:(order + 1) * n] = np.eye(n)
        out = self.passage(offsets, loads, speed, x_head0, n_samples, dt, rows)
        return out[:, :n], out[:, n:2 * n], out[:, 2 * n:]


class ModalStages(BridgeStages):
    """A :class:`ModalBridge` as the bridge subdomain of a time loop (:mod:`vtsi.subdomain`):
    coordinates q (n_modes), M = I, C = diag(2ζω), K = diag(ω²), effective matrices diagonal."""

    def __init__(self, modal, integrator, dt, track=None, self_weight_load=None):
        asm = modal.assembly
        self.modal, self.n = modal, modal.n_modes
        self.phi = modal.shapes[asm.full_of_free]                  # (n_free, n)
        self.mass = asm.M
        k, c = modal.omega ** 2, 2.0 * modal.zeta * modal.omega
        A = integrator.n_slots
        limit = integrator.stability_limit(dt)
        if limit is not None and modal.omega.max() * dt > limit * (1.0 + 1e-12):
            raise AnalysisError(f"integrator {integrator.name}: dt = {dt:g} s exceeds its stability limit "
                                f"{limit / modal.omega.max():.6g} s on the modal bridge (highest mode "
                                f"{modal.frequencies.max():.6g} Hz); reduce dt or keep fewer modes")
        stages = integrator.checked_stages(dt)      # the contract, once: a broken scheme is named here
        k_hat = [1.0 + st.kv[A] * c + st.ku[A] * k for st in stages]
        self._stepping(integrator, dt, sp.diags(k), sp.diags(c), sp.identity(self.n),
                       [ldl_band(sp.diags(d), 0) for d in k_hat])
        self.stiffness = sp.diags(k).tocsc()
        if track is not None:
            self.track_index = np.zeros(track.n_track, dtype=np.int64)
            self.track_basis = np.ascontiguousarray(self.phi[track.free_index])
            self.flex = np.ascontiguousarray(np.stack([(self.track_basis / d) @ self.track_basis.T for d in k_hat]))
            self.track_operator = sp.csr_matrix(self.track_basis)
            if self_weight_load is not None:
                self.track_sag = self.track_basis @ (self.phi.T @ self_weight_load / k)

    def mobility(self, track_dofs):
        """Σ_k φ_k² [1/kg] of each of the track dofs ``track_dofs`` over the kept modes (mass-normalised)."""
        return np.sum(self.track_basis[track_dofs] ** 2, axis=1)

    def coordinates(self, free):
        """q = Φᵀ M u of a free-dof vector."""
        return self.phi.T @ (self.mass @ free)

    def free_values(self, coords):
        return self.phi @ coords

    def static_load(self, p_free):
        return self.phi.T @ p_free

    def static_free(self, x):
        return self.phi @ x

    def loads(self, ptr, dof, val):
        """The pattern loads' modal forces Φᵀ P, one dense row of n per pattern (CSR). Refused: a
        load on a dof without mass (its static response is not in the modes), and a load that
        excites a mode left out because it moves no track dof (:attr:`ModalBridge.off_track`,
        e.g. a horizontal force on a straight beam's axial modes: it would be dropped silently)."""
        massless = dof[self.mass.diagonal()[dof] <= 0.0] if len(dof) else dof
        if len(massless):
            raise AnalysisError(f"modal bridge: a load on {self.modal.assembly.dof_label(massless[0])}, which has "
                                "no mass: the modes do not carry its static response (load a dof with mass, "
                                "or use the FE bridge)")
        n_p = len(ptr) - 1
        out = np.zeros((n_p, self.n))
        off = self.modal.off_track[self.modal.assembly.full_of_free]       # (n_free, n_off)
        for p in range(n_p):
            sl = slice(ptr[p], ptr[p + 1])
            out[p] = self.phi[dof[sl]].T @ val[sl]
            excited = off[dof[sl]].T @ val[sl]
            scale = np.abs(off[dof[sl]]).max(initial=0.0) * np.abs(val[sl]).sum()
            if np.any(np.abs(excited) > 1e-9 * scale):
                at = dof[sl][np.argmax(np.abs(off[dof[sl]]).max(axis=1) * np.abs(val[sl]))]
                raise AnalysisError(f"modal bridge: a load on {self.modal.assembly.dof_label(at)} excites modes "
                                    "that move no track dof and were left out (a straight deck's axial modes): its "
                                    "response would be dropped; build the ModalBridge without the track "
                                    "(track=None keeps every mode) or use the FE bridge")
        return (np.arange(n_p + 1, dtype=np.int64) * self.n, np.tile(np.arange(self.n, dtype=np.int64), n_p),
                out.ravel())

    def record_plan(self, rec_slot, rec_index):
        """Record every mode in each slot the recorders need; :meth:`recorded` maps them to the
        recorders' free dofs through their rows of Φ."""
        slots = np.unique(rec_slot)
        self._post = np.zeros((len(slots) * self.n, len(rec_slot)))
        for r, (slot, dof) in enumerate(zip(rec_slot, rec_index)):
            b = int(np.searchsorted(slots, slot))
            if dof >= 0:
                self._post[b * self.n: (b + 1) * self.n, r] = self.phi[dof]
        return np.repeat(slots, self.n).astype(np.int64), np.tile(np.arange(self.n, dtype=np.int64), len(slots))

    def recorded(self, out):
        return rows_times(out, self._post)


def _ratio_of(zeta, f):
    """The damping ratio the user's function ``zeta`` gives at ``f`` [Hz] (a number: a text or
    a bool it returns is refused, naming the frequency)."""
    try:
        ratio = zeta(f)
    except Exception as exc:       # the user's function: its failure named, with the frequency
        raise ModelError(f"modal bridge: the damping function failed at {f:.6g} Hz: "
                         f"{type(exc).__name__}: {exc}") from None
    return as_number(ratio, "modal bridge", f"the damping function's ratio at {f:.6g} Hz")


def _positive_hz(value):
    return as_positive(value, "modal bridge", "f_max [Hz]")

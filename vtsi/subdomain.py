"""The bridge subdomain the time loops step (docs/modal.md): one contract, two implementations.

A time loop (:func:`vtsi.timeloop.run_linear_steps`, :func:`vtsi.coupled_loop.run_coupled_steps`)
advances a padded state bank ``(n_slots, n + 2 kd)`` of ``n`` coordinates: per integrator stage, a
banded factor of the effective matrix ``M + kv C + ku K`` and the operators of the stage's known
part. What a bridge gives the loops for one integrator and Δt is a :class:`BridgeStages`:

- ``n``, ``du``, ``dv`` (the integrator's stage coefficients), ``fac`` (n_stages, n + kd, kd + 1), ``ops``, ``weights`` (:func:`vtsi.timeloop.stage_operators`),
  ``band``, ``load_points`` (each stage's ``(θ, weight)`` load evaluations): the stepping data;
- :meth:`~BridgeStages.loads`: pattern loads (CSR over the free dofs) as loads on the coordinates;
- :meth:`~BridgeStages.bank` (or :meth:`~BridgeStages.load_bank`, into a kept bank) /
  :meth:`~BridgeStages.commit`: the committed state in and out; ``exact_reload``: whether a
  committed bank comes back from the state it wrote to the bit (the FE bridge's coordinates are
  dof values; a modal bridge's q come back as Φᵀ M Φ q, q to round-off, so a loop that goes on
  from its own commit keeps its bank);
- :func:`rows_times`: ``a @ b`` whose rows do not depend on how many there are (a chunk's
  recorded rows, whatever its length);
- :meth:`~BridgeStages.record_plan` / :meth:`~BridgeStages.recorded`: what the kernel records for the
  recorders' free-dof columns and how those columns follow from it;
- along a track (coupled analyses): ``track_index`` (n_track,) the coordinate of each track dof and
  ``track_basis`` (n_track, n_basis) — a track dof's value is ``bank[kd + track_index[c]]`` when
  ``n_basis == 0``, else ``track_basis[c] · bank[kd: kd + n]``; ``flex`` (n_stages, n_track, n_track)
  the stages' K̂⁻¹ on the track dofs [per unit acceleration weight]; ``track_sag`` (n_track,) [m] the
  self-weight deflection of the track dofs (None without self weight);
- for the dead-load solve: ``stiffness`` over its own coordinates (the FE bridge's free dofs, the
  modes), ``track_operator`` (n_track × those), :meth:`~BridgeStages.static_load` and
  :meth:`~BridgeStages.static_free` to map a load in and a solution out.

Implementations: :class:`FEStages` (the FE bridge: banded, on the dofs that can move) here, and
:class:`vtsi.modal_bridge.ModalStages` (mass-normalised modes: diagonal, kd = 0).
"""
import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from vtsi.assembly import renumbered
from vtsi.banded import (LOST_PIVOT, NotPositiveDefinite, band_rows, band_rows_of_entries, band_type,
                          inverse_columns, ldl_band_of_entries, ldl_band_of_storage, lower_band_storage, pad_solve)
from vtsi.errors import AnalysisError
from vtsi.timeloop import stage_operators


def factor(assembly, matrix, what, cause=None, dofs=None, kd=None):
    """Banded Cholesky factor of a free-dof matrix, or of its rows and columns ``dofs`` (the
    matrix given already restricted to them), with the half bandwidth ``kd`` (default: that of K,
    M and C there); a failure names the dof at fault (``cause``: the explanation that follows, by
    default "a mechanism or a dof with neither stiffness nor mass")."""
    coo = sp.coo_matrix(matrix)
    return factor_entries(assembly, coo.row, coo.col, coo.data, what, cause, dofs, kd)


def factor_entries(assembly, rows, cols, values, what, cause=None, dofs=None, kd=None):
    """:func:`factor` of the matrix with the entries ``values`` at ``(rows, cols)`` (over the free
    dofs, or renumbered over ``dofs``)."""
    p = assembly.pattern
    if dofs is None:
        dofs = np.arange(assembly.n_free)
    if kd is None:
        r, c, _ = renumbered(p.rows, p.cols, dofs, assembly.n_free)
        kd = int(np.max(np.abs(r - c), initial=0))
    try:
        return ldl_band_of_entries(rows, cols, values, len(dofs), kd)
    except NotPositiveDefinite as exc:
        raise _singular(assembly, what, cause, dofs[exc.pivot], exc.lost) from None


def _singular(assembly, what, cause, dof, lost=False):
    """The AnalysisError of a factor that failed at free dof ``dof`` (``lost``: its pivot was lost
    to round-off, :data:`vtsi.banded.LOST_PIVOT`)."""
    if cause is None and lost:
        cause = (f"the structure is a mechanism, or a stiffness there is some {1 / LOST_PIVOT:.0e} times its "
                 f"neighbours' or more (its pivot kept less than {LOST_PIVOT:g} of its diagonal, lost to round-off: "
                 "a 'rigid' spring or penalty of 1e20 on a member of 1e6 N/m; tie the dofs with equalDOF or "
                 "rigidLink, or give the spring some 1e6 times the members' stiffness)")
    return AnalysisError(f"{what} is singular or not positive definite at {assembly.dof_label(dof)}: "
                         + (cause or "the structure is a mechanism or that dof has neither stiffness nor "
                                     "mass (fix it or connect it)"))


def factor_stage(assembly, active, rest, kv, ku, what, cause=None):
    """Banded factor of the effective matrix M + kv C + ku K on the moving dofs ``active``
    (:func:`vtsi.analysis.moving_dofs`), with the half bandwidth of K, M and C there (every stage's
    the same). The dofs at rest, ``rest`` (the other free dofs, ascending), are checked too: a dof
    with neither stiffness nor mass is a modelling error even where nothing moves, and is named as
    everywhere else."""
    p = assembly.pattern
    n = assembly.n_free
    for dofs in ((rest, active) if len(rest) else (active,)):
        try:
            lower = ldl_band_of_storage(stage_storage(p.rows, p.cols, p.K, p.C, p.M, dofs, n, kv, ku))
        except NotPositiveDefinite as exc:
            raise _singular(assembly, what, cause, dofs[exc.pivot], exc.lost) from None
    return lower


@njit(cache=True)
def stage_storage(rows, cols, K, C, M, dofs, n, kv, ku):
    """LAPACK's lower band storage ``(kd + 1, len(dofs))`` (Fortran order) of ``M + kv C + ku K``,
    given by their values at the entries ``(rows, cols)`` of the ``n`` free dofs, on the rows and
    columns ``dofs``; ``kd`` the half bandwidth of those entries there."""
    r, c, keep = renumbered(rows, cols, dofs, n)
    kd = 0
    for k in range(r.shape[0]):
        kd = max(kd, abs(r[k] - c[k]))
    return lower_band_storage(r, c, M[keep] + kv * C[keep] + ku * K[keep], dofs.shape[0], kd)


@njit(cache=True)
def band_rows_on(rows, cols, K, C, M, dofs, n, kd):
    """The band rows ``(n_d, 2 kd + 1)`` of K, C and M (their values at the entries ``(rows,
    cols)`` of the ``n`` free dofs) on the rows and columns ``dofs`` (n_d,)."""
    r, c, keep = renumbered(rows, cols, dofs, n)
    return (band_rows_of_entries(r, c, K[keep], dofs.shape[0], kd),
            band_rows_of_entries(r, c, C[keep], dofs.shape[0], kd),
            band_rows_of_entries(r, c, M[keep], dofs.shape[0], kd))


def max_frequency(assembly):
    """Largest ω [rad/s] of ``K φ = ω² M φ`` (stability check of conditionally stable schemes);
    infinite when a free dof has stiffness but no mass."""
    try:
        if assembly.n_free <= 1500:
            lam = scipy.linalg.eigvalsh(assembly.K.toarray(), assembly.M.toarray(), subset_by_index=[assembly.n_free - 1] * 2)
        else:
            lam = spla.eigsh(assembly.K.tocsc(), k=1, M=assembly.M.tocsc(), which="LM",
                             return_eigenvectors=False, tol=1e-8)
    except (np.linalg.LinAlgError, spla.ArpackError, ValueError):
        return np.inf
    return float(np.sqrt(max(lam[-1], 0.0)))


@njit(cache=True)
def rows_times(a, b):
    """``a @ b`` for ``a (n, k)``, ``b (k, m)``, each row summed in one order whatever n: the rows of
    a chunk of steps are the same in chunks of any length (BLAS picks its kernels by the shapes,
    so a one-step chunk's row and a longer chunk's differ in the last bits)."""
    out = np.zeros((a.shape[0], b.shape[1]))
    for i in range(a.shape[0]):
        for j in range(a.shape[1]):
            aij = a[i, j]
            for c in range(b.shape[1]):
                out[i, c] += aij * b[j, c]
    return out


class BridgeStages:
    """The contract (see the module docstring). Subclasses set the attributes and implement
    :meth:`free_values` (coordinates -> free-dof vectors) and :meth:`loads`."""

    n = 0
    exact_reload = False        # a modal bridge's q = Φᵀ M u of a commit Φ q is q to round-off only
    track_index = np.zeros(0, dtype=np.int64)
    track_basis = np.zeros((0, 0))
    flex = np.zeros((0, 0, 0))
    track_sag = None

    def _stepping(self, integrator, dt, K, C, M, factors):
        """Set fac, ops, weights, band from the stage factors and K, C, M (sparse) on the coordinates."""
        kd = factors[0].shape[1] - 1
        self._stepping_rows(integrator.checked_stages(dt), factors, *(band_rows(a, kd) for a in (K, C, M)))

    def _stepping_rows(self, stages, factors, k_rows, c_rows, m_rows):
        """:meth:`_stepping` from the integrator's ``stages`` and the band rows ``(n, 2 kd + 1)`` of
        K, C, M."""
        self.fac = np.array(factors)
        self.kd = self.fac.shape[2] - 1
        self.band = band_type(self.kd)
        self.load_points = [st.load for st in stages]
        pack = lambda name: np.array([getattr(st, name) for st in stages])
        self.du, self.dv = pack("du"), pack("dv")
        self.ops, self.weights = stage_operators(k_rows, c_rows, pack("ku"), pack("kv"), m_rows, pack("km"))

    def bank(self, state, full_of_free, n_slots):
        """A padded bank ``(n_slots, n + 2 kd)`` holding the committed ``state`` in slots 0..2."""
        return self.load_bank(np.zeros((n_slots, self.n + 2 * self.kd)), state, full_of_free)

    def load_bank(self, bank, state, full_of_free):
        """Write the committed ``state`` into slots 0..2 of the padded ``bank`` (its other slots and
        its padding kept); returns the bank."""
        for slot, vec in enumerate((state.u, state.v, state.a)):
            bank[slot, self.kd: self.kd + self.n] = self.coordinates(vec[full_of_free])
        return bank

    def commit(self, state, bank, full_of_free, time):
        """Write the bank's slots 0..2 back to the full-dof ``state`` at ``time`` [s]."""
        for slot, vec in enumerate((state.u, state.v, state.a)):
            vec[:] = 0.0
            vec[full_of_free] = self.free_values(bank[slot, self.kd: self.kd + self.n])
        state.time = time

    def rail_point_mass(self, track):
        """[kg] The smallest apparent mass of the bridge at a node of ``track``, 1 / (e M⁻¹ eᵀ)
        with e the rail's row at the node (its uy dof) on the coordinates (M = I for mass-normalised
        modes): the mass a massless wheel's springs act on there at high frequency (inf if no node
        of the track moves)."""
        cols, vals, _ = track.rows(np.append(track.x_start, track.x_end))
        at_node = np.unique(cols[(cols >= 0) & (vals == 1.0)])
        if not len(at_node):
            return np.inf
        mobility = self.mobility(at_node)
        return 1.0 / mobility.max() if mobility.max() > 0.0 else np.inf

    def track_values(self, coords):
        """The track dofs' values (n_track,) of a coordinate vector (n,)."""
        if self.track_basis.shape[1]:
            return self.track_basis @ coords
        return np.where(self.track_index >= 0, coords[np.maximum(self.track_index, 0)], 0.0)


class FEStages(BridgeStages):
    """The FE bridge on the free dofs that can move (``active``, :func:`vtsi.analysis.moving_dofs`).

    Parameters
    ----------
    assembly : the model's assembly; active : (n_a,) int64 free dofs integrated.
    integrator, dt [s] : the stages; track : vtsi.track.Track or None (transient analyses).
    self_weight_load : (n_free,) [N] or None: the self weight whose static deflection ``track_sag``
        the rail is measured from.

    ``rest_full`` (n_free − n_a,) int64: the full dofs of the free dofs at rest (ascending free
    index), which a run checks are still at rest.
    """

    exact_reload = True         # its coordinates are the moving dofs' values

    def __init__(self, assembly, active, integrator, dt, track=None, self_weight_load=None):
        self.assembly, self.active, self.n = assembly, active, len(active)
        self.active_full = assembly.full_of_free[active]        # the full dof of each coordinate
        self.position = np.full(assembly.n_free, -1, dtype=np.int64)
        self.position[active] = np.arange(len(active))
        rest = np.flatnonzero(self.position < 0)                # the free dofs at rest, ascending
        self.rest_full = assembly.full_of_free[rest]            # their full dofs (a run checks they stay at rest)
        A = integrator.n_slots
        cause = (f"{integrator.name} is explicit, so every free dof needs mass and that one has none "
                 "(give it mass, fix it, or use an implicit integrator: Newmark, HHT, Bathe)") if integrator.explicit else None
        factors = []
        stages = integrator.checked_stages(dt)       # the contract, once: a broken scheme is named here
        for s, st in enumerate(stages):
            what = f"effective matrix of {integrator.name} stage {s + 1} (M + {st.kv[A]:.3g} C + {st.ku[A]:.3g} K)"
            factors.append(factor_stage(assembly, active, rest, st.kv[A], st.ku[A], what, cause))
        limit = integrator.stability_limit(dt)
        if limit is not None:
            massless = np.flatnonzero((assembly.M.diagonal() <= 0.0) & (assembly.K.diagonal() > 0.0))
            if len(massless):          # omega_max (of every free dof, as max_frequency) is infinite: no dt is stable
                raise AnalysisError(f"integrator {integrator.name} is conditionally stable and "
                                    f"{assembly.dof_label(massless[0])} is a free dof without mass (omega_max is "
                                    "infinite: no dt is stable); give it mass, fix it, or use an unconditionally "
                                    "stable scheme (Newmark 0.5 0.25, HHT or GeneralizedAlpha with their default "
                                    "gamma and beta, Bathe)")
            omega_max = max_frequency(assembly)
            if omega_max * dt > limit * (1.0 + 1e-12):
                raise AnalysisError(f"integrator {integrator.name}: dt = {dt:g} s exceeds its stability limit "
                                    f"{limit / omega_max:.6g} s (= {limit:.4g}/omega_max, omega_max = "
                                    f"{omega_max:.6g} rad/s); reduce dt or use an unconditionally stable scheme")
        p = assembly.pattern
        self._stepping_rows(stages, factors, *band_rows_on(p.rows, p.cols, p.K, p.C, p.M, active, assembly.n_free,
                                                           factors[0].shape[1] - 1))
        if track is not None:
            self.track_index = self.position[track.free_index]
            self.track_basis = np.zeros((track.n_track, 0))
            self.flex = np.ascontiguousarray(np.stack([inverse_columns(f, self.track_index)[self.track_index]
                                                       for f in self.fac]))
            self.track_operator = sp.csr_matrix((np.ones(track.n_track), (np.arange(track.n_track), track.free_index)),
                                                shape=(track.n_track, assembly.n_free))
            if self_weight_load is not None:
                sag = pad_solve(factor(assembly, assembly.K, "bridge stiffness K"), self_weight_load)
                self.track_sag = sag[track.free_index]

    @property
    def stiffness(self):
        """K over the free dofs (CSR)."""
        return self.assembly.K

    def mobility(self, track_dofs):
        """(e M⁻¹ eᵀ) [1/kg] of each of the track dofs ``track_dofs`` (0 for a dof at rest) over the
        integrated dofs, the massless ones left out (they follow the others statically)."""
        coords = self.track_index[track_dofs]
        out = np.zeros(len(coords))
        moving = coords >= 0
        M = self.assembly.M.tocsr()[self.active][:, self.active]
        massed = np.flatnonzero(M.diagonal() > 0.0)
        where = np.searchsorted(massed, coords[moving])
        ok = where < len(massed)
        ok[ok] = massed[where[ok]] == coords[moving][ok]
        if len(massed) and np.any(ok):
            rhs = np.zeros((len(massed), int(ok.sum())))
            rhs[where[ok], np.arange(int(ok.sum()))] = 1.0
            sol = spla.splu(M[massed][:, massed].tocsc()).solve(rhs)
            vals = np.zeros(int(moving.sum()))
            vals[ok] = sol[where[ok], np.arange(int(ok.sum()))]
            out[moving] = vals
        return out

    def coordinates(self, free):
        return free[self.active]

    def free_values(self, coords):
        out = np.zeros(self.assembly.n_free)
        out[self.active] = coords
        return out

    def load_bank(self, bank, state, full_of_free):
        """:meth:`BridgeStages.load_bank`, reading the moving dofs' entries of the full-dof state
        straight (``full_of_free``: the assembly's)."""
        for slot, vec in enumerate((state.u, state.v, state.a)):
            bank[slot, self.kd: self.kd + self.n] = vec[self.active_full]
        return bank

    def commit(self, state, bank, full_of_free, time):
        """:meth:`BridgeStages.commit`, writing the moving dofs' entries straight (the others 0)."""
        for slot, vec in enumerate((state.u, state.v, state.a)):
            vec[:] = 0.0
            vec[self.active_full] = bank[slot, self.kd: self.kd + self.n]
        state.time = time

    def static_load(self, p_free):
        """A free-dof load as a load on the coordinates of ``stiffness`` (here the free dofs)."""
        return p_free

    def static_free(self, x):
        """The free-dof displacements of a solution over ``stiffness``'s coordinates."""
        return x

    def loads(self, ptr, dof, val):
        """The CSR ``(ptr, dof, val)`` over free dofs with the dofs as bank coordinates (a loaded
        dof is always integrated)."""
        return ptr, self.position[dof], val

    def record_plan(self, rec_slot, rec_index):
        """Kernel columns ``(slot, coordinate)`` for recorder columns of free dofs ``rec_index``
        (-1: a dof at rest, read as 0)."""
        return rec_slot, self.position[rec_index]

    def recorded(self, out):
        """The recorder columns from the kernel's columns (here the same)."""
        return out


class BridgeStageCache:
    """Bridge stages by what they were built for (the bridge — a FE assembly or a modal bridge —
    and a key: integrator, Δt, track, moving dofs, self-weight load). Analyses that share one cache
    prepare the bridge once (a sweep: once for all its passages). A coupled analysis keeps its
    train's share there too, with the bridge's (:class:`vtsi.coupled.TrainStages`, keyed by the
    train's matrices: a sweep factors a train with dofs once for all its speeds). Keeps the
    entries of the latest bridge only, so a changed model frees the old factors."""

    def __init__(self):
        self._entries = []

    def __len__(self):
        return len(self._entries)

    def get(self, source, key, build):
        """The stages of ``source`` for ``key``, built by ``build()`` when not cached."""
        for entry_source, entry_key, stages in self._entries:
            if entry_source is source and entry_key == key:
                return stages
        stages = build()
        self._entries = [e for e in self._entries if e[0] is source] + [(source, key, stages)]
        return stages

    def stages(self):
        """The cached stages (oldest first)."""
        return [e[2] for e in self._entries]


def stage_key(integrator, dt, track=None, active=None, self_weight_load=None):
    """What bridge stages depend on besides the bridge itself (hashable)."""
    weight = None if self_weight_load is None else np.asarray(self_weight_load).tobytes()
    tr = None if track is None else (track.free_index.tobytes(), track.dofs.tobytes(), track.x_start.tobytes(),
                                     track.length.tobytes())
    return (repr(integrator), float(dt), None if active is None else np.asarray(active).tobytes(), tr, weight)

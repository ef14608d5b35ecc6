"""The integrator contract: stages of coefficients, never elements.

Every step of every integrator is a sequence of *stages* (Newmark and HHT: one; Bathe: two).
A stage solves, for its acceleration ``a_s``,

    M (a_s + Σ_j km[j] X_j) + C ṽ + K ũ = P̃,
    ũ = Σ_j ku[j] X_j + ku[A] a_s,   ṽ = Σ_j kv[j] X_j + kv[A] a_s,   P̃ = Σ_q w_q P(t_n + θ_q Δt),

then sets ``u_s = Σ_j du[j] X_j + du[A] a_s`` and ``v_s = Σ_j dv[j] X_j + dv[A] a_s``. The
*bank* ``X`` holds the known vectors: slots 0, 1, 2 are ``u_n, v_n, a_n``; stage ``s`` writes
its ``u_s, v_s, a_s`` to slots ``3 + 3 s, 4 + 3 s, 5 + 3 s``; index ``A = n_slots`` is the
coefficient of the unknown ``a_s``. The last stage's slots are the state at ``t_n + Δt``. The
effective matrix of a stage is ``K̂_s = M + kv[A] C + ku[A] K``, constant for a linear model and a
constant step, so the analysis factors it once. ``km`` (zero but for the generalized-α method,
which weights the inertia of the step start) holds the mass's coefficients on known slots; the
load weights then sum to ``1 + Σ km`` (a constant load balances a constant acceleration), and so
do the weights of the constraint forces of a coupled analysis (:attr:`Stage.mass_weight`).

Contract of an integrator
-------------------------
Items 1 and 7, and that ``stages`` is defined, are checked by :func:`register`; items 2, 3 (a claim
of unconditional stability), 4, 6 and 8 by :meth:`Integrator.checked_stages` (:func:`check_stages`), which every analysis calls once when it
prepares a Δt (not per step; vtsi's own schemes once per class, parameters and Δt in a process,
:func:`_shipped_key`), so that a broken scheme is refused with an
:class:`~vtsi.errors.AnalysisError` naming it instead of crashing the compiled loop or running to
a wrong answer; ``tests/test_integrator_contract.py`` runs every registered integrator through
all of them.

1. ``name`` (non-empty str) and ``n_stages`` (int >= 1) class attributes; register with
   :func:`register`.
2. ``stages(dt)`` returns a list of ``n_stages`` fresh :class:`Stage` objects; their coefficient
   arrays ``du, dv, ku, kv, km`` have shape ``(n_slots + 1,)`` with ``n_slots = 3 + 3 n_stages``,
   finite, ``km[A] = 0``, and ``ku[A], kv[A] >= 0`` (``K̂`` positive definite). Stage ``s`` (from 0)
   reads only slots already written: ``0 .. 2 + 3 s`` (the step start and the stages before it).
   Each stage's ``load`` is a non-empty list of finite ``(θ, w)`` (θ may exceed 1: Wilson-θ) with
   ``Σ w = 1 + Σ km`` (its :attr:`Stage.mass_weight`: a constant load ``P`` then balances the
   constant acceleration ``M⁻¹P`` of a free body); the last stage's ``theta`` is 1.
3. ``stability_limit(dt)``: ``None`` if unconditionally stable (checked: the undamped
   oscillator's spectral radius <= 1 from ωΔt = 0.01 to 10⁴), else the largest stable ``ω Δt``
   (undamped); the analysis compares it with ``ω_max Δt`` and refuses to run beyond it.
4. ``explicit``: True exactly when ``ku[A] = 0`` in every stage, so that ``K̂ = M + kv[A] C`` holds
   no stiffness (``K̂ = M`` for an undamped model; central difference has ``kv[A] = Δt/2``).
5. Parameters are validated in ``__init__`` with an :class:`~vtsi.errors.AnalysisError`
   naming the integrator, the parameter and its stable range.
6. Each stage's ``force_weight`` ω is finite and > 0: a coupled analysis weights the stage's own
   constraint forces by ω (and divides by it to record them) and the step start's by
   ``1 + Σ km − ω``. The built-in schemes interpolate (``0 < ω <= 1 + Σ km``); a scheme that
   extrapolates has ``1 + Σ km − ω < 0`` (Wilson-θ: ω = 1, ``1 + Σ km = 1/θ``).
   ``force_record_weights()`` has ``n_stages + 1`` finite entries summing to 1.
7. A name is registered once: a second class under a registered name (a copy of a built-in not
   renamed) is refused with a TypeError naming both classes; the same class defined again (a
   script or notebook cell run twice) replaces the old definition.
8. Consistency: one step, every stage included, keeps a structure at rest in static equilibrium
   under a constant load (``u = K⁻¹P, v = a = 0``) and moves a body without stiffness at constant
   velocity ``V`` under the constant damping force ``C V`` (``u_s = u_n + V θ_s Δt``, ``v_s = V``,
   ``a_s = 0`` at each stage's end time ``θ_s Δt``), to roundoff. (Every scheme of the Newmark
   family, generalized-α, Bathe, backward Euler pass; a wrong update coefficient, a mass or stiffness
   weight that does not match the load weights, or a wrong stage end time does not.)

From the stages alone the base class gives :meth:`Integrator.amplification` (the step's 3×3
amplification matrix on an oscillator), :meth:`Integrator.spectral_radius` and
:attr:`Integrator.dissipative` (whether the highest frequencies are damped: a coupled analysis
with contact='lcp' needs it, and the design check reads wheel unloading only with it or with
smoothed rows).
"""
import inspect
import math
import re
from dataclasses import dataclass, field

import numpy as np

from vtsi.errors import AnalysisError, as_number

INTEGRATORS = {}
HIGH_OMEGA_DT = 1e4   # Ω = ωΔt where :attr:`Integrator.dissipative` reads the spectral radius
UNCONDITIONAL_OMEGA_DT = np.geomspace(1e-2, HIGH_OMEGA_DT, 61)
"""The Ω = ωΔt where :func:`check_stages` verifies a scheme that claims to be unconditionally
stable (``stability_limit`` None): spectral radius <= 1, ten points a decade."""


def register(cls):
    """Class decorator: check contract items 1 and 7 and that the class defines ``stages(dt)``,
    and make the integrator known by name (to :func:`make_integrator`, sweeps, coupled analyses
    and the ``integrator`` command).

    Raises TypeError for a missing or invalid ``name`` / ``n_stages``, no ``stages``, or a name
    that another class has registered (both classes named)."""
    for attribute in ("name", "n_stages"):
        if getattr(cls, attribute, None) is None:
            raise TypeError(f"integrator {cls.__name__}: missing class attribute {attribute!r}")
    if not isinstance(cls.name, str) or not cls.name:
        raise TypeError(f"integrator {cls.__name__}: name must be a non-empty str, got {cls.name!r}")
    if isinstance(cls.n_stages, bool) or not isinstance(cls.n_stages, (int, np.integer)) or cls.n_stages < 1:
        raise TypeError(f"integrator {cls.__name__}: n_stages must be an int >= 1 (the stages of a step), "
                        f"got {cls.n_stages!r}")
    if cls.stages is Integrator.stages:
        raise TypeError(f"integrator {cls.__name__}: must define stages(dt), returning its n_stages Stage objects")
    known = INTEGRATORS.get(cls.name)
    redefined = known is not None and (known.__module__, known.__qualname__) == (cls.__module__, cls.__qualname__)
    if known is not None and known is not cls and not redefined:   # re-running a script redefines its class
        raise TypeError(f"integrator name {cls.name!r} of {cls.__module__}.{cls.__qualname__} is already registered "
                        f"by {known.__module__}.{known.__qualname__}; give the new class a name of its own")
    INTEGRATORS[cls.name] = cls
    return cls


def make_integrator(spec, *args, **kwargs):
    """An integrator from an instance, a class, a registered name (with its parameters), or a
    name with its parameters as text, ``'HHT(0.9)'`` or its repr ``'HHT(alpha=0.9, gamma=0.6,
    beta=0.3025)'``."""
    if isinstance(spec, Integrator):
        if args or kwargs:
            raise AnalysisError(f"integrator {spec.name}: parameters given twice")
        return spec
    if isinstance(spec, type) and issubclass(spec, Integrator):
        return spec(*args, **kwargs)
    call = _CALL.fullmatch(spec) if isinstance(spec, str) else None
    if call and call.group(1) in INTEGRATORS:
        if args or kwargs:
            raise AnalysisError(f"integrator {spec!r}: parameters given twice")
        args, kwargs = _call_arguments(spec, call.group(2))
        spec = call.group(1)
    if isinstance(spec, str) and spec in INTEGRATORS:
        try:
            inspect.signature(INTEGRATORS[spec]).bind(*args, **kwargs)
        except TypeError:             # a parameter the integrator does not take
            given = ", ".join([f"{a!r}" for a in args] + [f"{k}={v!r}" for k, v in kwargs.items()])
            raise AnalysisError(f"integrator {spec}: ({given}) does not fit its parameters "
                                f"{inspect.signature(INTEGRATORS[spec])}") from None
        return INTEGRATORS[spec](*args, **kwargs)
    raise AnalysisError(f"unknown integrator {spec!r}; known: {', '.join(sorted(INTEGRATORS))} "
                        "(parameters as 'HHT(0.9)')")


_CALL = re.compile(r"\s*([A-Za-z]\w*)\s*\((.*)\)\s*")


def _call_arguments(spec, text):
    """The numbers of ``'0.9, gamma=0.6'``: ``([0.9], {'gamma': 0.6})``, or an AnalysisError; ``''``
    is no argument. An empty argument (``'HHT(0.9,,0.35)'``, a trailing comma) is refused: dropping
    it moved the numbers after it to the wrong parameters."""
    args, kwargs = [], {}
    parts = [p.strip() for p in text.split(",")] if text.strip() else []
    if "" in parts:
        raise AnalysisError(f"integrator {spec!r}: argument {parts.index('') + 1} of {len(parts)} is empty; "
                            "give every number, or name the ones after a parameter left at its default "
                            "('HHT(0.9, beta=0.35)')")
    for part in parts:
        key, _, value = part.rpartition("=")
        try:
            number = float(value)
        except ValueError:
            raise AnalysisError(f"integrator {spec!r}: {part!r} is not a number (or name=number)") from None
        if key and not key.strip().isidentifier():
            raise AnalysisError(f"integrator {spec!r}: {key.strip()!r} is not a parameter name")
        if key.strip() in kwargs:
            raise AnalysisError(f"integrator {spec!r}: {key.strip()} given twice")
        if key:
            kwargs[key.strip()] = number
        elif kwargs:
            raise AnalysisError(f"integrator {spec!r}: {part!r} follows a named parameter")
        else:
            args.append(number)
    return args, kwargs


@dataclass
class Stage:
    """Coefficients of one stage (see the module docstring); ``theta`` is the stage's end time
    as a fraction of the step, ``load`` the ``(θ_q, w_q)`` pairs of its load evaluation, and
    ``force_weight`` the weight ω of the stage's own constraint forces in its equation: the
    stage balances ``ω Gᵀλ_s + (m - ω) Gᵀλ_n`` with ``m`` its :attr:`mass_weight` (HHT: ω = α,
    m = 1, as for every other force; generalized-α: ω = αF/αM, m = 1/αM)."""

    du: np.ndarray
    dv: np.ndarray
    ku: np.ndarray
    kv: np.ndarray
    load: list = field(default_factory=lambda: [(1.0, 1.0)])
    theta: float = 1.0
    force_weight: float = 1.0
    km: np.ndarray = None

    def __post_init__(self):
        if self.km is None:
            self.km = np.zeros_like(self.ku)

    @property
    def mass_weight(self):
        """``1 + Σ km``, the equation's total mass coefficient: the load weights and the weights
        of the constraint forces sum to it (a constant force balances a constant acceleration);
        exactly 1.0 when ``km`` is zero."""
        return 1.0 + float(np.sum(self.km))


class Integrator:
    """Base class of the time integrators (see the module docstring for the contract)."""

    name = None
    n_stages = None
    explicit = False

    @property
    def n_slots(self):
        return 3 + 3 * self.n_stages

    def coefficients(self, **by_slot):
        """A coefficient vector from ``u_n=..., v_n=..., a_n=..., a=...`` or ``slot3=...``."""
        names = {"u_n": 0, "v_n": 1, "a_n": 2, "a": self.n_slots}
        c = np.zeros(self.n_slots + 1)
        for key, value in by_slot.items():
            c[names[key] if key in names else int(key[4:])] += value
        return c

    def stages(self, dt):
        raise AnalysisError(f"integrator {type(self).__name__}: stages(dt) is not defined; an integrator class "
                            "must define stages(dt), returning its n_stages Stage objects (vtsi.integrators.base)")

    def checked_stages(self, dt):
        """:meth:`stages` of ``dt`` [s] checked against the contract (items 2, 4, 6, 8 of the module
        docstring, :func:`check_stages`): what an analysis prepares its stepping from, once per
        Δt (the check costs about as much as :meth:`amplification`, nothing per step). vtsi's own
        schemes are checked once per (class, parameters, Δt) in a process (:func:`_shipped_key`);
        any other class every time.

        Raises AnalysisError naming the integrator (its repr), the stage and what is wrong."""
        stages = self.stages(dt)
        key = _shipped_key(self, dt)
        if key not in _CHECKED:
            check_stages(self, stages, dt)
            if key is not None:
                if len(_CHECKED) >= CHECKED_KEYS:
                    _CHECKED.clear()
                _CHECKED.add(key)
        return stages

    def force_record_weights(self):
        """Weights (n_stages + 1) of λ_n and of each stage's λ in the contact force an analysis
        records for a step. Default: the last stage's. A scheme whose velocity update mixes the
        step's forces (Bathe: v_{n+1} − v_n = Δt Σ w_s a_s) returns those w, so that the record's
        Σ λ Δt is the impulse the steps transferred, a span entry's included."""
        weights = np.zeros(self.n_stages + 1)
        weights[-1] = 1.0
        return weights

    def stability_limit(self, dt):
        return None

    def amplification(self, omega_dt, xi=0.0, dt=1.0):
        """The 3×3 matrix ``A`` with ``(u, v, a)_{n+1} = A (u, v, a)_n`` [m, m/s, m/s²] of the
        oscillator ``ü + 2ξω u̇ + ω² u = 0`` stepped with Ω = ``omega_dt`` = ωΔt, Δt = ``dt`` [s]:
        the stages run on one column per initial value, stage s solving
        ``(1 + c kv[A] + k ku[A]) a_s = −Σ km[j] X_j − c Σ kv[j] X_j − k Σ ku[j] X_j`` (k = ω², c = 2ξω)."""
        omega = omega_dt / dt
        bank = np.zeros((self.n_slots, 3))
        bank[:3] = np.eye(3)
        bank = oscillator_step(self.checked_stages(dt), bank, omega ** 2, 2.0 * xi * omega, np.zeros(3))
        return bank[self.n_slots - 3:]

    def spectral_radius(self, omega_dt, xi=0.0):
        """The largest |eigenvalue| of :meth:`amplification` at Ω = ``omega_dt``."""
        return float(np.max(np.abs(np.linalg.eigvals(self.amplification(omega_dt, xi)))))

    @property
    def dissipative(self):
        """Whether the scheme damps the highest frequencies it steps: spectral radius below 1 at
        Ω = ωΔt = HIGH_OMEGA_DT (at 0.999 × the limit of a conditionally stable scheme). Newmark's
        trapezoidal rule (γ = ½, so HHT with α = 1 and central differences) is not: after a jump
        of a rail's curvature its contact force rings for ever."""
        limit = self.stability_limit(1.0)
        return self.spectral_radius(HIGH_OMEGA_DT if limit is None else 0.999 * limit) < 1.0 - 1e-9

    def __repr__(self):
        params = ", ".join(f"{k}={v:.15g}" for k, v in vars(self).items() if isinstance(v, float) and k[0] != "_")
        return f"{type(self).__name__}({params})"


COEFFICIENTS = ("du", "dv", "ku", "kv", "km")
CONSISTENCY_TOL = 1e-8    # relative error allowed in the consistency check (roundoff: ~1e-15)
CHECKED_KEYS = 256        # how many keys of vtsi's own schemes checked_stages remembers (then it starts over)
_CHECKED = set()          # the keys (_shipped_key) whose stages check_stages passed
_PACKAGE = __name__.rpartition(".")[0] + "."      # 'vtsi.integrators.': the modules of vtsi's own schemes


def _shipped_key(integrator, dt):
    """``(class, its stages and force_record_weights, the instance's attributes, dt)`` for an
    instance of a class defined in this package: its stages and record weights are a pure function
    of this key (they read only the parameters set in ``__init__`` and ``dt``), so a key that
    :func:`check_stages` passed once passes again. ``None`` for any other class (a user's scheme,
    a subclass of a shipped one included: its methods may read anything), checked every time."""
    cls = type(integrator)
    if not cls.__module__.startswith(_PACKAGE):
        return None
    key = (cls, cls.stages, cls.force_record_weights, tuple(sorted(vars(integrator).items())), dt)
    try:
        hash(key)
    except TypeError:             # an attribute set to a list or an array
        return None
    return key


def oscillator_step(stages, bank, k, c, load):
    """One step of ``ü + c u̇ + k u = p`` (mass 1) through ``stages``, on the columns of ``bank``
    (n_slots, n_col) whose slots 0..2 hold ``u_n, v_n, a_n``; ``load`` (n_col,) the constant load
    ``p`` of each column; ``k`` [1/s²], ``c`` [1/s] scalars or one per column (n_col,). Fills each
    stage's slots ``3 + 3 s ..`` (the last stage's are the state at ``t_n + Δt``) and returns ``bank``."""
    n = bank.shape[0]
    for s, st in enumerate(stages):
        weight = sum(w for _, w in st.load)
        a = (weight * load - st.km[:n] @ bank - c * (st.kv[:n] @ bank) - k * (st.ku[:n] @ bank)) \
            / (1.0 + c * st.kv[n] + k * st.ku[n])
        bank[3 + 3 * s] = st.du[:n] @ bank + st.du[n] * a
        bank[4 + 3 * s] = st.dv[:n] @ bank + st.dv[n] * a
        bank[5 + 3 * s] = a
    return bank


def check_stages(integrator, stages, dt):
    """Raise an AnalysisError unless ``stages`` (``integrator.stages(dt)``) keep the contract of
    the module docstring (items 2, 4, 6, 8), in that order: count and types, coefficient shapes
    and finite values (array-likes are kept as float64 arrays), slots read only once written,
    ``km[A] = 0``, ``ku[A], kv[A] >= 0``, the ``explicit`` flag, load points and their weights
    (``Σ w = 1 + Σ km``), the last stage's ``theta`` = 1, ``force_weight`` > 0, the record weights,
    then consistency (rest under a constant load, constant velocity). The message names the
    integrator by its repr, the stage and what is wrong."""
    who = f"integrator {integrator!r}" + ("" if type(integrator).__name__ == integrator.name
                                          else f" (name {integrator.name!r})")
    n_stages, A = integrator.n_stages, integrator.n_slots
    if not isinstance(stages, (list, tuple)):
        raise AnalysisError(f"{who}: stages(dt={dt:g}) returned {type(stages).__name__}, not a list of Stage")
    if len(stages) != n_stages:
        raise AnalysisError(f"{who}: declares n_stages = {n_stages} but stages(dt={dt:g}) returned "
                            f"{len(stages)} stage(s); n_stages must count them (it sizes the state bank)")
    for s, st in enumerate(stages):
        where = f"{who}: stage {s + 1} of {n_stages}"
        if not isinstance(st, Stage):
            raise AnalysisError(f"{where} is a {type(st).__name__}, not a vtsi.integrators.Stage")
        known = 3 + 3 * s          # slots 0 .. known - 1 are written when the stage runs
        rows = []
        for name in COEFFICIENTS:
            try:
                c = np.asarray(getattr(st, name), dtype=np.float64)
            except (TypeError, ValueError):
                raise AnalysisError(f"{where}: {name} is not an array of numbers: {getattr(st, name)!r}") from None
            if c.shape != (A + 1,):
                raise AnalysisError(f"{where}: {name} has shape {c.shape}; it needs ({A + 1},): n_slots + 1 with "
                                    f"n_slots = 3 + 3 n_stages = {A} (slots 0..{A - 1}, then the unknown a_s's "
                                    "coefficient; Integrator.coefficients() builds one)")
            rows.append(c)
        block = np.array(rows)     # (5, A + 1): the coefficients checked together
        finite = np.isfinite(block).all(axis=1)
        if not finite.all():
            q = int(np.argmin(finite))
            raise AnalysisError(f"{where}: {COEFFICIENTS[q]} holds NaN or inf: {rows[q]}")
        late = block[:, known:A] != 0.0
        if late.any():
            q, slot = divmod(int(np.argmax(late)), A - known)
            slot += known
            raise AnalysisError(f"{where}: {COEFFICIENTS[q]} reads slot {slot} ({_slot_name(slot)}), not written "
                                f"yet; stage {s + 1} reads only slots 0..{known - 1} (the step start"
                                + (" and the stages before it)" if s else ")"))
        st.du, st.dv, st.ku, st.kv, st.km = rows
        if st.km[A] != 0.0:
            raise AnalysisError(f"{where}: km[{A}] = {st.km[A]:g}; the unknown's mass coefficient is 1, "
                                "km[A] must be 0")
        if st.ku[A] < 0.0 or st.kv[A] < 0.0:
            raise AnalysisError(f"{where}: ku[A] = {st.ku[A]:g}, kv[A] = {st.kv[A]:g}; both must be >= 0 (the "
                                "effective matrix M + kv[A] C + ku[A] K is then positive definite)")
        try:
            load = [(float(theta), float(w)) for theta, w in st.load]
        except (TypeError, ValueError):
            raise AnalysisError(f"{where}: load must be a list of (theta, weight) number pairs, "
                                f"got {st.load!r}") from None
        if not load or not all(math.isfinite(theta) and math.isfinite(w) for theta, w in load):
            raise AnalysisError(f"{where}: load must be a non-empty list of finite (theta, weight) pairs, "
                                f"got {st.load!r}")
        total, mass = sum(w for _, w in load), st.mass_weight
        if abs(total - mass) > 1e-9 * max(1.0, abs(mass)):
            raise AnalysisError(f"{where}: its load weights sum to {total:.10g}, its mass weight 1 + sum(km) is "
                                f"{mass:.10g}; they must be equal (a constant load P then balances the constant "
                                "acceleration M^-1 P; otherwise every load is scaled by their ratio)")
        if not np.isfinite(float(st.theta)) or (s == n_stages - 1 and abs(st.theta - 1.0) > 1e-12):
            raise AnalysisError(f"{where}: theta = {st.theta!r}; the end time of a stage as a fraction of the step "
                                "must be finite, and 1 for the last stage (it ends the step)")
        if not (np.isfinite(float(st.force_weight)) and st.force_weight > 0.0):
            raise AnalysisError(f"{where}: force_weight = {st.force_weight!r}; it must be finite and > 0 (the "
                                "weight of the stage's own constraint forces in its equation: 1 for Newmark, "
                                "alpha for HHT; a coupled analysis divides by it)")
    explicit = all(st.ku[A] == 0.0 for st in stages)
    if bool(integrator.explicit) != explicit:
        raise AnalysisError(f"{who}: explicit = {integrator.explicit!r}, but ku[A] is "
                            + ("0 in every stage (K̂ holds no stiffness: set explicit = True)" if explicit else
                               "nonzero in a stage (K̂ holds stiffness: set explicit = False)"))
    record = np.asarray(integrator.force_record_weights(), dtype=np.float64)
    if record.shape != (n_stages + 1,) or not np.all(np.isfinite(record)) or abs(record.sum() - 1.0) > 1e-9:
        raise AnalysisError(f"{who}: force_record_weights() = {record}; it needs n_stages + 1 = {n_stages + 1} "
                            "finite weights (lambda_n, then each stage's) summing to 1")
    _check_consistency(who, stages, A, dt)
    if integrator.stability_limit(dt) is None:
        _check_unconditional(who, integrator.stages(1.0), A)


def _check_unconditional(who, stages, n_slots):
    """Raise an AnalysisError unless ``stages`` (of Δt = 1 s) keep the undamped oscillator's
    spectral radius <= 1 at every Ω = ωΔt of :data:`UNCONDITIONAL_OMEGA_DT`, as a scheme whose
    ``stability_limit`` is None (unconditionally stable) must: an explicit scheme or a Wilson-θ
    with θ < 1.37 that claims it would diverge in the analysis. Each amplification matrix is
    taken in the scaled state (Ω² u, Ω v, a), where its entries are of order 1."""
    omega = UNCONDITIONAL_OMEGA_DT
    m = len(omega)
    bank = np.zeros((n_slots, 3 * m))
    bank[:3] = np.tile(np.eye(3), m)
    out = oscillator_step(stages, bank, np.repeat(omega ** 2, 3), 0.0, np.zeros(3 * m))[n_slots - 3:]
    amp = out.reshape(3, m, 3).transpose(1, 0, 2)             # (m, 3, 3): Ω's matrix, rows u, v, a
    scale = np.stack([omega ** 2, omega, np.ones(m)], axis=1)  # S A S⁻¹, S = diag(Ω², Ω, 1)
    radius = np.abs(np.linalg.eigvals(scale[:, :, None] * amp / scale[:, None, :])).max(axis=1)
    unstable = np.flatnonzero(~(radius <= 1.0 + 1e-6))         # (NaN: unstable too)
    if unstable.size:
        j = unstable[0]
        raise AnalysisError(f"{who}: stability_limit(dt) is None (unconditionally stable), but its spectral radius "
                            f"at omega dt = {omega[j]:.3g} is {radius[j]:.6g} > 1 (the first of {len(omega)} values "
                            f"from {omega[0]:g} to {omega[-1]:g} where it exceeds 1): it diverges there; return the "
                            "largest stable omega dt from stability_limit (central difference: 2)")


def _slot_name(slot):
    """``'u of stage 2'`` for slot 6 (``'u_n'`` .. for 0..2)."""
    what = "uva"[slot % 3]
    return f"{what}_n" if slot < 3 else f"{what} of stage {slot // 3}"


MOTIONS = ("the static equilibrium u = P/K, v = a = 0 under a constant load P",
           "the constant-velocity motion u = V t of a body without stiffness under the damping force P = C V")


def _check_consistency(who, stages, n_slots, dt):
    """Contract item 8 on the oscillator ``ü + c u̇ + k u = p`` with ``c = 1/Δt``: each stage must
    keep ``u = 1`` at rest under ``p = k = 1/Δt²`` and move ``u = V t`` (``V = 1/Δt``) under
    ``p = c V`` with ``k = 0`` (values of order 1 in units of Δt); both motions are the two columns
    of one :func:`oscillator_step`. The first failure (motion, stage, then u, v, a) is named."""
    c = 1.0 / dt
    bank = np.zeros((n_slots, 2))
    bank[0, 0], bank[1, 1] = 1.0, c               # u_n = 1 at rest; v_n = V = 1/Δt from u_n = 0
    oscillator_step(stages, bank, np.array([c * c, 0.0]), c, np.array([c * c, c * c]))
    # (stage, u v a, motion): u = 1 and u = V θ Δt = θ, v = 0 and V, a = 0, scaled by 1, Δt, Δt²
    expected = np.array([[[1.0, float(st.theta)], [0.0, c], [0.0, 0.0]] for st in stages])
    got = bank[3:].reshape(expected.shape)
    ok = (np.abs(got - expected) * np.array([[1.0], [dt], [dt * dt]]) <= CONSISTENCY_TOL).transpose(2, 0, 1)
    if ok.all():
        return
    m, s, q = np.unravel_index(int(np.argmin(ok)), ok.shape)          # motion, stage, u v a
    got, expected = got.transpose(2, 0, 1), expected.transpose(2, 0, 1)
    raise AnalysisError(
        f"{who}: stage {s + 1} of {len(stages)} does not keep {MOTIONS[m]} (dt = {dt:g} s): its {'uva'[q]} is "
        f"{got[m, s, q]:.10g} where the motion has {expected[m, s, q]:.10g} at the stage's end time theta = "
        f"{stages[s].theta:g}; check its update coefficients du, dv, its equation's ku, kv, km against its load "
        "weights, and its theta")


def number(integrator, name, value):
    """``float(value)``, or an AnalysisError naming the integrator and the parameter (a bool is
    not taken for 1 or 0: ``Newmark(True, True)`` was γ = β = 1; nor a text for its number:
    ``Newmark(beta='0.25')`` ran; :func:`~vtsi.errors.as_number`)."""
    return as_number(value, f"integrator {integrator}", name, AnalysisError)


def check_parameter(integrator, name, value, low, high, low_open=False, high_open=False, why=""):
    """Raise an AnalysisError unless ``low <= value <= high`` (open ends as flagged)."""
    ok = (value > low if low_open else value >= low) and (value < high if high_open else value <= high)
    if not (np.isfinite(value) and ok):
        lo, hi = ("(" if low_open else "["), (")" if high_open else "]")
        raise AnalysisError(f"integrator {integrator}: {name} = {value:g} is outside {lo}{low:g}, {high:g}{hi}"
                            + (f" ({why})" if why else ""))

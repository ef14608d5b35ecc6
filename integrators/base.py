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

Contract of an integrator (checked by ``tests/test_integrator_contract.py``)
-----------------------------------------------------------------------------
1. ``name`` (str) and ``n_stages`` (int) class attributes; register with :func:`register`.
2. ``stages(dt)`` returns ``n_stages`` :class:`Stage` objects; coefficient arrays have length
   ``n_slots + 1`` with ``n_slots = 3 + 3 n_stages`` (``km[A] = 0``), and a stage only reads
   slots already written.
3. ``stability_limit(dt)``: ``None`` if unconditionally stable, else the largest stable
   ``ω Δt`` (undamped); the analysis compares it with ``ω_max Δt`` and refuses to run beyond it.
4. ``explicit``: True when ``ku[A] = 0`` in every stage, so that ``K̂ = M + kv[A] C`` holds no
   stiffness (``K̂ = M`` for an undamped model; central difference has ``kv[A] = Δt/2``).
5. Parameters are validated in ``__init__`` with an :class:`~vtsi.errors.AnalysisError`
   naming the integrator, the parameter and its stable range.
6. Each stage's ``force_weight`` ω lies in ``(0, 1 + Σ km]``: a coupled analysis weights the
   stage's own constraint forces by ω and the step start's by ``1 + Σ km − ω`` (>= 0).

From the stages alone the base class gives :meth:`Integrator.amplification` (the step's 3×3
amplification matrix on an oscillator), :meth:`Integrator.spectral_radius` and
:attr:`Integrator.dissipative` (whether the highest frequencies are damped: a coupled analysis
with contact='lcp' needs it, and the design check reads wheel unloading only with it or with
smoothed rows).
"""
import inspect
import re
from dataclasses import dataclass, field

import numpy as np

from vtsi.errors import AnalysisError

INTEGRATORS = {}
HIGH_OMEGA_DT = 1e4   # Ω = ωΔt where :attr:`Integrator.dissipative` reads the spectral radius


def register(cls):
    for attribute in ("name", "n_stages"):
        if getattr(cls, attribute, None) is None:
            raise TypeError(f"integrator {cls.__name__}: missing class attribute {attribute!r}")
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
    """The numbers of ``'0.9, gamma=0.6'``: ``([0.9], {'gamma': 0.6})``, or an AnalysisError."""
    args, kwargs = [], {}
    for part in filter(None, (p.strip() for p in text.split(","))):
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
        raise NotImplementedError

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
        k, c = omega ** 2, 2.0 * xi * omega
        n = self.n_slots
        bank = np.zeros((n, 3))
        bank[:3] = np.eye(3)
        for s, st in enumerate(self.stages(dt)):
            a = -(st.km[:n] @ bank + c * st.kv[:n] @ bank + k * st.ku[:n] @ bank) / (1.0 + c * st.kv[n] + k * st.ku[n])
            bank[3 + 3 * s] = st.du[:n] @ bank + st.du[n] * a
            bank[4 + 3 * s] = st.dv[:n] @ bank + st.dv[n] * a
            bank[5 + 3 * s] = a
        return bank[n - 3:]

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


def number(integrator, name, value):
    """``float(value)``, or an AnalysisError naming the integrator and the parameter."""
    try:
        return float(value)
    except (TypeError, ValueError):
        raise AnalysisError(f"integrator {integrator}: {name} must be a number, got {value!r}") from None


def check_parameter(integrator, name, value, low, high, low_open=False, high_open=False, why=""):
    """Raise an AnalysisError unless ``low <= value <= high`` (open ends as flagged)."""
    ok = (value > low if low_open else value >= low) and (value < high if high_open else value <= high)
    if not (np.isfinite(value) and ok):
        lo, hi = ("(" if low_open else "["), (")" if high_open else "]")
        raise AnalysisError(f"integrator {integrator}: {name} = {value:g} is outside {lo}{low:g}, {high:g}{hi}"
                            + (f" ({why})" if why else ""))

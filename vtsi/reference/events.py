"""Reference solution with contact loss: one wheel that may leave the rail and land again.

The motion alternates between two smooth phases, each integrated with
:func:`scipy.integrate.solve_ivp` (DOP853 by default) and ended by a terminal event:

- **in contact**: the constraint-elimination ODE of R1 (:mod:`vtsi.reference.elimination`),
  the wheel dof eliminated (u_w = N u_b + r); λ(t) from the wheel row of the train equations.
  Event λ = 0, crossed downwards: **lift-off**.
- **in flight**: bridge and train unconstrained, each on its own (λ = 0); event gap
  g = u_w − N u_b − r = −ε, crossed downwards: **landing** (ε = 100 × atol [m] keeps the
  event from firing on round-off right after a lift-off, where g starts like (t − t_0)³; it
  shifts the landing by ε/|ġ|).

**Landing is a perfectly inelastic impact** at the position level (the wheel's vertical
velocity becomes that of the rail under it, N u̇_b + V N' u_b + V r'). The impulse ι ≥ 0 acts
on the wheel (up) and on the bridge (−Nᵀι, down); momentum balance and the velocity condition

    M_t Δu̇_t = Sᵀ ι,    M_b Δu̇_b = −Nᵀ ι,    S u̇_t⁺ − N u̇_b⁺ − V N' u_b − V r' = 0

give (1/m_w + N M_b⁻¹ Nᵀ) ι = −ġ⁻ (for a diagonal train mass; in general
(S M_t⁻¹ Sᵀ + N M_b⁻¹ Nᵀ) ι = −ġ⁻), the closing speed. It is the same impulse law that R1
applies at its restarts: Bᵀ M B ẏ⁺ = Bᵀ M (u̇⁻ − Ḃ y − ḃ)
(:meth:`vtsi.reference.elimination.Phase.reduce`), which minimises the kinetic energy of
the velocity change among the velocities that satisfy the constraint, i.e. a perfectly
inelastic (plastic) impact. Kinetic energy lost: ½ ι (−ġ⁻).

**Kinks of the rail line** (span entry and exit, irregularity breaks) are restarts as in R1:
in contact, the bilateral impulse law is tried; if it needs a tensile impulse (ι < 0: the rail
falls away faster than the wheel can follow) the wheel leaves the rail there instead, with its
velocity unchanged (a lift-off event at the kink).

The wheel needs a mass (a massless contact point cannot fly). Events are returned as
``(kind, time [s], position [m])`` with kind 'lift-off' or 'landing'; landings also list their
impulse in ``impulses``.
"""
import numpy as np

from vtsi.errors import AnalysisError, ModelError
from vtsi.reference.elimination import (IMPULSE_THRESHOLD, CoupledSystem, Phase, _check_times, _Histories,
                                        dead_load, integrate_segment)
from vtsi.vehicle import GRAVITY


def solve_single_wheel(model, constraint, t_end, t_eval=None, rtol=1e-10, atol=None, method="DOP853",
                       bridge_self_weight=False, gravity=GRAVITY, irregularity_breaks=(), max_events=1000):
    """One wheel (a moving mass, or a car with one wheel of nonzero mass) on a bridge or on rigid
    ground (``model=None`` with :class:`~vtsi.reference.elimination.RigidGround`), with lift-off
    and landing (module docstring).

    Parameters as :func:`vtsi.reference.elimination.solve`; ``method`` is a solve_ivp method
    (events need it: 'DOP853' default, 'Radau' ...); ``max_events`` guards against chattering.

    Returns
    -------
    ReferenceSolution with extra attributes ``events`` (list of (kind, time, position)),
    ``gap`` (n_t,) [m] and ``in_contact`` (n_t,) bool; ``contact_force`` is 0 in flight.
    """
    t_end, t_eval = _check_times(t_end, t_eval)
    method = "DOP853" if method == "dop853" else method
    s = CoupledSystem(model, constraint, bridge_self_weight, gravity, irregularity_breaks)
    if s.n_c != 1:
        raise ModelError(f"solve_single_wheel: the train must have exactly one contact wheel, it has {s.n_c}")
    w = s.wheel_dofs[0]
    if not s.M_t[w, w] > 0:
        raise ModelError("solve_single_wheel: the wheel has no mass; a massless contact point cannot leave the rail")
    bounds = s.breakpoints(t_end)
    u_b, u_t, lam0 = dead_load(s, 0.5 * (bounds[0] + bounds[1]))
    if lam0[0] < 0:
        raise AnalysisError(f"solve_single_wheel: the wheel pulls on the rail at rest (λ = {lam0[0]:g} N)")
    dead = (u_b.copy(), u_t.copy(), lam0)
    if atol is None:
        atol = s.default_atol(rtol, np.concatenate([u_b, u_t]))
    eps = 100.0 * float(np.max(atol))
    v_b, v_t = np.zeros(s.n_b), np.zeros(s.n_t)
    out = _Histories(len(t_eval), s)
    gap, in_contact = np.zeros(len(t_eval)), np.zeros(len(t_eval), dtype=bool)
    events, impulses, stats = [], [], {"segments": len(bounds) - 1}
    contact, start = True, True
    x_of = lambda t: float(s.x0[0] + s.V * t)
    for k, (ta, tb) in enumerate(zip(bounds[:-1], bounds[1:])):
        last = k == len(bounds) - 2
        t = ta
        while True:
            phase = Phase(s, 0.5 * (ta + tb), active=[contact])
            if start:
                y, yd = np.concatenate([u_b, u_t[phase.o]]), np.zeros(phase.n_y)
                start = False
            elif contact:
                y, yd = phase.reduce(t, u_b, v_b, u_t, v_t)
                iota = _impulse(s, phase, t, y, yd, v_t)
                if iota < -IMPULSE_THRESHOLD * s.load_scale:
                    # the rail falls away at a kink: the wheel leaves it with its velocity
                    events.append(("lift-off", float(t), x_of(t)))
                    contact = False
                    continue
                if abs(iota) > IMPULSE_THRESHOLD * s.load_scale:
                    impulses.append((float(t), 0, float(iota)))
                if phase.accel(t, y, yd)[1][0] < 0:     # lands (or sits) where it cannot stay
                    events.append(("lift-off", float(t), x_of(t)))
                    contact = False
                    u_b, v_b, _, u_t, v_t, _, _ = phase.full(t, y, yd)   # it leaves with the impact's velocities
                    continue
            else:
                y, yd = phase.reduce(t, u_b, v_b, u_t, v_t)
            idx = np.flatnonzero((t_eval >= t) & ((t_eval < tb) | (last & (t_eval <= tb))))
            times = np.unique(np.concatenate([t_eval[idx], [tb]]))
            event = _lift_off_event(phase) if contact else _landing_event(s, phase, eps)
            sol_t, sol_y, hit = integrate_segment(phase, t, tb, phase.pack(y, yd), times, method, rtol, atol,
                                                  stats, events=[event])
            for j, tj in enumerate(sol_t):
                if hit is not None and j == len(sol_t) - 1:
                    break
                i = np.searchsorted(t_eval, tj)
                if i < len(t_eval) and t_eval[i] == tj and i in idx:
                    yj, ydj = phase.unpack(sol_y[:, j])
                    ydd, lam = phase.accel(tj, yj, ydj)
                    out.store(i, phase.full(tj, yj, ydj, ydd), phase.aw, lam)
                    gap[i] = 0.0 if contact else _gap(s, phase, tj, yj)
                    in_contact[i] = contact
            y, yd = phase.unpack(sol_y[:, -1])
            t_now = float(sol_t[-1])
            u_b, v_b, _, u_t, v_t, _, _ = phase.full(t_now, y, yd)
            if hit is None:
                break
            t = t_now
            events.append(("lift-off" if contact else "landing", t, x_of(t)))
            contact = not contact
            if len(events) > max_events:
                raise AnalysisError(f"solve_single_wheel: more than {max_events} contact events by t = {t:.6g} s "
                                    "(chattering?)")
    sol = out.result(t_eval, impulses, s, dead, bounds, stats)
    sol.events, sol.gap, sol.in_contact = events, gap, in_contact
    return sol


def _impulse(s, phase, t, y, yd, v_t_before):
    """Impulse ι [N·s] on the wheel of the velocity change from v_t_before to the phase's state."""
    v_t = phase.full(t, y, yd)[4]
    return float((s.M_t @ (v_t - v_t_before))[phase.w][0])


def _gap(s, phase, t, y):
    """g = u_w − N u_b − r of the (inactive) wheel [m]."""
    x = s.x0 + s.V * t
    N, _, _ = s.rows(x, *phase.c_data)
    u_w = y[s.n_b + int(np.flatnonzero(phase.o == s.wheel_dofs[0])[0])]
    return float(u_w - N[0] @ y[: s.n_b] - s.profile(x, 0)[0])


def _lift_off_event(phase):
    def event(t, z):
        y, yd = phase.unpack(z)
        return phase.accel(t, y, yd)[1][0]
    event.terminal, event.direction = True, -1
    return event


def _landing_event(s, phase, eps):
    def event(t, z):
        y, _ = phase.unpack(z)
        return _gap(s, phase, t, y) + eps
    event.terminal, event.direction = True, -1
    return event

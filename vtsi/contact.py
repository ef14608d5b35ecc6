"""Wheel-rail contact state of a coupled analysis: flags, lift-off and landing events, summary.

Works on the step records of a :class:`~vtsi.coupled.CoupledAnalysis` (``time``,
``contact_force``, ``gap``) or on the same arrays from a recorder. Definitions (per contact
wheel i and step k, times t_k at the end of each step):

- **in contact**: ``gap[k, i] <= gap_tol`` (the analysis's ``gap_tol``, 1e-9 m by default).
  A wheel is *in flight* otherwise. Before the first recorded step every wheel is taken to be
  on the rail (an analysis starts from the dead-load equilibrium) unless ``initial`` says
  otherwise.
- **lift-off** at step k: in flight at t_k, in contact at t_{k-1}. Lift-off is the instant
  the contact force vanishes; the gap opens only after it, and slowly (like (t - t*)³: zero
  relative velocity and acceleration at t*), so the wheel often sits a few steps on the rail
  with λ = 0 ("touching") before its gap exceeds ``gap_tol``. Let j be the last step before k
  with λ_j > 0 (only touching steps between j and k): the force vanished in (t_j, t_{j+1}].
  With ``interpolate`` the event time is where the straight line through (t_{j-1}, λ_{j-1})
  and (t_j, λ_j) reaches zero, clamped to [t_j, t_{j+1}] (λ_j the end of step's force
  ``contact_force_end``: a multi-stage scheme's record is its step mean, Bathe's
  (λ_n + λ_γ + λ_{n+1})/3): λ(t) is smooth up to lift-off and
  falls to zero with a non-zero slope, so the root is O(Δt²) from the true one. Where λ is
  not falling there (a time-stepping artefact, e.g. the undamped period-2Δt ringing of the
  trapezoidal rule), t_{j+1}; without any such j, t_k.
- **landing** at step k: in contact at t_k, in flight at t_{k-1}. With ``interpolate``, the
  first root in (t_{k-1}, t_k] of the parabola through the last three flight gaps
  (t_{k-3..k-1}) (a straight line through two if the flight lasted two steps); in flight the gap
  is a smooth function of time (the wheel moves under smooth forces, the rail profile is
  smooth), so the extrapolated root is O(Δt³) from the true one when the wheel comes down with
  a non-zero relative velocity. Without a root there (grazing landing) or after a one-step
  flight, the step time t_k.
- **position** of an event: x = x_0 + V t at the event time (the wheel's position on the line).

Summary per wheel (:func:`contact_summary`):

- ``separations``: number of lift-offs;
- ``longest_flight`` [s]: longest landing time - lift-off time (a flight still open at the
  end counts up to the last recorded time);
- ``min_force``, ``max_force`` [N]: extreme contact forces over the steps (0 in flight; a
  landing step carries the impact spread over one step, see docs/theory/contact.md);
- ``static_load`` Q [N]: the static wheel load on rigid level ground
  (``Train.static_wheel_loads`` of the contact wheels);
- ``unloading_ratio`` ΔQ/Q = max over the steps of (Q - λ)/Q: 1 for a wheel that left the
  rail, > 1 only for a bilateral analysis, whose λ may go negative (tension);
- ``in_contact_at_end``.
"""
from dataclasses import dataclass

import numpy as np

from vtsi.errors import AnalysisError, as_positive

LIFT_OFF = "lift-off"
LANDING = "landing"
MAX_GAP_TOL = 1e-6
"""[m] The largest ``gap_tol`` accepted: a wheel at most gap_tol above the rail is put back on it,
so the tolerance is a round-off guard and must stay far below the smallest lift-off of interest
(0.1 mm). Measured (a four-dof car over a 20 mm, 1 m dip at 60 m/s, HHT(0.9), Δt = 0.25 ms): with
1e-6 m its wheels' flights of 0.067 and 0.090 mm start and peak as with 1e-9 m; with 1e-5 m they
start a step late and peak 10 % and 8 % lower."""


def gap_tolerance(value, where, error):
    """``value`` as a gap tolerance [m], 0 to :data:`MAX_GAP_TOL`, or ``error`` naming ``where``
    and the value (the analysis's flight criterion and a recorder's in-contact flag alike)."""
    gap_tol = as_positive(value, where, "gap_tol [m]", error, allow_zero=True)
    if gap_tol > MAX_GAP_TOL:
        raise error(f"{where}: gap_tol [m] must be at most {MAX_GAP_TOL:g} m, got {value!r}: a wheel less than "
                    "gap_tol above the rail is put back on it, so a larger one hides and delays lift-offs")
    return gap_tol


@dataclass(frozen=True)
class ContactEvent:
    """A lift-off or a landing of one contact wheel.

    Attributes
    ----------
    kind : 'lift-off' or 'landing'.
    wheel : contact-wheel index (column of ``contact_force``).
    step : index into the records of the first step in the new state.
    time : event time [s] (interpolated within the step, see the module docstring).
    position : wheel position x at ``time`` [m].
    """

    kind: str
    wheel: int
    step: int
    time: float
    position: float


@dataclass(frozen=True)
class ContactSummary:
    """Per-wheel summary of a run (arrays of shape (n_c,)); see the module docstring."""

    separations: np.ndarray
    longest_flight: np.ndarray
    total_flight: np.ndarray
    min_force: np.ndarray
    max_force: np.ndarray
    static_load: np.ndarray
    unloading_ratio: np.ndarray
    in_contact_at_end: np.ndarray

    def table(self):
        """The summary as a text table, one row per wheel; after a landing, a line saying that its
        max force is the impact's impulse over one step (it scales with 1/Δt)."""
        head = f"{'wheel':>5}  {'separations':>11}  {'longest flight [s]':>18}  {'min force [kN]':>14}  " \
               f"{'max force [kN]':>14}  {'ΔQ/Q':>6}  {'on rail at end':>14}"
        rows = [head, "-" * len(head)]
        for i in range(len(self.separations)):
            rows.append(f"{i:5d}  {self.separations[i]:11d}  {self.longest_flight[i]:18.5f}  "
                        f"{self.min_force[i] / 1e3:14.2f}  {self.max_force[i] / 1e3:14.2f}  "
                        f"{self.unloading_ratio[i]:6.3f}  {str(bool(self.in_contact_at_end[i])):>14}")
        if np.any(self.separations):
            rows.append("max force of a wheel that landed: its landing impact's impulse over one step (it scales with "
                        "1/dt; quote the impulse, docs/theory/contact.md)")
        return "\n".join(rows)


def _records(analysis):
    time = np.asarray(analysis.time, dtype=float)
    force = np.asarray(analysis.contact_force, dtype=float)
    gap = np.asarray(analysis.gap, dtype=float)
    if force.shape != gap.shape or force.shape[0] != time.shape[0]:
        raise AnalysisError(f"contact results: time {time.shape}, contact_force {force.shape} and gap {gap.shape} "
                            "do not match")
    return time, force, gap


def contact_state(gap, gap_tol=1e-9):
    """In-contact flags (bool, same shape as ``gap``): ``gap <= gap_tol``."""
    return np.asarray(gap, dtype=float) <= gap_tol


def _lift_off_time(time, force, flags, k, i):
    """Lift-off before the flight that starts at step k (see the module docstring)."""
    j = k - 1
    while j >= 0 and flags[j, i] and force[j, i] == 0.0:     # touching: on the rail, no force
        j -= 1
    if j < 0 or not flags[j, i]:
        return time[k]
    hi = time[j + 1]
    if j < 1:
        return hi
    t1, t2 = time[j - 1], time[j]
    f1, f2 = force[j - 1, i], force[j, i]
    if not f1 > f2 > 0.0:
        return hi
    t = t2 + (t2 - t1) * f2 / (f1 - f2)
    return float(min(max(t, t2), hi))


def _landing_time(time, gap, k, i, n_flight):
    """Landing between t_{k-1} and t_k from the last flight gaps (see the module docstring)."""
    lo, hi = time[k - 1], time[k]
    m = min(n_flight, 3)
    if k < 1 or m < 2:
        return hi
    ts, gs = time[k - m: k], gap[k - m: k, i]
    coef = np.polyfit(ts - hi, gs, m - 1)
    roots = np.roots(coef)
    roots = roots[np.isreal(roots)].real + hi
    roots = roots[(roots > lo) & (roots <= hi)]
    return float(roots.min()) if len(roots) else hi


def find_events(time, contact_force, gap, positions, gap_tol=1e-9, initial=None, interpolate=True):
    """Lift-off and landing events from step records (the work of :func:`contact_events`).

    Parameters
    ----------
    time : (n_steps,) step end times [s].
    contact_force, gap : (n_steps, n_c) [N], [m].
    positions : callable t -> (..., n_c) wheel positions [m] (``MovingLoadConstraint.positions``).
    gap_tol : [m].
    initial : (n_c,) bool contact state before the first record (default: all on the rail).
    interpolate : locate the event times within their steps (else the step times).

    Returns
    -------
    list of ContactEvent, sorted by time (then wheel).
    """
    time = np.asarray(time, dtype=float)
    force = np.asarray(contact_force, dtype=float)
    gap = np.asarray(gap, dtype=float)
    n_steps, n_c = gap.shape
    flags = contact_state(gap, gap_tol)
    before = np.ones(n_c, bool) if initial is None else np.asarray(initial, bool)
    events = []
    for i in range(n_c):
        state = np.concatenate([[before[i]], flags[:, i]])
        changes = np.flatnonzero(state[1:] != state[:-1])
        flight_start = None
        for k in changes:
            if state[k]:            # contact -> flight at step k
                t = _lift_off_time(time, force, flags, k, i) if interpolate else time[k]
                kind, flight_start = LIFT_OFF, k
            else:                   # flight -> contact at step k
                n_flight = k - flight_start if flight_start is not None else k
                t = _landing_time(time, gap, k, i, n_flight) if interpolate else time[k]
                kind = LANDING
            x = float(np.asarray(positions(np.array(t)))[..., i])
            events.append(ContactEvent(kind, i, int(k), float(t), x))
    events.sort(key=lambda e: (e.time, e.wheel))
    return events


def contact_events(analysis, interpolate=True, initial=None):
    """Lift-off and landing events of a :class:`~vtsi.coupled.CoupledAnalysis` run (its
    ``time``, ``contact_force``, ``gap``, ``gap_tol`` and wheel positions); see
    :func:`find_events` and the module docstring for the definitions."""
    time, force, gap = _records(analysis)
    return find_events(time, np.asarray(analysis.contact_force_end, dtype=float), gap, analysis.constraint.positions,
                       analysis.gap_tol, initial, interpolate)


def summarize(events, time, contact_force, gap, static_load, gap_tol=1e-9):
    """:class:`ContactSummary` from step records and their events (see the module docstring)."""
    time = np.asarray(time, dtype=float)
    force = np.asarray(contact_force, dtype=float)
    n_c = force.shape[1]
    static_load = np.asarray(static_load, dtype=float)
    if static_load.shape != (n_c,) or not np.all(static_load > 0):
        raise AnalysisError(f"contact summary: static wheel loads must be {n_c} positive numbers, got {static_load}")
    separations = np.zeros(n_c, dtype=np.int64)
    longest = np.zeros(n_c)
    total = np.zeros(n_c)
    start = [None] * n_c
    for e in events:
        if e.kind == LIFT_OFF:
            separations[e.wheel] += 1
            start[e.wheel] = e.time
        elif start[e.wheel] is not None:
            duration = e.time - start[e.wheel]
            longest[e.wheel] = max(longest[e.wheel], duration)
            total[e.wheel] += duration
            start[e.wheel] = None
    end = time[-1] if len(time) else 0.0
    for i in range(n_c):
        if start[i] is not None:            # still in flight at the end
            longest[i] = max(longest[i], end - start[i])
            total[i] += end - start[i]
    if len(time):
        min_force, max_force = force.min(axis=0), force.max(axis=0)
        ratio = ((static_load - force) / static_load).max(axis=0)
        at_end = contact_state(np.asarray(gap, dtype=float)[-1], gap_tol)
    else:
        min_force = max_force = ratio = np.full(n_c, np.nan)
        at_end = np.ones(n_c, bool)
    return ContactSummary(separations, longest, total, min_force, max_force, static_load, ratio, at_end)


def contact_summary(analysis, static_load=None, events=None, interpolate=True):
    """Per-wheel :class:`ContactSummary` of a :class:`~vtsi.coupled.CoupledAnalysis` run.

    ``static_load`` (n_c,) [N] defaults to the static wheel loads of the train's contact wheels
    on rigid level ground; ``events`` to :func:`contact_events` of the analysis.
    """
    time, force, gap = _records(analysis)
    if static_load is None:
        train = analysis.constraint.train
        static_load = np.asarray(train.train.static_wheel_loads)[train.contact_wheels]
    if events is None:
        events = contact_events(analysis, interpolate=interpolate)
    return summarize(events, time, force, gap, static_load, analysis.gap_tol)

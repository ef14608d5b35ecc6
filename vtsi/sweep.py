"""Speed sweeps: every train of a list at every speed of a range (and every rail sample), on any
``concurrent.futures.Executor``, into one resumable HDF5 results file (docs/sweeps.md).

    sweep = Sweep(bridge, ["HSLM-A1", "HSLM-A2", "ICE3"], speeds("140:420:5"),
                  PassageSettings(dt=2e-3, damping=0.012))
    results = sweep.run("hslm.h5")            # all cores; workers=1: serial; executor=...: any
    print(results.summary())

The bridge is built and factored once per sweep (in the calling process, before any passage
is dispatched); each task carries that prepared bridge to its worker, and each passage starts
from the bridge's rest state (:class:`~vtsi.passage.PassageRunner`). Cases are grouped into
tasks of about ``TASK_STEPS`` time steps, so that dispatching a task costs well under 5 % of
running it, and of at most ``TASK_HISTORY_BYTES`` of time histories (:meth:`Sweep.tasks`).
Results are written by the calling process as each task completes, atomically
(:mod:`vtsi.sweep_results`): a sweep killed at any moment loses only the tasks that were
running, and ``resume=True`` runs only what is missing.

Speeds are km/h at this surface (``speeds``, ``en_speed_grid``); the passages run in m/s.
"""
import hashlib
import logging
import math
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import time
import types
from concurrent.futures import FIRST_COMPLETED, BrokenExecutor, Executor, ProcessPoolExecutor, wait
from dataclasses import dataclass
from decimal import Context, Decimal
from fractions import Fraction
from functools import partial
from multiprocessing.reduction import ForkingPickler

import numpy as np
from threadpoolctl import threadpool_limits
from tqdm.auto import tqdm

from vtsi.codes.en1991_2 import SPEED_SERIES_START_KMH
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis
from vtsi.errors import (BridgeError, BridgeModelError, BridgeSweepError, ModelError, PassageError, SettingError,
                         SweepError, VtsiError, is_int)
from vtsi.model import Model
from vtsi.models.bridges import continuous_beam
from vtsi.models.catalogue import describe, train_names
from vtsi.passage import (DEFAULT_OUTPUTS, HISTORY_OUTPUTS, Output, PassageRunner, PassageSettings, dt_resolving,
                          modal_basis_hz, rail_frequency_hz, resolves, step_error_text, step_ratio, step_rule_text)
from vtsi.signature import HARMONICS
from vtsi.sweep_results import (ResultsWriter, canonical_train_name, case_key, cases_text, seeds_text, speed_index,
                                 train_fingerprint)
from vtsi.track_ends import free_end_text
from vtsi.train import TrainSubdomain
from vtsi.units import MAX_MASS_PER_METRE, MIN_MASS_PER_METRE, deck_mass_per_length
from vtsi.vehicle import MAX_TRAIN_SPEED

log = logging.getLogger(__name__)

TASK_STEPS = 200_000        # time steps per task (about 0.2-1 s of work)
MAX_SEEDS = 10_000          # rail samples of a sweep at most
MAX_SPEEDS = 10_000
"""Speeds of a sweep at most: 10 000 of them cover every speed a train reaches (up to 720 km/h)
0.072 km/h apart, far finer than a resonance of a damped deck (its peak is about 2ζ·v wide: 3 km/h
at 300 km/h and ζ = 0.5 %; EN 1991-2 §6.4.6.2 steps 10 km/h, 2 km/h near one), so more is a typo
('200:300:0.001': 100 001 passages, which ran 9 minutes before they were stopped)."""
WORKER_GRACE_S = 5.0        # [s] a stopped pool's workers have to exit once their tasks ended, then are ended
CAR_STEP_COST = 8.0         # a coupled step of cars in steps of moving forces (measured: ICE3's 32 wheels 20-31 µs,
                            # HSLM-A1's 50 axles 4 µs, on a 20 m span of 10 elements): tasks of cars last as long
EXACT_SAMPLE_COST = 0.02    # an exact modal passage's output sample against a FE time step (S4: ~0.02 µs vs ~1 µs)
TASK_HISTORY_BYTES = 128 * 2 ** 20
"""[B] The time histories (``history=True`` outputs, float64) a task's cases hold at most, as
counted case by case by :meth:`Sweep.history_bytes` (:meth:`Sweep.tasks`; a case above it alone
is a task of its own): a task keeps its histories until the calling process writes them, and
every write rewrites the whole file (docs/sweeps.md, "Memory"). Measured on 60
exact modal passages of HSLM-A7 over 10 × 30 m keeping the deck accelerations (14.5 MB each, a
560 MB file): tasks of 32, 64, 128, 256 MB and all in one ran 50, 35, 26, 25 and 23 s, peaking at
1.36, 1.39, 1.51, 1.56 and 2.58 GB; 128 MB costs 14 % of time and little memory over smaller
tasks, whose more frequent rewrites of the file cost more time."""


# -- speeds ------------------------------------------------------------------------------------
def speeds(spec):
    """Speeds [km/h] from ``'START:STOP:STEP'`` (STOP included when it falls on the grid),
    ``'v1,v2,...'``, a number or a sequence of numbers. Every speed must be > 0 and finite, and
    at most MAX_SPEEDS of them."""
    if isinstance(spec, str):
        text = spec.strip()
        try:
            parts = [float(p) for p in text.split(":")] if ":" in text else None
            values = None if parts else np.array([float(p) for p in text.replace(";", ",").split(",") if p.strip()])
        except ValueError:
            parts, values = [], None
        if parts is not None and len(parts) != 3 or values is None and parts is None:
            raise SweepError(f"speeds {spec!r}: expected START:STOP:STEP or a comma-separated list [km/h]")
        if parts:
            for name, value in zip(("start", "stop", "step"), parts):
                if not math.isfinite(value):
                    raise SweepError(f"speeds {spec!r}: the {name} must be finite, got {value:g} km/h")
            start, stop, step = parts
            if not step > 0:
                raise SweepError(f"speeds {spec!r}: the step must be > 0 km/h, got {step:g}")
            if stop < start:
                raise SweepError(f"speeds {spec!r}: empty range (stop {stop:g} < start {start:g} km/h)")
            quotient = (stop - start) / step
            if math.isfinite(quotient):
                count = math.floor(quotient + 1e-9) + 1
                shown = f"{float(count):.6g}"
            else:               # a step below ~1e-308 of the range: more speeds than a float holds
                count = math.floor((Fraction(stop) - Fraction(start)) / Fraction(step)) + 1
                shown = f"{Decimal(count).normalize(Context(prec=6)):g}"
            if count > MAX_SPEEDS:
                raise SweepError(f"speeds {spec!r}: a step of {step:g} km/h makes {shown} speeds, more than "
                                 f"{MAX_SPEEDS} (MAX_SPEEDS: every speed a train reaches, 0.072 km/h apart); EN 1991-2 "
                                 "6.4.6.2 steps 10 km/h, 2 km/h near a resonance")
            values = start + step * np.arange(count)
    else:
        try:
            values = np.atleast_1d(np.asarray(spec, dtype=float)).ravel()
        except (TypeError, ValueError):
            raise SweepError(f"speeds: expected numbers [km/h], got {spec!r}") from None
    if values.size == 0:
        raise SweepError(f"speeds {spec!r}: no speed")
    bad = values[~(np.isfinite(values) & (values > 0))]
    if bad.size:
        raise SweepError(f"speeds: every speed must be > 0 km/h and finite, got {bad[0]:g}")
    if values.max() > 3.6 * MAX_TRAIN_SPEED:
        raise SweepError(f"speeds: {values.max():g} km/h is faster than any train (at most "
                         f"{3.6 * MAX_TRAIN_SPEED:g} km/h)")
    values = np.unique(np.round(values, 9))
    if values.size > MAX_SPEEDS:
        raise SweepError(f"speeds: {values.size} speeds, more than {MAX_SPEEDS} (MAX_SPEEDS: every speed a train "
                         "reaches, 0.072 km/h apart)")
    return values


def resonance_speeds(frequencies_hz, lengths_m, orders=tuple(range(1, HARMONICS + 1))):
    """v = n·D/i [km/h] for every frequency n [Hz], characteristic length D [m] and i in ``orders``
    (EN 1991-2 §6.4.6.2: λ = D/i, v = n₀ λ; by default the orders at which a train's signature
    reads its D, :data:`vtsi.signature.HARMONICS`)."""
    f = np.atleast_1d(np.asarray(frequencies_hz, dtype=float))
    D = np.atleast_1d(np.asarray([d for d in lengths_m if d], dtype=float))
    if D.size == 0:
        return np.zeros(0)
    i = np.asarray(orders, dtype=float)
    return np.unique((f[:, None, None] * D[None, :, None] / i[None, None, :]).ravel() * 3.6)


def en_speed_grid(line_speed_kmh, frequencies_hz, lengths_m, start_kmh=SPEED_SERIES_START_KMH, step_kmh=10.0,
                  fine_step_kmh=2.0, band=0.1):
    """The EN 1991-2 §6.4.6.2 speed series [km/h]: from ``start_kmh`` (40 m/s) up to 1.2 × the
    line speed in steps of ``step_kmh``, plus every resonance speed v = n·D/i
    (:func:`resonance_speeds`) in that range and steps of ``fine_step_kmh`` within ± ``band`` (a
    fraction) of it, on one lattice from ``start_kmh`` (the bands of several trains share it).
    A length None or NaN in ``lengths_m`` (a train without D, whose resonance speeds are unknown)
    makes the whole series step ``fine_step_kmh`` on that lattice. The end points are included;
    speeds are rounded to 0.01 km/h."""
    v_max = 1.2 * float(line_speed_kmh)
    if not (math.isfinite(v_max) and v_max > 0):
        raise SweepError(f"EN speed grid: the line speed must be > 0 km/h, got {line_speed_kmh!r}")
    if v_max > 3.6 * MAX_TRAIN_SPEED:
        raise SweepError(f"EN speed grid: line speed {line_speed_kmh:g} km/h: 1.2 x it = {v_max:g} km/h is faster than "
                         f"any train (at most {3.6 * MAX_TRAIN_SPEED:g} km/h)")
    if not (0 < start_kmh <= v_max):
        in_ms = (f"; if {line_speed_kmh:g} is in m/s, the line speed is {3.6 * line_speed_kmh:g} km/h"
                 if 1.2 * 3.6 * line_speed_kmh >= start_kmh else "")
        raise SweepError(f"EN speed grid: line speed {line_speed_kmh:g} km/h: 1.2 x it = {v_max:g} km/h is below "
                         f"{start_kmh:g} km/h, where the series starts"
                         f"{' (EN 1991-2 6.4.6.2(3): from 40 m/s)' if start_kmh == SPEED_SERIES_START_KMH else ''}{in_ms}")
    if not (step_kmh > 0 and fine_step_kmh > 0 and band >= 0):
        raise SweepError("EN speed grid: steps must be > 0 km/h and band >= 0")
    known = [d for d in lengths_m if d is not None and math.isfinite(d)]
    steady = fine_step_kmh if len(known) < len(lengths_m) else step_kmh     # a train without D: fine throughout
    grid = [np.arange(start_kmh, v_max + 1e-9, steady), [v_max]]
    for v in resonance_speeds(frequencies_hz, known):
        lo, hi = max(start_kmh, v * (1 - band)), min(v_max, v * (1 + band))
        if lo <= hi:     # the fine steps on one lattice from the start, so that bands share them
            first = start_kmh + math.ceil((lo - start_kmh) / fine_step_kmh - 1e-9) * fine_step_kmh
            grid.append(np.arange(first, hi + 1e-9, fine_step_kmh))
            grid.append([v] if start_kmh <= v <= v_max else [])
    return np.unique(np.round(np.concatenate(grid), 2))


# -- trains ------------------------------------------------------------------------------------
def train_list(trains):
    """Train names from ``trains`` (a comma-separated string, or a sequence of names and paths),
    catalogue names in the catalogue's spelling: case is ignored, 'A1' is 'HSLM-A1' and 'HSLM-A'
    stands for HSLM-A1 … HSLM-A10; anything else (an axle-table path) as given. The one reading
    of train names (``vtsi sweep --trains`` and :class:`Sweep`)."""
    items = trains.split(",") if isinstance(trains, str) else trains
    out = []
    for item in (str(t).strip() for t in items):
        if not item:
            continue
        if item.upper() == "HSLM-A":
            out.extend(n for n in train_names() if n.upper().startswith("HSLM-A"))
        else:
            out.append(canonical_train_name(item))
    return out


def _train_key(name):
    """What makes two of :func:`train_list`'s names one train: a file's real path (an axle table
    named 'emu.csv' and './emu.csv' is one), else the name."""
    return os.path.realpath(name) if os.path.isfile(name) else name


def _count(value, name):
    """``value`` unless it is neither None nor an integer >= 1 (a SweepError naming it)."""
    if value is not None and not (is_int(value) and value >= 1):
        raise SweepError(f"sweep: {name} must be an integer >= 1 (or None), got {value!r}")
    return value


def _seed_list(seeds):
    """``seeds`` sorted, or a SweepError naming the first bad one: integers in [0, 2⁶³) (the
    results file stores them as int64), each once, at least one and at most MAX_SEEDS."""
    if not np.iterable(seeds) or isinstance(seeds, (str, bytes)):
        raise SweepError(f"sweep: seeds must be a list of integers >= 0, got {seeds!r}")
    if not 1 <= len(seeds) <= MAX_SEEDS:
        raise SweepError(f"sweep: an irregular rail needs 1 to {MAX_SEEDS} seeds, got {len(seeds)}")
    bad = next((s for s in seeds if not (is_int(s) and 0 <= s < 2 ** 63)), None)
    if bad is not None:
        raise SweepError(f"sweep: a seed is an integer in [0, 2^63), got {bad!r}")
    seen = set()
    for seed in seeds:
        if int(seed) in seen:
            raise SweepError(f"sweep: seed {seed} is given twice")
        seen.add(int(seed))
    return sorted(seen)


# -- the bridge --------------------------------------------------------------------------------
@dataclass
class SweepBridge:
    """A bridge model for a sweep: the model, the tags of its track elements, a description
    (JSON-able dict, stored in the results; e.g. the beam's data or the script's path) and the
    ``modal_damping`` of a script: ``((frequency [Hz], ratio [-]), ...)`` that its
    ``modalDamping`` gave the modes of its ``eigen`` (:class:`~vtsi.passage.PassageRunner`).

    ``min_mass_per_metre`` [kg/m]: the lightest deck the sweep accepts
    (:func:`check_deck_mass`; 0 accepts any mass, e.g. a laboratory scale model)."""

    model: object
    track_elements: list
    description: dict
    modal_damping: tuple = ()
    min_mass_per_metre: float = MIN_MASS_PER_METRE


def check_deck_mass(model, track_elements, what, minimum=MIN_MASS_PER_METRE):
    """The deck's mass per metre of track [kg/m] (:func:`~vtsi.units.deck_mass_per_length`), or a
    :class:`~vtsi.errors.BridgeModelError` naming ``what``, the value and the likely unit slip
    when it is below ``minimum`` (:data:`~vtsi.units.MIN_MASS_PER_METRE`; 0: no lower bound; a
    model without vertical mass is told so) or above :data:`~vtsi.units.MAX_MASS_PER_METRE`: a
    deck of 15 t/m typed as ``mu=15``, or a model in kN, t, m, reads 1000 times too light, and
    the trains' loads in N would then move it 1000 times too far. The one check of a sweep's
    bridge, whichever way it came (a :func:`beam_bridge`, a user's model, a bridge file)."""
    if isinstance(minimum, bool) or not isinstance(minimum, (int, float, np.integer, np.floating)) \
            or not (math.isfinite(minimum) and minimum >= 0):
        raise SweepError(f"{what}: min_mass_per_metre must be a number >= 0 [kg/m], got {minimum!r}")
    try:
        mu = deck_mass_per_length(model, track_elements)
    except ModelError as exc:
        raise BridgeModelError(f"{what}: {exc}") from None
    if minimum and mu == 0.0:
        raise BridgeModelError(f"{what}: the model has no vertical mass (0 kg/m along its track): give its "
                               "elements their mass per metre [kg/m] (elasticBeamColumn ... -mass MU) or its nodes "
                               "theirs (mass)")
    if minimum and not mu >= minimum:
        raise BridgeModelError(
            f"{what}: the deck weighs {mu:.4g} kg/m along its track, below {minimum:g} kg/m (no railway deck is that "
            f"light); vtsi is SI (N, kg, m, Pa): a mass per metre typed in t/m ({mu:.4g} t/m is {1e3 * mu:.6g} kg/m), "
            "or a model in kN, t, m, gives masses 1000 times too small")
    if mu > MAX_MASS_PER_METRE:
        raise BridgeModelError(
            f"{what}: the deck weighs {mu:.4g} kg/m along its track, above {MAX_MASS_PER_METRE:g} kg/m (no railway "
            f"deck is that heavy); vtsi is SI (N, kg, m, Pa): a mass per metre typed in g/m ({mu:.4g} g/m is "
            f"{1e-3 * mu:.6g} kg/m) gives masses 1000 times too large")
    return mu


SPAN_RANGE_M = (1.0, 1000.0)    # a beam's spans [m]: outside, they are taken to be in mm or km


def check_span_lengths(spans, name):
    """A :class:`~vtsi.errors.BridgeModelError` naming ``name`` (the spans' argument or key) when
    a span of ``spans`` (positive finite lengths [m]) is outside SPAN_RANGE_M, no railway span:
    lengths typed in mm (above) or km (below). The one check of a beam's spans, whichever way the
    beam came (:func:`beam_bridge`, a bridge file's ``spans_m``)."""
    lo, hi = SPAN_RANGE_M
    odd = next((s for s in spans if not lo <= s <= hi), None)
    if odd is not None:
        raise BridgeModelError(f"{name}: a span of {odd:g} m is not a railway span ({lo:g} to {hi:g} m); "
                               f"is {name} in {'mm' if odd > hi else 'km'}?")


def beam_bridge(spans, E, I, mu, elements_per_span=10, A=1.0, damping=None, min_mass_per_metre=MIN_MASS_PER_METRE):
    """A continuous Euler-Bernoulli beam over ``spans`` [m] (pin, then rollers) as a sweep
    bridge; its track is the beam. E [Pa], I [m⁴], mu [kg/m], A [m²] (axial only); ``damping``:
    a ratio ζ [-] as Rayleigh damping through n₀ and the EN cut-off (or the sweep's settings).
    A span outside SPAN_RANGE_M is refused (:func:`check_span_lengths`: a span in mm). A sweep
    refuses ``mu`` below ``min_mass_per_metre`` [kg/m] (:func:`check_deck_mass`; 15 t/m is
    ``mu=15000.0``; 0 accepts any mass)."""
    model = Model()
    beam = continuous_beam(model, spans, elements_per_span, E, I, mu, A=A, damping=damping)
    lengths = [float(s) for s in spans]
    try:
        check_span_lengths(lengths, "spans")
    except BridgeModelError as exc:
        raise BridgeModelError(f"beam_bridge: {exc}") from None
    description = {"kind": "beam", "spans_m": lengths, "E_Pa": float(E), "I_m4": float(I),
                   "mu_kg_m": float(mu), "elements_per_span": int(elements_per_span), "A_m2": float(A)}
    if damping is not None:
        description["damping"] = float(damping)
    return SweepBridge(model, list(beam.elements), description, min_mass_per_metre=min_mass_per_metre)


def _fingerprint(runner):
    """A hash of what the passages see of the bridge: its matrices and its track."""
    asm = runner.model.build()
    digest = hashlib.sha256()
    for matrix in (asm.K, asm.M, asm.C):
        m = matrix.tocsr()
        for part in (m.indptr, m.indices, m.data):
            digest.update(np.ascontiguousarray(part).tobytes())
    for part in (runner.track.x_start, runner.track.length, runner.track.dofs):
        digest.update(np.ascontiguousarray(part).tobytes())
    return digest.hexdigest()


# -- the sweep ---------------------------------------------------------------------------------
_worker_stop = None
"""In a worker of a sweep's own process pool, the flag by which the sweep asks its workers to
stop (:func:`_worker_start`); None in any other process."""


def _run_task(runner, cases, out=None):
    """A worker's task: the passages of ``cases`` ((train, speed_kmh, seed), ...); in a worker of
    the sweep's own pool, those that began before the sweep asked its workers to stop (the
    cases a stopped task finished, in order). Each result is appended to ``out`` as its case
    finishes (a list the caller owns: the sweep in this process writes those of a task a
    failure or an interrupt cut), a new list by default; returns ``out``."""
    out = [] if out is None else out
    for train, speed, seed in cases:
        if _worker_stop is not None and _worker_stop.value:
            break
        try:
            out.append(runner.run(train, speed, seed))
        except VtsiError as exc:
            error = PassageError(f"case {case_key(train, speed, seed)}: {exc}")
            error.finished = list(out)      # to the sweep from a worker too (an exception's __dict__ is pickled)
            raise error from None
    return out


class Sweep:
    """Every train of ``trains`` at every speed of ``speeds_kmh`` (and every rail sample of
    ``seeds``) over ``bridge``.

    Parameters
    ----------
    bridge : SweepBridge (:func:`beam_bridge`, or a model with its track elements).
    trains : catalogue names ('HSLM-A1' … 'HSLM-A10', 'HSLM-B', 'ICE3') or axle-table CSV paths
        (:mod:`vtsi.models.catalogue`).
    speeds_kmh : speeds [km/h]: anything :func:`speeds` takes, or :func:`en_speed_grid`'s output.
    settings : PassageSettings (Δt, integrator, fidelity, contact, damping, irregularity …).
    outputs : the responses kept per passage (:class:`~vtsi.passage.Output`); default
        (DEFAULT_OUTPUTS): deck deflection and acceleration at every deck node (the track's nodes
        on a deck: not the approaches'), end rotations at the decks' supports, bending moments at
        mid-span and over the piers, and with cars the contact forces and car-body accelerations.
    seeds : rail samples (ints in [0, 2⁶³), at most MAX_SEEDS, each once) of an irregular rail;
        None: seed 0 on an irregular rail, the one smooth case (seed -1) without irregularity,
        where seeds are refused (they would select nothing).

    Train names are read by :func:`train_list` ('hslm-a1' and 'A1' are 'HSLM-A1'); a train
    named twice in any spelling is refused, an axle table named by two paths to one file too
    ('emu.csv' and './emu.csv'); the names stay as given.

    Every input is checked before anything runs or any file is written. ``settings`` and
    ``outputs`` check their own fields when they are made (:class:`~vtsi.passage.PassageSettings`,
    :class:`~vtsi.passage.Output`: a :class:`~vtsi.errors.ModelError`, as every definition);
    the rest, and whether the settings and outputs suit this bridge and these trains, is checked
    here: a :class:`~vtsi.errors.SweepError` naming it, a :class:`~vtsi.errors.SettingError`
    (also a SweepError, with ``.setting``) for a time step the passages cannot resolve, a
    :class:`~vtsi.errors.BridgeSweepError` (also a SweepError) when the bridge or its track is at
    fault.
    """

    def __init__(self, bridge, trains, speeds_kmh, settings=None, outputs=DEFAULT_OUTPUTS, seeds=None):
        settings = PassageSettings() if settings is None else settings
        if not isinstance(settings, PassageSettings):
            raise SweepError(f"sweep: settings must be PassageSettings, got {type(settings).__name__}")
        if not isinstance(bridge, SweepBridge):
            raise SweepError(f"sweep: bridge must be a SweepBridge (vtsi.sweep.beam_bridge, or a model with its "
                             f"track elements), got {type(bridge).__name__}")
        if not bridge.track_elements:
            raise BridgeSweepError("sweep: the bridge has no track (no track elements)")
        if not isinstance(trains, str) and (not np.iterable(trains)
                                            or not all(isinstance(t, (str, os.PathLike)) for t in trains)):
            raise SweepError(f"sweep: trains must be catalogue names or axle-table paths, got {trains!r}")
        self.trains = train_list(trains)
        if not self.trains:
            raise SweepError("sweep: no train")
        keys = [_train_key(t) for t in self.trains]
        twice = next((k for k in range(len(keys)) if keys[k] in keys[:k]), None)
        if twice is not None:
            first = self.trains[keys.index(keys[twice])]
            why = ("names ignore case; 'A1' is 'HSLM-A1'" if first == self.trains[twice] else
                   f"{first} and {self.trains[twice]} are one file, {keys[twice]}")
            raise SweepError(f"sweep: train {self.trains[twice]} is listed twice ({why}): {trains!r}")
        self.speeds_kmh = speeds(speeds_kmh)
        if settings.irregularity is None:
            if seeds is not None:
                raise SweepError(f"sweep: seeds {seeds!r} select samples of an irregular rail, and the rail is smooth "
                                 "(settings.irregularity None): give an irregularity, or no seeds")
            self.seeds = [-1]
        else:
            self.seeds = _seed_list([0] if seeds is None else seeds)
        self.settings, self.bridge = settings, bridge
        for o in outputs:
            if not isinstance(o, Output):
                raise SweepError(f"sweep: outputs must be vtsi.passage.Output, got {o!r}")
        try:
            check_deck_mass(bridge.model, bridge.track_elements, "bridge", bridge.min_mass_per_metre)
            self.runner = PassageRunner(bridge.model, bridge.track_elements, settings, outputs, bridge.modal_damping,
                                        top_speed_kmh=float(self.speeds_kmh[-1]), trains=self.trains)
            self.settings = self.runner.settings       # dt (and modal_hz) set from the bridge when None
            for name in self.trains:             # every name, fidelity, span and resolution is checked now
                for speed in (self.speeds_kmh[0], self.speeds_kmh[-1]):
                    self.runner.check_resolution(name, float(speed))
            if settings.hslm_b is not None and not any(describe(t) == describe("HSLM-B") for t in self.trains):
                raise SettingError(f"hslm_b = {settings.hslm_b} (--hslm-b) is HSLM-B's N and d, and the sweep runs "
                                   "no HSLM-B "
                                   f"(trains {', '.join(self.trains)}): add HSLM-B to the trains, or leave hslm_b "
                                   "unset", "hslm_b")
        except SettingError as exc:              # a setting's refusal keeps its setting (a file names its key)
            raise SettingError(f"sweep: {exc}", exc.setting) from None
        except VtsiError as exc:                 # what is the bridge's stays the bridge's (BridgeError)
            raise (BridgeSweepError if isinstance(exc, BridgeError) else SweepError)(f"sweep: {exc}") from None
        self.outputs = self.runner.outputs

    def __repr__(self):
        s = self.settings
        return (f"Sweep({cases_text(self.trains, self.speeds_kmh, self.seeds)}, bridge "
                f"{self.bridge.description.get('kind', '?')} ({len(self.bridge.track_elements)} track elements), "
                f"cars={s.cars!r}, contact={s.contact!r}, bridge={s.bridge!r}, dt = {s.dt:g} s, "
                f"{len(self.outputs)} outputs)")

    @property
    def cases(self):
        """Every case (train, speed [km/h], seed), trains outermost."""
        return [(t, float(v), s) for t in self.trains for v in self.speeds_kmh for s in self.seeds]

    def identity(self):
        """What makes two sweeps the same (stored in the results file; a resumed sweep must match):
        the bridge (its description and matrices' hash), what each train is (its hash, so that an
        edited axle table or a changed catalogue train is another sweep, and the same table by
        another path is not: :class:`~vtsi.sweep_results.ResultsWriter`), settings, outputs,
        trains, speeds and seeds."""
        return {"bridge": self.bridge.description, "bridge_fingerprint": _fingerprint(self.runner),
                "train_fingerprints": {name: train_fingerprint(self.runner.train(name, 1.0)) for name in self.trains},
                "settings": self.settings.as_dict(),
                "outputs": [{"name": o.name, "response": o.response, "nodes": o.nodes, "history": o.history,
                             "cutoff_hz": None if o.cutoff is None else self.runner.cutoff_hz(o.cutoff)}
                            for o in self.outputs],
                "trains": self.trains, "speeds_kmh": [float(v) for v in self.speeds_kmh], "seeds": self.seeds}

    def resolution_note(self):
        """'' when the sweep's results count every frequency up to the EN cut-off and Δt keeps the
        default's rule at the highest frequency they count (:func:`~vtsi.passage.dt_resolving`:
        20 steps a period and, time-stepped, Newmark's period error at most 0.1 ζ); else a
        line (two at most, each 'note: …') for each that does not hold:

        - a modal bridge whose modes stop at ``modal_hz`` below the EN cut-off: its deck
          accelerations count the frequencies up to ``modal_hz`` only (and may read low), which
          :func:`vtsi.check.check` refuses;
        - Δt too coarse for the EN cut-off (or the modal bridge's modes, when they stop below it)
          and, for cars on an irregular rail, for the rail's shortest wavelength at the top speed
          (:func:`~vtsi.passage.rail_frequency_hz`, 20 steps a period): which is under-resolved,
          what Newmark's period error may cost a resonance there
          (:func:`~vtsi.passage.step_error_text`) and the Δt that resolves it, the rule of the
          notes of :func:`vtsi.check.check` (its deck acceleration and car rows)."""
        s, runner = self.settings, self.runner
        basis = modal_basis_hz(s.bridge, s.modal_hz, runner.frequency_record)
        top = float(self.speeds_kmh[-1])
        below = basis is not None and basis < runner.en_cutoff_hz * (1 - 1e-9)
        notes = [f"note: the modal bridge's modes stop at modal_hz = {basis:.4g} Hz, below the EN cut-off "
                 f"{runner.en_cutoff_hz:.4g} Hz: the deck accelerations count frequencies up to {basis:.4g} Hz only and "
                 f"may read low (the design check refuses them); take modal_hz >= {runner.en_cutoff_hz:.4g} Hz, or leave it "
                 "unset (the default: 1.1 x the cut-off, or more with moment outputs)"] if below else []
        deck = (basis, "the modal bridge's highest frequency") if below else (runner.en_cutoff_hz, "the EN cut-off")
        zeta = step_ratio(s.bridge, s.cars, s.damping, s.bridge_self_weight)    # None: exact passages, dt samples them
        coarse = [(f, where, what, z) for (f, where), what, z in (
            (deck, "the deck accelerations", zeta),
            ((rail_frequency_hz(s.irregularity, s.cars, top), f"the rail's shortest wavelength at {top:g} km/h"),
             "the contact forces and car-body accelerations", None))
            if f is not None and not resolves(s.dt, f, z)]
        if coarse:
            steps = "; ".join(f"{where}, {f:.4g} Hz, {1.0 / (f * s.dt):.3g} times a period"
                              + (f" ({step_error_text(s.dt, f, z)})" if z is not None else "") for f, where, _, z in coarse)
            exact = zeta is None
            notes.append(f"note: dt = {1e3 * s.dt:g} ms {'samples' if exact else 'steps'} {steps}: "
                         f"{' and '.join(what for _, _, what, _ in coarse)} "
                         f"{'read low between the samples' if exact else 'are not converged in dt'}; take dt <= "
                         f"{1e3 * min(dt_resolving(f, z) for f, _, _, z in coarse):g} ms (the default's rule: "
                         f"{step_rule_text(zeta)}; a dt left unset keeps it)"
                         + (f"; {100 * zeta:.3g} % is the rule's floor (EN 1991-2 Table 6.6's smallest ratio): "
                            "the bridge's own damping is not read"
                            if s.damping is None and zeta is not None else ""))
        return "\n".join(notes)

    def free_end_note(self):
        """'' unless the sweep runs cars (``cars='full'``) and a track end sags more than
        :data:`~vtsi.track_ends.FREE_END_SAG` under the trains' heaviest static wheel load
        (:meth:`~vtsi.passage.PassageRunner.track_ends`): then one line naming it, its sag and the
        fix (:func:`~vtsi.track_ends.free_end_text`), which the check's wheel unloading and contact
        loss rows carry too. Moving forces read no step: no note for them."""
        if self.settings.cars == "force":
            return ""
        text = free_end_text(self.runner.track_ends(self.trains))
        return f"note: {text}" if text else ""

    def prepare(self):
        """Factor the bridge once (into the runner's cache) before passages are dispatched (a
        modal bridge has nothing to factor)."""
        if self.runner.modal is not None:
            return
        train = self.runner.train(self.trains[0], float(self.speeds_kmh[0]) / 3.6)
        sub = TrainSubdomain(train, self.runner.track.x_begin - 1.0 - train.length)
        s = self.settings
        tie = MovingLoadConstraint(self.runner.track, sub, None, s.interpolation)
        CoupledAnalysis(self.runner.model, tie, s.integrator, dt=s.dt, contact=s.contact,
                        bridge_self_weight=s.bridge_self_weight, bridge_cache=self.runner.cache).prepare()

    def case_cost(self, cases):
        """The mean work of a case of ``cases`` in FE time steps of moving forces (an exact modal
        passage's output samples count EXACT_SAMPLE_COST each, a step of cars CAR_STEP_COST),
        from every twentieth case."""
        steps = np.mean([self.runner.n_steps(self.runner.train(t, v / 3.6)) for t, v, _ in cases[:: max(1, len(cases) // 20)]])
        s = self.settings
        if s.bridge == "modal" and s.cars == "force" and not s.bridge_self_weight:
            steps *= EXACT_SAMPLE_COST          # exact modal passages: their samples cost little
        elif s.cars == "full":
            steps *= CAR_STEP_COST              # a coupled step of cars costs several of moving forces
        return float(steps)

    def history_bytes(self, cases):
        """The size [B] of the time histories each case of ``cases`` keeps, an array: its outputs
        with ``history=True``, a time and a value per column at each of its steps, float64 (its
        steps known before it runs, :meth:`~vtsi.passage.PassageRunner.n_steps`: about ∝ 1/speed);
        0 when no output keeps one."""
        kept = [o for o in self.outputs if o.history]
        if not kept:
            return np.zeros(len(cases))
        sizes = {}                           # (train, speed): a case's seed does not change it
        for t, v, _ in cases:
            if (t, v) not in sizes:
                train = self.runner.train(t, v / 3.6)
                sizes[t, v] = 8.0 * self.runner.n_steps(train) * sum(1 + len(self.runner.columns(o, train))
                                                                     for o in kept)
        return np.array([sizes[t, v] for t, v, _ in cases])

    @staticmethod
    def task_size(n_cases, cost, workers):
        """Cases per task at most: about TASK_STEPS steps (``cost``: a case's, :meth:`case_cost`)
        and at least one task per worker."""
        if not n_cases:
            return 1
        return int(max(1, min(math.ceil(TASK_STEPS / max(cost, 1.0)), math.ceil(n_cases / workers))))

    def tasks(self, cases, workers):
        """``cases`` in tasks of consecutive cases, each of at most :meth:`task_size` cases and
        at most TASK_HISTORY_BYTES of time histories, counted case by case (:meth:`history_bytes`:
        HSLM-A1 at 40 km/h over 10 × 30 m keeps 9.5 times what it keeps at 400 km/h); a case
        whose histories alone exceed TASK_HISTORY_BYTES is a task of its own. Without histories,
        tasks of :meth:`task_size` cases each."""
        size = self.task_size(len(cases), self.case_cost(cases), workers)
        tasks, held = [], 0.0
        for case, nbytes in zip(cases, self.history_bytes(cases)):
            if not tasks or len(tasks[-1]) == size or held + nbytes > TASK_HISTORY_BYTES:
                tasks.append([])
                held = 0.0
            tasks[-1].append(case)
            held += nbytes
        return tasks

    def run(self, path=None, *, workers=None, executor=None, progress=None, resume=False, overwrite=False,
            cases_per_task=None):
        """Run the sweep; returns :class:`~vtsi.sweep_results.SweepResults`.

        Parameters
        ----------
        path : results file (HDF5); None keeps the results in memory.
        workers : processes of the default pool (None: every core, or this process when the
            sweep's work is at most TASK_STEPS steps, less than a pool's start-up gains);
            1 runs in this process. A bridge the pool cannot be sent is refused before anything
            runs (SweepError naming what cannot be pickled), and one whose classes a fork server's
            or spawned worker cannot import (a bridge script's) runs in this process, with a
            logged warning (docs/sweeps.md, "Execution").
        executor : any ``concurrent.futures.Executor`` (e.g. a dask.distributed ``Client``'s
            ``get_executor()``); then ``workers`` only sizes the tasks (default: every core).
        progress : show a progress bar (tqdm: cases done, rate, time left); None: when stderr
            is a terminal.
        resume : continue the sweep in an existing ``path`` (its finished cases are skipped;
            a file of a different sweep is refused).
        overwrite : replace an existing ``path``: the new sweep is written to ``<path>.new`` and
            replaces ``path`` when it is complete, so that an interrupted overwrite leaves the
            old file as it was (the next ``overwrite`` of the same sweep continues ``<path>.new``).
        cases_per_task : override the task size (an integer >= 1).

        One run at a time writes a results file: a second one is refused while the first runs
        (:class:`~vtsi.sweep_results.ResultsFileInUse`, naming its pid).
        """
        _count(workers, "workers")
        _count(cases_per_task, "cases_per_task")
        if executor is not None and not isinstance(executor, Executor):
            raise SweepError(f"sweep: executor must be a concurrent.futures.Executor, got {type(executor).__name__}")
        n_workers = int(workers or os.cpu_count() or 1)
        with ResultsWriter(path, self.identity(), self.runner, resume=resume, overwrite=overwrite) as writer:
            done = writer.done()
            todo = [c for c in self.cases if case_key(*c) not in done]
            if todo:
                self.prepare()
                cost = self.case_cost(todo)
                if workers is None and executor is None and cost * len(todo) <= TASK_STEPS:
                    n_workers = 1
                if executor is None and n_workers > 1:
                    context = _pool_context()
                    stranger = _unimportable(self.runner, context.get_start_method())
                    if stranger is not None:
                        log.warning("sweep: %s is defined in module %s, which the pool's %s workers (another "
                                    "thread runs in this process) cannot import: the sweep runs in this process, "
                                    "on one core; define it in an importable module to run it on %d",
                                    stranger.__qualname__, stranger.__module__, context.get_start_method(),
                                    n_workers)
                        n_workers = 1
                tasks = ([todo[i: i + cases_per_task] for i in range(0, len(todo), cases_per_task)]
                         if cases_per_task else self.tasks(todo, n_workers))
                bar = partial(_progress_bar, len(self.cases), len(self.cases) - len(todo), progress)
                if executor is None and n_workers == 1:
                    with bar() as shown:
                        for task in tasks:
                            results = []
                            try:
                                _run_task(self.runner, task, results)
                            finally:            # a failure or an interrupt: the cases finished before it
                                writer.write(results)
                            shown.update(len(results))
                elif executor is None:
                    stop = context.RawValue("b", 0)   # no lock: a worker killed holding one would hang the sweep
                    with ProcessPoolExecutor(max_workers=min(n_workers, len(tasks)), mp_context=context,
                                             initializer=_worker_start, initargs=(stop,)) as pool:
                        self._dispatch(pool, tasks, writer, bar, stop)
                else:
                    self._dispatch(executor, tasks, writer, bar)
            writer.commit()                 # complete: an overwritten file is replaced only now
        return writer.results()

    def record_histories(self, path, cases, outputs=HISTORY_OUTPUTS):
        """Run ``cases`` ((train, speed_kmh, seed), e.g. the governing ones a check names) again
        in this process, keeping the time histories of ``outputs`` (default: the deck's
        displacement [m] and acceleration up to the EN cut-off [m/s²] at every deck node, and,
        for trains of cars, the contact forces [N, their 10 ms mean] and the car bodies'
        accelerations [m/s², as the sweep reads them]), and add them to the results file
        ``path`` of this sweep (/histories; each ``<output>_values`` has attrs response, units, kind and cutoff_hz).
        Returns the results.

        Every case must be one of the sweep's: a train of the sweep (named as :func:`train_list`
        reads it: 'ice3' is 'ICE3'), one of its speeds and one of its seeds (-1 on a smooth
        rail); anything else is a SweepError naming the case and what is valid, before anything
        runs or is written. An axle table the file names by another path (the sweep resumed
        from another folder: :class:`~vtsi.sweep_results.ResultsWriter`) may be given by either
        name, and its histories are stored under the file's, the name its check rows give. A
        file of another sweep is refused naming its first difference, a missing file as such
        (:class:`~vtsi.sweep_results.ResultsFileRefused`: build the Sweep with the file's)."""
        for o in outputs:
            if not isinstance(o, Output):
                raise SweepError(f"record_histories: outputs must be vtsi.passage.Output, got {o!r}")
        with ResultsWriter(path, self.identity(), self.runner, resume=True, adding_histories=True) as writer:
            cases = self.sweep_cases(cases, "record_histories", writer.stored_names)
            self.prepare()
            try:
                results = [self.runner.run(t, v, s, outputs=outputs) for t, v, s in cases]
            except VtsiError as exc:
                raise PassageError(f"record_histories: {exc}") from None
            writer.write_histories(results, outputs)
        return writer.results()

    def sweep_cases(self, cases, who="sweep", stored_names=None):
        """``cases`` ((train, speed_kmh, seed), ...) as the sweep names them (train names read by
        :func:`train_list`, the sweep's own speed values), or a SweepError naming ``who``, the
        first case that is not one of the sweep's and what is valid. ``stored_names``: {an axle
        table's name here: its name in the results file}
        (:attr:`~vtsi.sweep_results.ResultsWriter.stored_names`); a case may name it either way."""
        here = {there: name for name, there in (stored_names or {}).items()}
        if isinstance(cases, (str, bytes)) or not np.iterable(cases):
            raise SweepError(f"{who}: cases must be a list of (train, speed_kmh, seed), got {cases!r}")
        out = []
        for case in cases:
            if isinstance(case, (str, bytes)) or not np.iterable(case) or len(case) != 3:
                raise SweepError(f"{who}: a case is (train, speed_kmh, seed), got {case!r}")
            train, speed, seed = case
            shown = f"case ({train!r}, {_shown(speed)}, {_shown(seed)})"
            name = canonical_train_name(train) if isinstance(train, (str, os.PathLike)) else None
            name = here.get(name, name)
            if name not in self.trains:
                raise SweepError(f"{who}: {shown}: train {train!r} is not in the sweep; its trains: "
                                 f"{', '.join(self.trains)}")
            try:
                value = math.nan if isinstance(speed, (bool, np.bool_)) else float(speed)
            except (TypeError, ValueError):
                value = math.nan
            k = speed_index(self.speeds_kmh, value)
            if k < 0:
                v = self.speeds_kmh
                listing = ", ".join(f"{x:g}" for x in v) if len(v) <= 12 else f"{len(v)} speeds, {v[0]:g} to {v[-1]:g}"
                raise SweepError(f"{who}: {shown}: speed {_shown(speed)} km/h is not one of the sweep's "
                                 f"({listing} km/h)")
            if not is_int(seed) or int(seed) not in self.seeds:
                raise SweepError(f"{who}: {shown}: seed {_shown(seed)} is not one of the sweep's: {seeds_text(self.seeds)}")
            out.append((name, float(self.speeds_kmh[k]), int(seed)))
        return out

    def _dispatch(self, executor, tasks, writer, bar, stop=None):
        """Submit every task (the pool's processes start now, before the progress bar's thread
        exists), then write each task's results as it completes.

        A failure or an interrupt (Ctrl-C; SIGTERM on the command line) stops the sweep: the
        tasks not begun are cancelled, ``stop`` (the flag of the sweep's own pool,
        :func:`_worker_start`) is set, so that its workers end their tasks after the case they
        run, and once the running tasks have ended their cases are written, before the failure
        or interrupt goes on (a second interrupt stops the waiting). A task that failed (the
        first failure, or one meanwhile) has its cases before the failure written
        (``PassageError.finished``); its failed case and those after run again on resume."""
        unwritten = {executor.submit(_run_task, self.runner, task) for task in tasks}
        with bar() as shown:
            try:
                while unwritten:
                    for future in wait(unwritten, return_when=FIRST_COMPLETED).done:
                        unwritten.discard(future)          # before writing: a batch is never written twice
                        try:
                            results = future.result()
                        except BrokenExecutor as exc:
                            raise SweepError(f"sweep: a worker process died ({type(exc).__name__}: {exc}; killed, "
                                             "or out of memory)") from None
                        writer.write(results)
                        shown.update(len(results))
            except BaseException as exc:
                # The sweep's own pool cancels the tasks not begun and waits for the others in its
                # manager thread: a future cancelled here while that thread failed the futures of a
                # broken pool (its workers killed by a SIGTERM to the whole process group) killed
                # the thread (Python 3.11: InvalidStateError), and the process hung at exit.
                if stop is not None:
                    stop.value = 1
                    workers = (list((executor._processes or {}).values()),     # before shutdown lets go of them
                               executor._executor_manager_thread)
                    executor.shutdown(wait=False, cancel_futures=True)
                    while not all(future.done() for future in unwritten):    # the running tasks end after
                        wait(unwritten, timeout=0.1)        # their case; cancelled ones, which wait() misses
                    _end_workers(*workers)
                else:
                    for future in unwritten:
                        future.cancel()
                    wait([future for future in unwritten if not future.cancelled()])
                failures = [exc] + [future.exception() for future in unwritten if not future.cancelled()]
                for future in unwritten:
                    if not future.cancelled() and future.exception() is None:
                        results = future.result()
                        writer.write(results)
                        shown.update(len(results))
                for failure in failures:        # a failed task's cases before its failure (PassageError.finished)
                    results = getattr(failure, "finished", None)
                    if results:
                        writer.write(results)
                        shown.update(len(results))
                raise


def _shown(value):
    """A number of a case as a message shows it (``275``, not ``np.float64(275.0)``), else its repr."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        return repr(value)
    return f"{value:g}"


def _worker_start(stop):
    """A pool worker's start. SIGTERM ends it (the default), whatever handler the calling
    process installed (the ``vtsi`` command's, which a forked worker inherits). SIGINT is
    ignored (a Ctrl-C reaches every process of the terminal's group): the sweep stops its
    workers by ``stop`` (a byte in shared memory, 1: stop; :meth:`Sweep._dispatch`), and they
    end the case they run. A thread ends the worker as soon as the process that started it has ended
    (a sweep killed by SIGKILL leaves no worker behind). Its BLAS runs one thread: the pool
    keeps the cores busy, and a passage's small products gain nothing from more (a 3 × 30 m
    deck's FE passage took twice the CPU time on two BLAS threads for the same wall time)."""
    global _worker_stop
    threadpool_limits(1)
    if hasattr(signal, "SIGTERM"):
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _worker_stop = stop
    threading.Thread(target=_exit_with_parent, name="vtsi-exit-with-parent", daemon=True).start()


def _end_workers(processes, manager, grace_s=WORKER_GRACE_S):
    """End a stopped pool of the sweep: wait up to ``grace_s`` [s] for its worker ``processes``
    (multiprocessing.Process, their tasks ended) to exit, end those still alive (SIGTERM, which a
    worker takes by default, :func:`_worker_start`), then join the pool's ``manager`` thread. A
    worker killed while it held a lock of the pool's call queue (a SIGTERM to the whole process
    group, an out-of-memory kill) leaves the others unable to read the sentinel that stops them,
    and Python's pool joined them forever (1 in 18 such stops under load; docs/sweeps.md).
    ``processes`` and ``manager`` are ProcessPoolExecutor's ``_processes`` and
    ``_executor_manager_thread`` (private, as in Python 3.9 to 3.13)."""
    deadline = time.monotonic() + grace_s
    for process in processes:
        process.join(max(0.0, deadline - time.monotonic()))
    for process in processes:
        if process.is_alive():
            process.terminate()
    if manager is not None:
        manager.join()


def _exit_with_parent():
    """End this process (a pool worker) as soon as the process that started it has ended
    (multiprocessing's sentinel of the parent: a pipe only the parent holds open)."""
    multiprocessing.parent_process().join()
    os._exit(1)


def _pool_context():
    """Processes forked from this one (they inherit its compiled kernels and start at once) when
    no other thread runs here (forking a threaded process is unsafe); a fork server otherwise."""
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods and threading.active_count() == 1:
        return multiprocessing.get_context("fork")
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


class _Discard:
    """A file that keeps nothing written to it (:func:`_unimportable` only reads the pickling)."""

    def write(self, data):
        return memoryview(data).nbytes     # (a large array comes as a pickle.PickleBuffer, which has no len)


class _PoolPickler(ForkingPickler):
    """The pickler of a process pool's tasks, writing nothing, that notes the first class or
    function it pickles by name from a module a new process cannot import: one made at run time
    (``__spec__`` None), such as a bridge script's (:func:`vtsi.bridge_file._script_module`),
    which only a forked worker has (it inherits ``sys.modules``). ``__main__`` is
    multiprocessing's own to import (by its path)."""

    def __init__(self):
        super().__init__(_Discard(), pickle.HIGHEST_PROTOCOL)
        self.stranger = None

    def reducer_override(self, obj):
        if self.stranger is None and isinstance(obj, (type, types.FunctionType)):
            name = getattr(obj, "__module__", None)
            module = sys.modules.get(name) if name != "__main__" else None
            if module is not None and getattr(module, "__spec__", None) is None:
                self.stranger = obj
        return NotImplemented


def _pickle_error(obj):
    """``(error, pickler)``: the error pickling ``obj`` for a pool's workers raised, or None, and
    the :class:`_PoolPickler`, whose ``stranger`` is a class or function they cannot import."""
    pickler = _PoolPickler()
    try:
        pickler.dump(obj)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:    # what pickle raises on what it cannot take
        return exc, pickler
    return None, pickler


def _unimportable(runner, start_method):
    """The class or function of ``runner`` that the workers of a pool started by
    ``start_method`` ('fork', 'forkserver', 'spawn') cannot import (None for 'fork', whose
    workers inherit this process's modules), else None; a SweepError naming the part of
    ``runner`` that cannot be pickled at all (a lambda or an open file in a user's model or
    settings), before any task is sent."""
    error, pickler = _pickle_error(runner)
    if error is not None:
        part = next(name for name, value in [*vars(runner).items(), ("passage runner", runner)]
                    if _pickle_error(value)[0] is not None)
        raise SweepError(f"sweep: the sweep's {part.lstrip('_')} cannot be pickled for the pool's workers "
                         f"({type(error).__name__}: {error}); keep lambdas, open files and locks out of the bridge "
                         "and settings, or run in this process with workers=1 (--workers 1)")
    return None if start_method == "fork" else pickler.stranger


class _ProgressBar(tqdm):
    """tqdm without its monitor thread (a thread in this process would keep a later process
    pool from forking, see :func:`_pool_context`)."""

    monitor_interval = 0


def _progress_bar(total, initial, show):
    if show is None:
        show = sys.stderr.isatty()
    return _ProgressBar(total=total, initial=initial, unit="case", disable=not show, desc="sweep", smoothing=0.1)

"""One train passage over a bridge: the unit of work of a sweep (:mod:`vtsi.sweep`).

A :class:`PassageRunner` holds a bridge model with its track, factored once (a
:class:`~vtsi.subdomain.BridgeStageCache` shared by every passage) and runs
:class:`~vtsi.coupled.CoupledAnalysis` passages on it, each from the bridge's rest state
(or its self-weight state), without rebuilding or re-factoring anything: per passage it makes
only the train (at the case's speed), its constraint, the recorders and the compiled run.

A passage (docs/sweeps.md):

* at t = 0 the train's first wheel is ``approach`` metres before the track's first point, every
  wheel on rigid ground in its dead-load equilibrium (computed once per train and rail sample,
  and reused at every speed: on rigid ground it does not depend on the speed);
* it runs until the last wheel has left the track, plus a free-vibration window (default
  ``FREE_VIBRATION_PERIODS`` periods of the bridge's first vertical mode: the largest free
  vibration follows the exit within one period, as every mode then decays), and, when the
  sweep's outputs read car bodies, at least until every car body has stopped counting (its
  last wheel off the decks plus its run-out, :meth:`PassageRunner.n_steps`);
* the irregular rail (optional) is a seeded sample of a spectrum, faded in over the
  ``TAPER`` metres ahead of the first wheel, so that the train starts at rest on a level rail;
* the envelopes of the cars' outputs (contact forces, car bodies) count what happens on the
  bridge: a wheel on a deck, a car body while a wheel of its car is on one and a run-out after
  (:meth:`PassageRunner.counted`); the rigid ground before and after it, with its own rail, is
  kept apart (``CaseResult.whole_run``).

Units: SI (m, s, N, kg); speeds in m/s here (the sweep takes km/h at its surface).
"""
import copy
import math
import time
from dataclasses import asdict, dataclass, field, replace
from functools import partial

import numpy as np
import scipy.linalg
from scipy.ndimage import convolve1d

from vtsi.analysis import domain_state, modes_up_to
from vtsi.codes.en1991_2 import frequency_limits, hslm_b_refusal
from vtsi.constraint import INTERPOLATIONS, MovingLoadConstraint
from vtsi.coupled import CONTACT_STRATEGIES, STEPS_ON_TRACK, CoupledAnalysis, coupled_integrator
from vtsi.damping import (bridge_modes, deck_frequencies, deck_frequencies_table, decks_cutoff_hz, rayleigh_damping,
                           vertical_frequencies)
from vtsi.deck import deck_layout
from vtsi.errors import (AnalysisError, BridgeModelError, ModelError, SettingError, VtsiError, as_flag, as_number,
                         as_numbers, as_positive, is_int, is_number, number_array)
from vtsi.influence import InfluenceLines, StaticEnvelopes
from vtsi.modal_bridge import CUTOFF_MARGIN, ModalBridge
from vtsi.modal_passage import add_quasi_static, peaks, shape_polynomials
from vtsi.models.catalogue import FIDELITIES, catalogue_train, describe
from vtsi.models.trains import hslm_b, hslm_b_given
from vtsi.models.irregularity import (POINTS_PER_BLOCK, WAVELENGTH_BAND, Irregularity, fra_psd, german_psd,
                                      sample_profile)
from vtsi.recorders import ContactRecorder, NodeRecorder, TrainRecorder
from vtsi.recorders.envelope import Envelope
from vtsi.recorders.modal import ModalNodeRecorder
from vtsi.recorders.moment import BendingMomentRecorder, fixed_end_moments, moment_rows
from vtsi.subdomain import BridgeStageCache
from vtsi.track import Track
from vtsi.track_ends import TrackEnd, end_flexibility
from vtsi.train import TrainSubdomain
from vtsi.units import MIN_FIRST_FREQUENCY_HZ

FREE_VIBRATION_PERIODS = 1.5
MAX_BRIDGE_DAMPING = 0.2        # a sweep's ζ above this is a percentage typed as a ratio (EN: 0.5-4 %)
# What a passage's time step must resolve (PassageRunner.check_resolution): a coarser Δt gives
# envelopes that are silently wrong (Δt = 10 s samples nothing but the bridge at rest).
STEPS_PER_PERIOD = 8            # Δt <= T₁/8: the first mode sampled 8 times a cycle
DEFAULT_DT = 1e-3               # [s] a passage's default time step ...
STEPS_PER_CUTOFF_PERIOD = 20    # ... or finer: 20 steps (samples) a period of the EN cut-off frequency
                                # (the samples' under-read of a peak there 1 − cos(π/20) = 1.2 %) ...
PERIOD_ERROR_SHARE = 0.1        # ... and, time-stepped, Newmark's period error at the cut-off (ωΔt)²/12
                                # at most 0.1 ζ: its resonance moves by a tenth of its half-width
MIN_STEP_DAMPING = 0.005        # [-] the ζ of that rule when the sweep gives none or less (EN 1991-2 Table 6.6's
                                # smallest)
PLAUSIBLE_FREQUENCY_SHARE = 0.2  # a first frequency below this share of EN 1991-2 Fig. 6.10's lower limit: other units
E_UNITS = (("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9))   # E typed in them as Pa: f1 ∝ √E reads √(factor) times low
MAX_PASSAGE_STEPS = 10_000_000  # steps (or exact passages' samples) of one passage
TAPER = 20.0            # [m] the irregularity fades in over this length ahead of the first wheel
CAR_APPROACH = 25.0     # [m] default approach of trains of cars on a smooth rail (covers the taper)
SETTLE_DECAYS = math.log(20.0) / 2.0   # [-] σ t after which a stationary response's variance is within 5 % of its
                                       # own (e^(−2σt) = 1/20, σ the slowest decay rate): ~1.5
MAX_SETTLE_TIME = 10.0  # [s] the longest settle time a default approach takes (ten periods of a 1 Hz car body, a
                        # mode at ζ ≈ 2.4 %; an ICE3 coach: 2.3 s): longer is a car whose damping is missing
PROFILE_STEP = 0.1      # [m] sampling of the irregular profile
PROFILE_BLOCK = POINTS_PER_BLOCK   # samples of the profile computed at once (409.6 m), each block once per seed
PROFILE_MARGIN = 5.0    # [m] the profile is sampled this far beyond the wheels' travel, ...
SPLINE_REACH_STEPS = 4  # ... plus the B-spline rows' reach, 2 knots of 2 V Δt (MovingLoadConstraint.check_travel)
BODY_RUNOUT_PERIODS = 0.5   # a car body counts this many periods of its lowest mode after its last wheel leaves a deck
IRREGULARITIES = ("german-low", "german-high") + tuple(f"fra-{k}" for k in range(1, 7))

# Output responses: node responses (NodeRecorder names) and the vehicle responses.
NODE_RESPONSES = {"disp": "m", "vel": "m/s", "accel": "m/s^2", "rotation": "rad", "moment": "N m"}
VEHICLE_RESPONSES = {"contact_force": "N", "car_body_accel": "m/s^2"}
PLACES = ("deck", "track", "midspan", "supports", "piers")
CONTACT_FORCE_WINDOW = 0.01   # [s] a sweep's contact forces are their centred moving mean over this window
BODY_ON_TWO_SUPPORTS = ("four_dof", "ten_dof")   # car kinds whose body rests at the mean of each wheel half
BRIDGE_MODELS = ("fe", "modal", "modal-stepped")


@dataclass(frozen=True)
class BodyPoints:
    """The car bodies' accelerations of a passage (:meth:`PassageRunner._body_points`):
    ``largest`` (n_steps, n_cars) [m/s²] the signed value of the point with the largest |a| at
    each step (the envelopes' signal), ``governing`` (n_steps, n_cars) [m/s²] the history of
    each car's governing point (the stored history), ``point`` (n_cars,) which point that is
    (0 centre, 1 front bogie pivot, 2 rear bogie pivot)."""

    largest: np.ndarray
    governing: np.ndarray
    point: np.ndarray


@dataclass(frozen=True)
class Output:
    """A response a sweep keeps for every passage: its envelope (min, max, absmax and their
    times, per column) and, with ``history=True``, its time history.

    Parameters
    ----------
    name : str
        The name in results (e.g. 'deflection').
    response : str
        Node responses 'disp' [m], 'vel' [m/s], 'accel' [m/s²] (vertical, dof uy) and
        'rotation' [rad] (dof rz, counter-clockwise positive) and 'moment' [N·m] (bending moment,
        sagging positive, :mod:`vtsi.recorders.moment`), or 'contact_force' [N, compression
        positive] (one column per contact wheel; its centred moving mean over
        CONTACT_FORCE_WINDOW = 10 ms, :func:`contact_force_mean`), or 'car_body_accel' [m/s²]
        (each car body's vertical acceleration at its centre or over either bogie: the envelope
        of whichever is the largest at each step, the history of the point that governs the
        car's largest, :meth:`PassageRunner._body_points`). The vehicle responses need a train of
        cars (fidelity 'full'); a train of moving forces skips them. Their envelopes count what
        happens on the bridge (:meth:`PassageRunner.counted`); ``CaseResult.whole_run`` holds
        their envelopes over the whole run.
    nodes : 'deck' (the track's nodes on a deck, its spans and overhangs, in x order:
        :func:`vtsi.deck.deck_layout`; the approaches on the ground are not), 'track' (every node
        of the track, in x order, the approaches' too), 'midspan' (the node nearest each span's
        middle), 'supports' (the track's nodes that carry a deck: uy fixed, or on bearings or
        piers), 'piers' (those over the intermediate supports of continuous decks; a bridge
        without any produces no such output) or a tuple of node tags.
    history : keep the time history too.
    cutoff : None (the FE model's full response), 'en' (the EN 1990 A2.4.4.2.1 cut-off
        max(30 Hz, 1.5 n₀, n₃); of several decks the largest of theirs, :func:`en_cutoff_hz`)
        or a frequency [Hz]: the node response in the modes up to it only (modal projection,
        :class:`~vtsi.recorders.modal.ModalNodeRecorder`).

    Each field is checked when the output is made: a :class:`~vtsi.errors.ModelError` ("output
    'a': ...") naming it and its value (a definition, made before any sweep); a node the bridge
    lacks is the :class:`~vtsi.sweep.Sweep`'s SweepError.
    """

    name: str
    response: str
    nodes: object = "deck"
    history: bool = False
    cutoff: object = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ModelError(f"output {self.name!r}: the name must be an identifier (letters, digits, _)")
        if self.response not in NODE_RESPONSES and self.response not in VEHICLE_RESPONSES:
            raise ModelError(f"output {self.name!r}: unknown response {self.response!r}; valid: "
                             f"{', '.join(list(NODE_RESPONSES) + list(VEHICLE_RESPONSES))}")
        if isinstance(self.nodes, str):
            if self.nodes not in PLACES:
                raise ModelError(f"output {self.name!r}: nodes must be {', '.join(repr(p) for p in PLACES)} or node "
                                 f"tags, got {self.nodes!r}")
        else:
            tags = list(self.nodes) if np.iterable(self.nodes) else [self.nodes]
            if not all(is_int(n) for n in tags):
                raise ModelError(f"output {self.name!r}: nodes must be {', '.join(repr(p) for p in PLACES)} or node "
                                 f"tags, got {self.nodes!r}")
            object.__setattr__(self, "nodes", tuple(int(n) for n in tags))
        as_flag(self.history, f"output {self.name!r}", "history")
        if self.cutoff is not None:
            if self.response not in NODE_RESPONSES:
                raise ModelError(f"output {self.name!r}: a cut-off applies to node responses, not {self.response!r}")
            if self.cutoff != "en":
                value = float(self.cutoff) if is_number(self.cutoff) else math.nan
                if not (math.isfinite(value) and value > 0):
                    raise ModelError(f"output {self.name!r}: cutoff must be 'en' or a frequency > 0 [Hz], "
                                     f"got {self.cutoff!r}")
                object.__setattr__(self, "cutoff", value)

    @property
    def units(self):
        return NODE_RESPONSES.get(self.response) or VEHICLE_RESPONSES[self.response]

    @property
    def vehicle(self):
        return self.response in VEHICLE_RESPONSES


HISTORY_OUTPUTS = (Output("deck_displacement", "disp", history=True),
                   Output("deck_acceleration", "accel", cutoff="en", history=True),
                   Output("contact_force", "contact_force", history=True),
                   Output("car_body_acceleration", "car_body_accel", history=True))

DEFAULT_OUTPUTS = (Output("deflection", "disp"), Output("acceleration", "accel", cutoff="en"),
                   Output("end_rotation", "rotation", nodes="supports"),
                   Output("bending_moment", "moment", nodes="midspan"),
                   Output("support_moment", "moment", nodes="piers"),
                   Output("contact_force", "contact_force"), Output("car_body_acceleration", "car_body_accel"))


@dataclass(frozen=True)
class PassageSettings:
    """How each passage of a sweep is computed (all stored in the results file).

    Parameters
    ----------
    dt : time step [s]; None: DEFAULT_DT (1 ms), or finer where the bridge's EN cut-off f
        max(30 Hz, 1.5 n₀, n₃) (of several decks the largest of theirs) needs it to get
        STEPS_PER_CUTOFF_PERIOD (20) steps a period (a 5 m span's n₃ = 183 Hz: 0.25 ms, where 1
        ms read its deck acceleration 45 % high) and, for time-stepped passages (all but the
        exact modal ones), Newmark's period error there (2π f Δt)²/12 at most 0.1 ζ, Δt ≤
        √(1.2 ζ) / (2π f) with ζ ``damping`` (at least 0.5 %, which None takes: :func:`step_ratio`;
        30 Hz: 0.5 ms at ζ = 1 %, 0.4 ms at 0.5 %; :func:`default_dt`, :func:`dt_resolving`), and, for cars on an
        irregular rail, where the rail's shortest wavelength (3 m) passed at the sweep's top
        speed needs it (:func:`rail_frequency_hz`; 1 ms resolves it up to 540 km/h); the runner
        sets it from the bridge and the sweep's speeds.
    integrator : a registered name ('Newmark', 'Bathe', …), a name with its parameters
        ('HHT(0.9)') or an integrator instance such as ``vtsi.integrators.HHT(0.9)`` (implicit;
        stored in results by its repr); None:
        Newmark with bilateral contact, HHT(0.9) with contact='lcp', which refuses one without
        numerical dissipation (:func:`vtsi.coupled.coupled_integrator`).
    cars : fidelity of the trains: 'force' (moving axle loads) or 'full' (the catalogue's
        multibody cars; a train without them is refused).
    contact : 'bilateral' or 'lcp' (contact loss).
    interpolation : 'hermite' or 'bspline' (the ringing remedy (a)); None: 'bspline' for trains of
        cars (with Newmark's undamped rule 'hermite' rows ring after the rail's kinks at the
        supports, and the check reads no wheel unloading from them), 'hermite' for moving forces
        and with ``exact_events``.
    exact_events : take the kinks of the rail line (span entries and exits, a profile's declared
        kinks) at their own time (see CoupledAnalysis), for the wheels of cars on 'hermite' rows
        (the rows' default with it; 'bspline' rows refuse it: it would do nothing; moving forces
        have no wheels, and it changes nothing for them).
    damping : None (the bridge as built) or a damping ratio ζ [-] given to the bridge by
        Rayleigh damping through the two frequencies ``damping_hz`` (default: the first
        vertical frequency n₀ and the EN 1990 A2 cut-off max(30 Hz, 1.5 n₀, n₃), of several
        decks the largest of theirs): modes between them get less than ζ, modes outside more.
        On a modal bridge ζ goes to every mode, and None keeps the model's own damping,
        projected on the modes (refused unless classical).
    damping_hz : (f_a, f_b) [Hz] or None.
    irregularity : None (smooth rail) or 'german-low', 'german-high', 'fra-1' … 'fra-6'; each
        case's seed selects the sample. Only with cars='full' (moving forces do not feel it).
    approach : distance of the first wheel before the track at t = 0 [m]; None: 0 for moving
        forces, CAR_APPROACH for cars on a smooth rail, and for cars on an irregular rail TAPER
        plus the run in which their bodies settle (:meth:`PassageRunner.approach`).
    free_vibration : the bridge's free vibration, time after the last wheel leaves the track [s];
        None: FREE_VIBRATION_PERIODS periods of the first vertical mode. A sweep reading car
        bodies runs longer where a car body still counts then (its last wheel off the decks
        plus :func:`body_runout`, :meth:`PassageRunner.n_steps`), whatever this is.
    bridge_self_weight : include the deck's self weight (results are then totals, which the
        check refuses: its criteria read the trains' effects).
    bridge : 'fe' (the FE bridge, time-stepped) or 'modal' (its modes up to ``modal_hz``, each
        with the damping ratio ``damping`` exactly, :class:`~vtsi.modal_bridge.ModalBridge`):
        trains of moving forces over a bridge without self weight run as exact modal passages
        (:mod:`vtsi.modal_passage`, sampled every ``dt``); cars, contact loss and self weight are
        time-stepped on the modal bridge (:class:`~vtsi.coupled.CoupledAnalysis` ``bridge=``);
        'modal-stepped' time-steps every passage on the modal bridge (the work-precision study).
    modal_hz : the modal bridge's highest frequency [Hz]; None: :func:`default_modal_hz` (1.1 × the
        EN cut-off, or with a bending-moment output 1.1 × twice the frequency of the trains' closest
        axles at the top speed where higher), set by the :class:`PassageRunner` as it sets ``dt``.
    static_correction : passages of moving forces on the modal bridge (exact or 'modal-stepped')
        add the truncated modes' quasi-static response to displacements, rotations and bending
        moments without a cut-off (:mod:`vtsi.modal_bridge`); accelerations keep the modes up to
        ``modal_hz`` only (the cut-off). Passages of cars or with self weight are not corrected.
    hslm_b : (N, d [m]) of HSLM-B for the bridge's span, as read from EN 1991-2 Figure 6.13 by
        the user (:func:`~vtsi.models.trains.hslm_b_given`: N a whole number >= 1, d > 0 [m]);
        None: vtsi's straight-line reading of the figure (:func:`~vtsi.models.trains.hslm_b_parameters`,
        not verified against it, which the check says). A sweep without HSLM-B refuses it. Stored
        only when given (a results file without it ran vtsi's reading).

    Each field is checked when the settings are made: a :class:`~vtsi.errors.ModelError`
    ("sweep settings: ...") naming it and its value (a definition, made before any sweep); a
    setting that does not suit the sweep's bridge or trains is the :class:`~vtsi.sweep.Sweep`'s
    :class:`~vtsi.errors.SettingError`.
    """

    dt: float = None
    integrator: object = None
    cars: str = "force"
    contact: str = "bilateral"
    interpolation: str = None
    exact_events: bool = False
    damping: object = None
    damping_hz: object = None
    irregularity: object = None
    approach: object = None
    free_vibration: object = None
    bridge_self_weight: bool = False
    bridge: str = "fe"
    modal_hz: object = None
    static_correction: bool = True
    hslm_b: object = None

    def __post_init__(self):
        def positive(name, allow_none=False, allow_zero=False):
            value = getattr(self, name)
            if value is None and allow_none:
                return
            object.__setattr__(self, name, as_positive(value, "sweep settings", name, allow_zero=allow_zero))

        positive("dt", allow_none=True)
        positive("approach", allow_none=True, allow_zero=True)
        positive("free_vibration", allow_none=True, allow_zero=True)
        positive("damping", allow_none=True, allow_zero=True)
        if self.damping is not None and not self.damping <= MAX_BRIDGE_DAMPING:
            raise ModelError(f"sweep settings: damping {self.damping:g} is {100 * self.damping:g} % of critical, above "
                             f"the {100 * MAX_BRIDGE_DAMPING:g} % any bridge has: it is a ratio (0.01 for 1 %)")
        if self.damping_hz is not None:
            hz = number_array(self.damping_hz)
            pair = () if hz is None or hz.ndim != 1 else tuple(hz.tolist())
            if len(pair) != 2 or not all(math.isfinite(f) and f > 0 for f in pair) or pair[0] == pair[1]:
                raise ModelError(f"sweep settings: damping_hz must be two different frequencies > 0 [Hz], "
                                 f"got {self.damping_hz!r}")
            object.__setattr__(self, "damping_hz", pair)
        if self.exact_events is True and self.interpolation == "bspline":
            raise ModelError("sweep settings: exact_events takes the kinks of 'hermite' rows; 'bspline' rows smooth "
                             "them and take none: take interpolation='hermite' (the default with exact_events)")
        if self.interpolation is None:           # exact events need the kinks of 'hermite' rows
            object.__setattr__(self, "interpolation", "bspline" if self.cars == "full" and not self.exact_events
                               else "hermite")
        for name, valid in (("cars", FIDELITIES), ("contact", CONTACT_STRATEGIES), ("interpolation", INTERPOLATIONS)):
            if getattr(self, name) not in valid:
                raise ModelError(f"sweep settings: unknown {name} {getattr(self, name)!r}; valid: {', '.join(valid)}")
        if self.irregularity is not None and self.irregularity not in IRREGULARITIES:
            raise ModelError(f"sweep settings: unknown irregularity {self.irregularity!r}; valid: "
                             f"{', '.join(IRREGULARITIES)} (or None for a smooth rail)")
        if self.irregularity is not None and self.approach is not None and self.approach < TAPER:
            raise ModelError(f"sweep settings: approach {self.approach:g} m is shorter than the {TAPER:g} m over which "
                             f"the rail's irregularity ({self.irregularity}) fades in ahead of the train: the span "
                             f"would carry a faded profile (approach >= {TAPER:g} m, or leave it unset)")
        if self.irregularity is not None and self.cars == "force":
            raise ModelError(f"sweep settings: an irregular rail ({self.irregularity}) acts through the wheels of cars; "
                             "moving forces (cars='force') do not feel it, and every rail sample would repeat the "
                             "smooth passage: take cars='full' or no irregularity")
        if self.bridge not in BRIDGE_MODELS:
            raise ModelError(f"sweep settings: unknown bridge {self.bridge!r}; valid: {', '.join(BRIDGE_MODELS)}")
        positive("modal_hz", allow_none=True)
        if self.modal_hz is not None and self.bridge == "fe":
            raise ModelError(f"sweep settings: modal_hz = {self.modal_hz!r} is the modal bridge's highest frequency, and "
                             "bridge is 'fe': take bridge='modal' (or 'modal-stepped'), or leave modal_hz unset")
        for name in ("exact_events", "bridge_self_weight", "static_correction"):
            as_flag(getattr(self, name), "sweep settings", name)
        try:
            integrator = coupled_integrator(self.integrator, self.contact, "sweep settings")
        except VtsiError as exc:
            raise ModelError(f"sweep settings: {exc}" if not str(exc).startswith("sweep settings") else str(exc)) from None
        if self.hslm_b is not None:
            object.__setattr__(self, "hslm_b", hslm_b_given(self.hslm_b, "sweep settings: hslm_b"))
        if self.integrator is None:      # the contact strategy's default, by name where it has one
            object.__setattr__(self, "integrator", "Newmark" if self.contact == "bilateral" else integrator)
        if integrator.explicit:
            raise ModelError(f"sweep settings: {integrator.name} is explicit; a passage needs an implicit integrator "
                             "(Newmark, HHT, Bathe)")

    def as_dict(self):
        """The settings as JSON-able values (the integrator by its repr)."""
        out = asdict(self)
        out["integrator"] = self.integrator if isinstance(self.integrator, str) else repr(self.integrator)
        if self.hslm_b is None:          # as a file of a vtsi before the setting: vtsi's reading of Fig. 6.13
            del out["hslm_b"]
        return out



def _modal_damping(pairs):
    """``pairs`` ((frequency [Hz], ratio [-]), ...) as a tuple of float pairs, each frequency > 0
    and ratio >= 0, finite; else a ModelError naming the pair at fault."""
    rows = as_numbers(pairs, "sweep", "modal damping (frequency [Hz], ratio) pairs")
    if rows.size == 0:
        return ()
    if rows.ndim != 2 or rows.shape[1] != 2:
        raise ModelError(f"sweep: modal damping must be (frequency [Hz], ratio) pairs, got {pairs!r}")
    for f, zeta in rows:
        if not (math.isfinite(f) and f > 0.0 and math.isfinite(zeta) and zeta >= 0.0):
            raise ModelError(f"sweep: modal damping ({f:g} Hz, {zeta:g}): the frequency must be > 0 and the ratio "
                             ">= 0, both finite")
    return tuple((float(f), float(zeta)) for f, zeta in rows)


def _ratios_by_frequency(frequencies, modal_damping):
    """The ratios (n,) that ``modal_damping`` ((frequency [Hz], ratio), ...) gives the modes of
    ``frequencies`` (n,) [Hz]: each pair's ratio to the modes within 1e-6 of its frequency (0
    elsewhere: a mode the script's eigen did not reach)."""
    ratios = np.zeros(len(frequencies))
    for f, zeta in modal_damping:
        ratios[np.abs(frequencies - f) <= 1e-6 * f] += zeta
    return ratios


def contact_force_mean(forces, dt, window=CONTACT_FORCE_WINDOW):
    """The centred moving mean (n_steps, n_wheels) [N] of contact forces sampled every ``dt`` [s]
    over ``window`` [s]: trapezoidal weights on 2m + 1 samples, m = ⌊window / 2Δt + ½⌋ ≥ 1 (the
    mean spans 2mΔt: 10 ms for Δt = 1, 0.5, 0.25 ms; 12 ms for 2 ms; 2Δt once Δt > 6.7 ms), under
    which a period-2Δt oscillation averages to zero, also at the record's ends: the record is
    continued there by its mirror image about the first and last sample, which continues such an
    oscillation (repeating the last sample broke it: an ICE3 ringing ±500 kN at 2Δt read a
    whole-run ΔQ/Q of 1.74 in its last samples, 0.44 elsewhere).
    Where the rail kinks (rigid ground next to a span) the exact force holds an impulse, which a
    step shows as impulse/Δt, and Newmark's rows ring at period 2Δt after it: the raw minimum of
    an ICE3 over a 20 m span went from ΔQ/Q = 0.11 to 0.79 as Δt fell from 2 to 0.25 ms
    ('bspline' rows), to 2.3 with exact events; the mean stays at 0.07–0.08. Where a wheel flies at
    the kink (contact='lcp': an ICE3 at 360 km/h over a 15 m, 5.5 Hz span) the mean does not make
    it Δt-stable with 'bspline' rows, which round the kink off over ~8 V Δt: 0.26, 0.31, 0.39, 0.42
    at Δt 0.8, 0.4, 0.2, 0.1 ms, against 0.44–0.46 with 'hermite' rows and exact events at Δt ≤
    0.4 ms. ``dt`` and ``window`` finite and > 0, else a ModelError naming them."""
    dt = as_positive(dt, "contact force mean", "dt [s]")
    window = as_positive(window, "contact force mean", "window [s]")
    m = max(1, int(math.floor(0.5 * window / dt + 0.5)))
    forces = as_numbers(forces, "contact force mean", "forces [N]")
    if forces.ndim == 0:
        raise ModelError(f"contact force mean: forces [N] must be samples (n_steps, n_wheels), got {forces!r}")
    weights = np.ones(2 * m + 1)
    weights[[0, -1]] = 0.5
    samples = np.ascontiguousarray(np.moveaxis(forces, 0, -1))     # each wheel's record contiguous: 1.5-3x faster
    return np.moveaxis(convolve1d(samples, weights / (2 * m), axis=-1, mode="mirror"), -1, 0)


def en_cutoff_hz(bridge):
    """The bridge's EN 1990 A2.4.4.2.1(4)P cut-off [Hz] from its record ``bridge`` (a mapping: a
    results file's /bridge, :meth:`SweepResults.bridge() <vtsi.sweep_results.SweepResults.bridge>`,
    or :attr:`PassageRunner.frequency_record`): the largest of its decks' cut-offs max(30 Hz,
    1.5 n₀, n₃), each deck's from its own first vertical frequencies (``deck_frequencies_hz``
    (n_decks, 3), :func:`~vtsi.damping.deck_frequencies_table`). Counting every frequency up to
    the largest is on the safe side for each deck (the EN asks at least its own). The one
    reading of the cut-off: the passage's default Δt, 'en' outputs, Rayleigh damping and modal
    basis, the check and the report all call it."""
    return decks_cutoff_hz(deck_frequencies_table(bridge))


def default_dt(bridge, rail_hz=None, zeta=None):
    """The default time step [s] of a bridge of record ``bridge`` (:func:`en_cutoff_hz`):
    :func:`dt_resolving` its EN cut-off for damping ratio ``zeta`` (:func:`step_ratio`; None:
    exact modal passages, sampled only), and also ``rail_hz`` [Hz] when given (cars on an
    irregular rail: :func:`rail_frequency_hz` at the sweep's top speed, sampled)."""
    return min(dt_resolving(en_cutoff_hz(bridge), zeta), dt_resolving(rail_hz) if rail_hz else DEFAULT_DT)


def rail_frequency_hz(irregularity, cars, speed_kmh):
    """The frequency [Hz] at which a wheel at ``speed_kmh`` [km/h] passes the irregular rail's
    shortest wavelength (WAVELENGTH_BAND: 3 m; 27.8 Hz at 300 km/h), what a passage of cars
    (``cars`` 'full') on it must resolve in time; None on a smooth rail or for moving forces
    (which do not feel it). Its STEPS_PER_CUTOFF_PERIOD steps a period bound the default Δt
    (:func:`default_dt`), and the check notes the car rows of a coarser Δt: an ICE3 at 300 km/h
    over a 20 m span on a 'german-high' rail read ΔQ/Q 0.094 at 10 ms, 0.149 at 1/(20 f) = 1.8
    ms, 0.154 at 0.25 ms; on 'fra-1' a wheel lifted at 1.8 ms and finer, none at 2 ms or coarser
    (docs/check.md). DEFAULT_DT (1 ms) resolves it up to 540 km/h."""
    if irregularity is None or cars == "force" or speed_kmh is None:
        return None
    return float(speed_kmh) / 3.6 / WAVELENGTH_BAND[0]


def e_unit_slip(f1, band=None):
    """The hint for a first vertical frequency ``f1`` [Hz] far too low: the unit of E_UNITS in
    which E typed as pascals (the rest SI) brings f₁ into EN 1991-2 Fig. 6.10's ``band`` (lower,
    upper) [Hz] of the span, or nearest it within half a unit's step (f₁ ∝ √E: kPa reads f₁ 31.6
    times low, MPa 1000, GPa 31623); all of them when none does or without a band."""
    ratios = [math.sqrt(factor) for _, factor in E_UNITS]
    shown = [f"{r:.3g}" if r < 100 else f"{r:.0f}" for r in ratios]
    if band is not None:
        # how far f₁ √factor lies outside the band, in decades; a unit's step is log10 √1000 = 1.5
        off = [max(0.0, math.log10(band[0] / (f1 * r)), math.log10(f1 * r / band[1])) for r in ratios]
        k = int(np.argmin(off))
        if off[k] <= 0.5 * math.log10(ratios[1] / ratios[0]):
            return f"E in {E_UNITS[k][0]} reads f1 {shown[k]} times low"
    units = [unit for unit, _ in E_UNITS]
    return (f"E in {', '.join(units[:-1])} or {units[-1]} reads f1 {', '.join(shown[:-1])} or {shown[-1]} "
            "times low")


def step_ratio(bridge, cars, damping, bridge_self_weight=False):
    """The damping ratio ζ [-] the time step of a sweep's passages must resolve
    (:func:`dt_resolving`), from its settings (:class:`PassageSettings` ``bridge``, ``cars``,
    ``damping``, ``bridge_self_weight``): None for exact modal passages (bridge 'modal', moving
    forces, no self weight: no step error, Δt only samples them); else the sweep's ``damping``,
    at least MIN_STEP_DAMPING (0.5 %, EN 1991-2 Table 6.6's smallest), which it also is when
    ``damping`` is None (the bridge's own damping). The bridge's own ratios are not read: the FE
    model's damping has no modal ratios without a projection (exact only when classical), and
    the results file records the settings, not the modal bridge's ratios, so the check's notes
    could not judge a Δt taken from them; below 0.5 % the rule's Δt would shrink without bound."""
    if bridge == "modal" and cars == "force" and not bridge_self_weight:
        return None
    return max(MIN_STEP_DAMPING, float(damping or 0.0))


def period_error(dt, frequency_hz):
    """Newmark's (trapezoidal rule's) relative period elongation (2π f Δt)²/12 [-] of a mode of
    ``frequency_hz`` [Hz] stepped by ``dt`` [s] (leading term; 1 ms at 30 Hz: 0.30 %)."""
    return (2.0 * math.pi * frequency_hz * dt) ** 2 / 12.0


def step_error_text(dt, frequency_hz, zeta):
    """What a time step ``dt`` [s] may cost a time-stepped resonance of a mode of ``frequency_hz``
    [Hz] and damping ratio ``zeta`` (> 0): Newmark's period error e (:func:`period_error`)
    moves the mode's resonances by e in speed, e/ζ of their half-width, and the mode's steady
    resonant share of a peak read at one speed changes by up to 1 − 1/√(1 + (e/ζ)²) (HSLM-A2
    over a 25+32+25 m viaduct, cut-off 30 Hz, ζ 1 %, at 1 ms: e/ζ = 0.30, 4.1 %; its deck
    acceleration measured +4.3 % at 334 km/h)."""
    e = period_error(dt, frequency_hz)
    return (f"Newmark's period error there, (2 pi f dt)^2/12 = {100 * e:.2g} %, is {e / zeta:.2g} x the damping ratio "
            f"({100 * zeta:.3g} %): a mode there resonates at a speed {100 * e:.2g} % off, and its share of a peak at "
            f"one speed may be off by up to {100 * step_effect(dt, frequency_hz, zeta):.2g} % either way")


def step_effect(dt, frequency_hz, zeta):
    """The most a time step ``dt`` [s] may cost the peak of a mode of ``frequency_hz`` [Hz] [-]:
    sampled (``zeta`` None, exact passages) 1 − cos(π f Δt), 1 from two samples a period down;
    time-stepped (damping ratio ``zeta`` > 0) the steady resonant share's change
    1 − 1/√(1 + (e/ζ)²), e Newmark's period error (:func:`period_error`, :func:`step_error_text`)."""
    if zeta is None:
        return 1.0 - math.cos(math.pi * min(frequency_hz * dt, 0.5))
    r = period_error(dt, frequency_hz) / zeta
    return 1.0 - 1.0 / math.sqrt(1.0 + r * r)


def step_rule_text(zeta=None):
    """The rule of :func:`dt_resolving` in words, for the notes of a coarser Δt: for damping
    ratio ``zeta`` (time-stepped passages) or None (exact modal passages, sampled)."""
    if zeta is None:
        return f"{STEPS_PER_CUTOFF_PERIOD} samples a period"
    return (f"{STEPS_PER_CUTOFF_PERIOD} steps a period and Newmark's period error at most {PERIOD_ERROR_SHARE:g} x the "
            f"damping ratio ({100 * zeta:.3g} %), dt <= sqrt({12 * PERIOD_ERROR_SHARE:g} zeta) / (2 pi f)")


def resolves(dt, frequency_hz, zeta=None):
    """Whether the time step ``dt`` [s] keeps the rule of :func:`dt_resolving` at
    ``frequency_hz`` [Hz] for damping ratio ``zeta`` (None: sampling only; rounding aside): the
    rule the default Δt keeps and the notes of a coarser one read (``vtsi sweep``, the check's
    rows)."""
    return dt <= _dt_bound(frequency_hz, zeta) * (1 + 1e-9)


def _dt_bound(frequency_hz, zeta):
    """The largest Δt [s] of the rule of :func:`dt_resolving`, before rounding."""
    frequency_hz = as_positive(frequency_hz, "time step", "frequency [Hz]")
    dt = min(DEFAULT_DT, 1.0 / (STEPS_PER_CUTOFF_PERIOD * frequency_hz))
    if zeta is not None:
        zeta = as_positive(zeta, "time step", "damping ratio")
        dt = min(dt, math.sqrt(12.0 * PERIOD_ERROR_SHARE * zeta) / (2.0 * math.pi * frequency_hz))
    return dt


def dt_resolving(frequency_hz, zeta=None):
    """DEFAULT_DT [s], or finer: STEPS_PER_CUTOFF_PERIOD steps (samples) a period of
    ``frequency_hz`` (finite and > 0, else a ModelError) and, for a time-stepped passage
    (``zeta`` its damping ratio, finite and > 0, :func:`step_ratio`; None for exact modal passages), Newmark's
    period error there at most PERIOD_ERROR_SHARE ζ: Δt ≤ √(1.2 ζ) / (2π f) (:func:`period_error`;
    30 Hz: 0.5 ms at ζ = 1 %, 0.4 ms at 0.5 %, where 1 ms moved a viaduct's HSLM-A2 resonance
    enough to read its deck acceleration 4.3 % high at one speed and the HSLM-A envelope over the
    EN speed series 3.6 % low); rounded down to 1, 2, 2.5, 4 or 5 × 10^k s."""
    dt = _dt_bound(frequency_hz, zeta)
    decade = 10.0 ** math.floor(math.log10(dt))
    return max(m for m in (1.0, 2.0, 2.5, 4.0, 5.0) if m * decade <= dt * (1 + 1e-12)) * decade


AXLE_GAP_TOLERANCE = 1e-3     # [m] axles closer than this are one (coincident wheels)
AXLE_PAIR_HARMONICS = 2       # the moments' default modal basis holds the closest axles' first two harmonics


def axle_pair_hz(top_speed_kmh, axle_offsets):
    """[Hz] v_max / d_min: how often the trains' two closest axles, d_min apart, pass a point at
    the top speed [km/h] (``axle_offsets``: each train's axle offsets [m]; gaps under
    AXLE_GAP_TOLERANCE are one axle); None when no train has two axles. A mode at k v/d
    (k = 1, 2, …) is loaded by both axles of every such pair in phase (|1 + e^(-2πi f d/v)| = 2)
    and resonates with the coaches' repeated bogies at the speeds near it: HSLM-A's bogies
    (d_BA = 2.0 m, EN 1991-2 Table E.1) at 420 km/h, 58.3 Hz."""
    gaps = [g for x in axle_offsets for g in np.diff(np.sort(np.asarray(x, dtype=float).ravel()))
            if g > AXLE_GAP_TOLERANCE]
    return top_speed_kmh / 3.6 / min(gaps) if gaps else None


def default_modal_hz(record, responses=(), top_speed_kmh=None, axle_offsets=()):
    """A sweep's modal basis by default [Hz]: CUTOFF_MARGIN × the EN cut-off of the bridge's
    ``record`` (:func:`en_cutoff_hz`: its accelerations need no more) and, when ``responses``
    (the outputs' kinds) hold a 'moment', CUTOFF_MARGIN × AXLE_PAIR_HARMONICS ×
    :func:`axle_pair_hz` of the trains' ``axle_offsets`` at ``top_speed_kmh`` where that is
    higher (HSLM-A at 420 km/h: 128.3 Hz). A bending moment takes a share from every mode, and
    the static correction puts back only the truncated modes' quasi-static share: a mode above
    the cut-off driven to resonance by the bogies is missed. Over the pier of a 2 × 20 m deck on
    bearings and piers (modes at 33.9 and 58.0 Hz, just above the 33 Hz of 1.1 × the cut-off),
    HSLM-A1..A10 at 150–420 km/h, ζ 1 %, against every mode: the hogging moment's envelope read
    6.3 % low with the cut-off's basis (a train's 10.2 %, a passage's 19 %), 0.7 % with this one
    (1.9 %, 2.9 %); at 1.1 v/d, 0.5 % (2.1 %, 5.7 %) (docs/modal.md)."""
    f = en_cutoff_hz(record)
    if "moment" in responses and top_speed_kmh is not None:
        f = max(f, AXLE_PAIR_HARMONICS * (axle_pair_hz(top_speed_kmh, axle_offsets) or 0.0))
    return CUTOFF_MARGIN * f


def modal_basis_hz(bridge, modal_hz, record):
    """The highest frequency [Hz] of a sweep's modal bridge (``bridge`` 'modal' or
    'modal-stepped'): ``modal_hz`` (the runner sets it, :func:`default_modal_hz`), or for a
    results file of an older vtsi, which left it None, the default of then: CUTOFF_MARGIN × the
    EN cut-off of the bridge's ``record`` (:func:`en_cutoff_hz`); None for the FE bridge ('fe').
    Every output of a modal sweep counts the frequencies up to it at most."""
    if bridge == "fe":
        return None
    return float(modal_hz) if modal_hz else CUTOFF_MARGIN * en_cutoff_hz(record)


@dataclass
class CaseResult:
    """What one passage gives a sweep.

    ``envelopes[name]`` (6, n_columns): min, max, absmax and the times of each [units, s];
    ``columns[name]``: what the columns are (node tags, contact-wheel or car indices);
    ``histories[name]``: (time (n,), values (n, n_columns)) of the outputs kept as histories;
    ``x_head0`` [m]: the train's head at t = 0 (wheel i is at x_head0 + V t − offset_i);
    ``whole_run[name]`` (6, n_columns): a vehicle output's envelope over the whole run, where
    ``envelopes[name]`` counts only the samples on the bridge (:meth:`PassageRunner.counted`);
    ``deck_flights``: how many contact wheels flew (gap > gap_tol at the end of a step, however
    briefly: the raw contact, not the 10 ms mean) while their contact force would count on a
    deck (:meth:`PassageRunner.counted`), in a passage with contact='lcp', whatever its
    outputs; -1 otherwise (not counted).
    """

    train: str
    speed_kmh: float
    seed: int
    n_steps: int
    seconds: float
    x_head0: float = 0.0
    envelopes: dict = field(default_factory=dict)
    columns: dict = field(default_factory=dict)
    histories: dict = field(default_factory=dict)
    whole_run: dict = field(default_factory=dict)
    deck_flights: int = -1


def windowed_envelope(time, values, counted):
    """The envelope rows (6, n) (min, max, absmax and the time [s] of each, as
    :class:`~vtsi.recorders.envelope.Envelope`: the first on ties) of ``values`` (m, n) sampled
    at ``time`` (m,), over the samples where ``counted`` (m, n) is True; NaN in a column with
    none counted."""
    values = np.asarray(values, dtype=float)
    counted = np.asarray(counted, dtype=bool)
    out = np.full((6, values.shape[1]), np.nan)
    rows = np.flatnonzero(counted.any(axis=1))
    if rows.size == 0:
        return out
    # only the rows from the first to the last counted one (a car passage's approach is most of it)
    lo, hi = rows[0], rows[-1] + 1
    values, counted, time = values[lo:hi], counted[lo:hi], np.asarray(time, dtype=float)[lo:hi]
    columns, some = np.arange(values.shape[1]), counted.any(axis=0)
    for k, (source, fill, pick) in enumerate(((values, np.inf, np.argmin), (values, -np.inf, np.argmax),
                                              (np.abs(values), -np.inf, np.argmax))):
        at = pick(np.where(counted, source, fill), axis=0)
        out[k] = np.where(some, source[at, columns], np.nan)
        out[k + 3] = np.where(some, time[at], np.nan)
    return out


def contact_force_reach(dt):
    """Half the span [s] of :func:`contact_force_mean` at time step ``dt`` [s] (m Δt: 5 ms for Δt
    = 1, 0.5, 0.25 ms): the mean at a sample holds the forces this long before and after it."""
    return max(1, int(math.floor(0.5 * CONTACT_FORCE_WINDOW / dt + 0.5))) * dt


def _wheels_held(car):
    """A car's K [N/m], M [kg] and C [N s/m] (rotations: N m/rad, kg m², N m s/rad) on its dofs
    other than the wheels' (its body and bogies on their suspensions, the wheels held at rest),
    or None for a car without such dofs."""
    free = car.body_dofs
    if not free.size:
        return None
    return tuple(np.asarray(m, dtype=float)[np.ix_(free, free)] for m in (car.K, car.M, car.C))


def body_runout(car):
    """How long [s] a car body's acceleration still counts after its last wheel left a deck:
    BODY_RUNOUT_PERIODS (½) periods of the car's lowest mode with its wheels held (its body and
    bogies on their suspensions; an ICE3 coach: 0.804 Hz, 0.62 s). The bridge-induced motion
    the body carries off the deck is a decaying free vibration, whose largest |a| comes within
    half a period; counting longer reads the ground's rail. 0 for a car without such dofs;
    infinite (the rest of the run) for one whose lowest mode has no stiffness."""
    held = _wheels_held(car)
    if held is None:
        return 0.0
    K, M, _ = held
    try:
        lowest = float(np.min(scipy.linalg.eigh(K, M, eigvals_only=True)))       # ω² [rad²/s²]
    except (np.linalg.LinAlgError, ValueError):      # a mass matrix that is not positive definite
        return math.inf
    scale = float(np.max(np.abs(np.diag(K)))) / float(np.max(np.diag(M)))          # the stiffest dof's ω²
    if not lowest > 1e-12 * scale:                   # a rigid-body mode: no stiffness to end its motion
        return math.inf
    return BODY_RUNOUT_PERIODS * 2.0 * math.pi / math.sqrt(lowest)


def body_decay_rate(car):
    """The slowest decay rate σ [1/s] of a car's free vibration with its wheels held (the dofs of
    :func:`body_runout`): the least −Re λ over the eigenvalues λ of its state matrix
    [[0, I], [−M⁻¹K, −M⁻¹C]] (an ICE3 coach: 0.649 1/s, its 0.807 Hz mode at ζ = 12.8 %). inf for a
    car without such dofs (nothing to settle). A mode that does not decay (σ = 0: undamped, or a
    rigid-body mode without damping) never reaches a steady state on an irregular rail: a
    :class:`~vtsi.errors.ModelError` naming the car and the mode."""
    return _slowest_mode(car)[0]


def _slowest_mode(car):
    """(σ [1/s], f [Hz]) of the slowest-decaying mode of ``car`` with its wheels held
    (:func:`body_decay_rate`, which says what σ is and when it refuses; f = |Im λ| / 2π, 0 for an
    overdamped mode); (inf, nan) for a car without such dofs."""
    held = _wheels_held(car)
    if held is None:
        return math.inf, math.nan
    K, M, C = held
    n = len(K)
    eye, zero = np.eye(n), np.zeros((n, n))
    lam = scipy.linalg.eig(np.block([[zero, eye], [-K, -C]]), np.block([[eye, zero], [zero, M]]), right=False)
    decay = -lam.real
    slowest = int(np.argmin(decay))
    frequency = abs(float(lam[slowest].imag)) / (2 * math.pi)
    if not decay[slowest] > 1e-9 * float(np.max(np.abs(lam))):
        shown = max(float(decay[slowest]), 0.0) + 0.0          # a rounding's -1e-17 or -0.0 read as 0
        raise ModelError(f"car {car.name!r}: its mode at {frequency:.4g} Hz with the wheels held does not decay "
                         f"(decay rate {shown:.3g} 1/s: no damping on it), so its body never reaches a steady "
                         "state on the irregular rail and no default approach brings it there: give the car "
                         "damping, or the sweep's settings an approach [m]")
    return float(decay[slowest]), frequency


def _psd(name):
    if name.startswith("german-"):
        return partial(german_psd, level=name.split("-")[1])
    return partial(fra_psd, fra_class=int(name.split("-")[1]))


class PassageRunner:
    """A bridge model with its track, ready to run passages (see the module docstring).

    Parameters
    ----------
    model : vtsi.Model (the bridge; copied, the caller's model is left as it is).
    track_elements : tags of the track's elements (the chain the wheels run along).
    settings : PassageSettings.
    outputs : sequence of Output.
    modal_damping : ``((frequency [Hz], ratio [-]), ...)``: damping ratios of the model's modes
        (a script's ``modalDamping``, :class:`~vtsi.sweep.SweepBridge`), added on the modal
        bridge to each kept mode of that frequency (within 1e-6) over the model's own damping,
        as the command layer adds them; replaced, as the model's own damping is, by
        ``settings.damping``; the FE bridge, which steps Rayleigh damping, refuses them.
    top_speed_kmh : the sweep's top speed [km/h]; with cars on an irregular rail the default Δt
        also resolves the rail's shortest wavelength at it (:func:`rail_frequency_hz`).
    trains : the sweep's train names: with ``top_speed_kmh`` and a bending-moment output, the
        default modal basis also holds the modes their closest axles drive (:func:`default_modal_hz`).

    Attributes
    ----------
    frequencies : (3,) first vertical frequencies [Hz] (with the sweep's damping applied: the
        undamped ones of the model), of the modes that do not move mostly the approaches
        (:func:`~vtsi.damping.vertical_frequencies` ``ground``): a single deck's n₀, n₂, n₃; of
        several decks, the model's first three (two identical decks: their n₀ twice).
    deck_frequencies : (n_decks, 3) each deck's n₀, n₂, n₃ [Hz] (:func:`~vtsi.damping.deck_frequencies`;
        one deck: ``frequencies``).
    en_cutoff_hz : the bridge's EN cut-off [Hz], the largest of its decks'
        (:func:`en_cutoff_hz`): the default Δt, 'en' outputs, the Rayleigh damping's upper
        anchor and the modal basis follow it.
    track_nodes, deck_nodes, midspan_nodes : node tags of the track (x order), of those on a deck
        (its spans and overhangs, x order: not the ground's) and at each span's middle.
    span_ends : (n_spans, 2) x of each span's first and last support [m]; span_lengths [m]
        their distances; span_decks the deck of each span; deck_ends (n_decks, 2) the x of each
        deck's ends (its spans and overhangs); ground_nodes the track's nodes on no deck
        (approaches); support_nodes the track's nodes that carry a deck, pier_nodes those over the
        intermediate supports of continuous decks. The rules:
        :mod:`vtsi.deck` (docs/sweeps.md).
    track_on_a_structure : the track stands on elements over another structure at most of its
        nodes (a rail on its pads over the deck): the deck outputs are the track's.
    """

    def __init__(self, model, track_elements, settings, outputs=DEFAULT_OUTPUTS, modal_damping=(), top_speed_kmh=None,
                 trains=()):
        if top_speed_kmh is not None:
            top_speed_kmh = as_positive(top_speed_kmh, "sweep", "top speed [km/h]")
        modal_damping = _modal_damping(modal_damping)
        self.model = copy.deepcopy(model)
        outputs = tuple(outputs)
        names = [o.name for o in outputs]
        if len(set(names)) != len(names):
            raise ModelError(f"sweep outputs: names must differ, got {names}")
        self.track = Track(self.model, list(track_elements))
        self.track_nodes, self.deck_nodes, self.midspan_nodes, self.span_ends = self._deck()
        self.outputs = tuple(o for o in outputs if o.nodes != "piers" or self.pier_nodes)   # none: not produced
        self.span_lengths = [b - a for a, b in self.span_ends]
        for o in self.outputs:
            missing = [n for n in self.output_nodes(o.nodes) if n not in self.model.nodes]
            if missing and not o.vehicle:
                raise ModelError(f"output {o.name!r}: node {missing[0]} does not exist")
        try:                           # the modes of the approaches (ground) are not the bridge's
            self.frequencies, self.mode_shapes = vertical_frequencies(self.model, 3, ground=self.ground_nodes)
            self.deck_frequencies = self.frequencies[None, :] if len(self.nodes_by_deck) == 1 else \
                deck_frequencies(self.model, self.nodes_by_deck, 3, ground=self.ground_nodes)
        except (ModelError, AnalysisError) as exc:      # a mechanism (eigen factors K) is the bridge's too
            raise BridgeModelError(f"bridge (its track: {len(self.track.elements)} elements, x = "
                                   f"{self.track.x_begin:g} to {self.track.x_end:g} m): {exc}") from None
        # a first frequency far below what a span of its length has: E, I or the mass in other units
        # (E in kPa reads f₁ 31.6 times low: it passes an absolute floor on most spans)
        span = max(self.span_lengths, default=None)
        band = None if span is None else frequency_limits(span)
        if span is None:
            lowest, floor = MIN_FIRST_FREQUENCY_HZ, f"the {MIN_FIRST_FREQUENCY_HZ:g} Hz of any railway bridge"
        else:                          # (a fifth of Fig. 6.10's limit is >= 0.31 Hz: above the absolute floor)
            lowest = PLAUSIBLE_FREQUENCY_SHARE * band[0]
            floor = (f"{PLAUSIBLE_FREQUENCY_SHARE:g} x EN 1991-2 Figure 6.10's lower limit for its {span:g} m span "
                     f"({band[0]:.3g} Hz)")
        if not self.frequencies[0] >= lowest:
            raise BridgeModelError(f"bridge: first vertical frequency {self.frequencies[0]:.3g} Hz, below {floor}: "
                                   "are E, I or the mass in other units? (vtsi's data are SI: Pa, m^4, kg/m; "
                                   f"{e_unit_slip(self.frequencies[0], band)})")
        self.en_cutoff_hz = en_cutoff_hz(self.frequency_record)
        if settings.dt is None:
            rail = rail_frequency_hz(settings.irregularity, settings.cars, top_speed_kmh)
            zeta = step_ratio(settings.bridge, settings.cars, settings.damping, settings.bridge_self_weight)
            settings = replace(settings, dt=default_dt(self.frequency_record, rail, zeta))
        self.settings = settings
        if modal_damping and settings.damping is None and settings.bridge == "fe":
            raise BridgeModelError(f"the bridge's modalDamping ({', '.join(f'{z:g}' for _, z in modal_damping)}) "
                                   "damps its modes: the FE bridge steps Rayleigh damping only; take the modal bridge "
                                   "(bridge='modal', --bridge-model modal) or the sweep's own damping ratio "
                                   "(damping=..., --damping)")
        if settings.damping is not None and settings.bridge == "fe":
            rayleigh_damping(self.model, settings.damping,
                             settings.damping_hz or (self.frequencies[0], self.en_cutoff_hz))
        self.cache = BridgeStageCache()
        self._trains = {}
        self.modal = None
        if settings.bridge != "fe":      # damping None: the model's own (classical) damping on its modes
            if settings.modal_hz is None:
                offsets = [self.train(name, 1.0).wheel_offsets for name in trains]
                self.settings = settings = replace(settings, modal_hz=default_modal_hz(
                    self.frequency_record, [o.response for o in self.outputs], top_speed_kmh, offsets))
            f_max = settings.modal_hz
            if f_max < self.frequencies[0]:
                raise ModelError(f"modal_hz = {f_max:g} Hz is below the bridge's first frequency "
                                 f"({self.frequencies[0]:.4g} Hz): no mode to keep")
            self.modal = ModalBridge(self.model, self.track, f_max, settings.damping)
            if modal_damping and settings.damping is None:
                self.modal.add_ratios(_ratios_by_frequency(self.modal.frequencies, modal_damping))
            if settings.bridge == "modal" and settings.cars == "force":     # exact passages: before any case runs
                self.modal.check_underdamped()
        self._dead_load = {}
        self._profiles = {}
        self._static = {}            # static_envelopes by (output, train names)
        self._modes = {}
        self._modal_plans = {}
        self._residuals = {}
        self._fixed_ends = {}
        self._runouts = {}
        self._settle_times = {}
        self._end_flexibility = None

    # -- the bridge -------------------------------------------------------------------------
    def _deck(self):
        """The bridge's layout along its track (:func:`vtsi.deck.deck_layout`): sets
        ``support_nodes``, ``span_decks``, ``deck_ends``, ``nodes_by_deck``, ``ground_nodes`` and
        ``track_on_a_structure``; returns the track nodes, deck nodes, mid-span nodes and span ends."""
        layout = deck_layout(self.model, self.track)
        self.support_nodes = list(layout.support_nodes)
        self.pier_nodes = list(layout.pier_nodes)
        self.span_decks = list(layout.span_decks)
        self.deck_ends = list(layout.deck_ends)
        self.nodes_by_deck = layout.nodes_by_deck
        self.ground_nodes = layout.ground_nodes
        self.track_on_a_structure = layout.track_on_a_structure
        return list(layout.track_nodes), list(layout.deck_nodes), list(layout.midspan_nodes), list(layout.span_ends)

    def track_ends(self, train_names):
        """The track's first and last nodes as :class:`~vtsi.track_ends.TrackEnd`: each one's
        static sag [m] under the heaviest static wheel load [N] of the trains ``train_names`` (0
        for a node fixed in uy), from the bridge's stiffness, computed once per runner
        (:func:`~vtsi.track_ends.end_flexibility`). A car's wheel rolling onto a free end from the
        rigid ground meets a step (:func:`~vtsi.track_ends.free_end_text`)."""
        nodes = (self.track_nodes[0], self.track_nodes[-1])
        if self._end_flexibility is None:
            self._end_flexibility = end_flexibility(self.model, self.track, nodes)
        load = max(float(np.max(self.train(name, 1.0).static_wheel_loads)) for name in train_names)
        return tuple(TrackEnd(int(n), float(self.model.nodes[n][0]), float(f * load), load)
                     for n, f in zip(nodes, self._end_flexibility))

    @property
    def frequency_record(self):
        """The bridge's frequencies as a results file records them (/bridge): ``{'frequencies_hz':
        (3,), 'deck_frequencies_hz': (n_decks, 3)}`` [Hz], what :func:`en_cutoff_hz` reads."""
        return {"frequencies_hz": self.frequencies, "deck_frequencies_hz": self.deck_frequencies}

    def cutoff_hz(self, cutoff):
        """The cut-off [Hz] of an output's ``cutoff`` ('en': the bridge's, :func:`en_cutoff_hz`; or a frequency)."""
        return self.en_cutoff_hz if cutoff == "en" else float(cutoff)

    def modes_up_to(self, cutoff):
        """``(cutoff [Hz], shapes (n_full, n))``: every mode of the bridge up to the cut-off
        (mass-normalised; at least one; a mode within 1e-9 above it too: the other of a
        degenerate pair on the cut-off, two identical decks' n₃), computed once per cut-off
        (with their frequencies, :attr:`frequencies_to_cutoff`)."""
        f_max = self.cutoff_hz(cutoff)
        if f_max not in self._modes:
            self._modes[f_max] = modes_up_to(self.model, f_max * (1.0 + 1e-9))
        return f_max, self._modes[f_max][1]

    @property
    def frequencies_to_cutoff(self):
        """(n,) the bridge's vertical frequencies [Hz] up to its EN cut-off (:meth:`modes_up_to`
        'en', the modes an 'en' output counts, without a beam's axial modes and the approaches':
        :func:`~vtsi.damping.bridge_modes`), as a results file records them
        (/bridge/frequencies_to_cutoff_hz): the modes the Rayleigh note reads."""
        f_max, shapes = self.modes_up_to("en")
        f = self._modes[f_max][0]
        return f[bridge_modes(self.model, f, shapes, self.ground_nodes)]

    def static_envelopes(self, output, train_names):
        """The static min and max of a displacement, rotation or moment output under each train's
        static axle loads and under Load Models 71 and SW/0, α = 1
        (:class:`~vtsi.influence.StaticEnvelopes`): what dynamic increments and the comparison
        with Φ × LM71/SW/0 are measured against. None for other outputs. Computed once per
        output and trains (a check's refusals before the sweep build the results record too)."""
        if output.response not in ("disp", "rotation", "moment") or output.cutoff is not None:
            return None
        key = (output, tuple(train_names))
        if key not in self._static:
            self._static[key] = self._static_envelopes(output, train_names)
        return self._static[key]

    def _static_envelopes(self, output, train_names):
        nodes = self.output_nodes(output.nodes)
        if output.response == "moment":
            lines = InfluenceLines(self.model, self.track, moments=nodes)
        else:
            lines = InfluenceLines(self.model, self.track, [(n, 3 if output.response == "rotation" else 2)
                                                            for n in nodes])
        trains = []
        for name in train_names:
            train = self.train(name, 1.0)
            trains.append(lines.train_envelope(train.wheel_offsets, train.static_wheel_loads))
        return StaticEnvelopes(np.stack(trains), lines.lm71_envelope(), lines.sw0_envelope())

    # -- one passage --------------------------------------------------------------------------
    def train(self, name, speed):
        """The catalogue train ``name`` at ``speed`` [m/s] in this sweep's fidelity (built once
        per name, then copied at each speed). HSLM-B is built from the span of a bridge whose
        decks are each one simply supported span, all of one length under 7 m, and refused
        (ModelError) on any other (:func:`~vtsi.codes.en1991_2.hslm_b_refusal`: a continuous
        deck takes HSLM-A1 to A10); its N and d are the settings' ``hslm_b`` when given."""
        if name not in self._trains:
            decks = [[L for L, d in zip(self.span_lengths, self.span_decks) if d == k]
                     for k in range(len(self.deck_ends))]                    # each deck's spans [m]
            refusal = hslm_b_refusal(decks)
            is_b = describe(name) == describe("HSLM-B")              # the catalogue's HSLM-B, by any of its names
            if refusal and is_b:
                raise ModelError(refusal)
            span = None if refusal else float(self.span_lengths[0])
            train = catalogue_train(name, speed, fidelity=self.settings.cars, span=span)   # name, fidelity, span
            if is_b and self.settings.hslm_b is not None:
                train = hslm_b(span, speed, self.settings.hslm_b)
            self._trains[name] = train
        return self._trains[name].with_speed(speed)

    def approach(self, train):
        """The first wheel's distance before the track at t = 0 [m]: the settings' ``approach``, or
        by default 0 for moving forces, CAR_APPROACH for cars on a smooth rail (nothing moves them
        before the deck) and, for cars on an irregular rail, the TAPER over which it fades in plus
        the run at the train's speed V [m/s] in which its car bodies reach their steady response
        there, V × :meth:`settle_time` (an ICE3 at 300 km/h: 20 + 192 m; with 25 m its car-body
        accelerations on a 20 m span read 9-23 % low), never less than CAR_APPROACH. A settle time
        beyond MAX_SETTLE_TIME is refused (a :class:`~vtsi.errors.SettingError`, setting
        'approach', naming the car, its mode and the approach it would take): such a car lacks
        damping, and the default would run kilometres before the bridge."""
        s = self.settings
        if s.approach is not None:
            return s.approach
        if train.n_dof == 0:
            return 0.0
        if s.irregularity is None:
            return CAR_APPROACH
        settle = self.settle_time(train)
        needed = max(CAR_APPROACH, TAPER + train.speed * settle)
        if settle > MAX_SETTLE_TIME:
            car, sigma, frequency = self._slowest_car(train)
            raise SettingError(
                f"car {car.name!r} of {train.name} at {3.6 * train.speed:.4g} km/h: its {frequency:.4g} Hz mode with "
                f"the wheels held decays at {sigma:.3g} 1/s, so its body takes {settle:.3g} s to reach its steady "
                f"response on the irregular rail and the default approach would be {needed:.0f} m ({TAPER:g} m "
                f"taper + {train.speed:.4g} m/s x {settle:.3g} s), beyond the {MAX_SETTLE_TIME:g} s the default "
                "takes (an ICE3 coach: 2.3 s): give the car damping (its suspension's), or the sweep's settings "
                "an approach [m] (approach_m in a bridge file's [analysis])", "approach")
        return needed

    def settle_time(self, train):
        """SETTLE_DECAYS / σ [s], σ the least :func:`body_decay_rate` of ``train``'s cars (each
        distinct car computed once per train): the time after which a car body's stationary
        response to the rail has come within 5 % in variance (an ICE3: 2.31 s); 0 for a train
        whose cars have no suspended dofs."""
        return SETTLE_DECAYS / self._slowest_car(train)[1]

    def _slowest_car(self, train):
        """(car, σ [1/s], f [Hz]) of ``train``'s car whose mode with the wheels held decays slowest
        (:func:`body_decay_rate`; (None, inf, nan) without suspended dofs), once per train."""
        key = id(train.cars)               # the cars a train shares with its copies at every speed
        if key not in self._settle_times or self._settle_times[key][0] is not train.cars:
            modes = {id(car): (car, *_slowest_mode(car)) for car in train.cars}
            slowest = min(modes.values(), key=lambda m: m[1], default=(None, math.inf, math.nan))
            self._settle_times[key] = (train.cars, slowest)
        return self._settle_times[key][1]

    def start_position(self, train):
        """x_head0 [m]: the train's head at t = 0 (its first wheel ``approach`` before the track)."""
        return self.track.x_begin - self.approach(train) + float(train.wheel_offsets[0])

    def n_steps(self, train):
        """Steps of a passage of ``train``, the one rule of its length (the passages, their cost
        estimate, :meth:`check_resolution` and the resume of a results file call it): until its last wheel has left the track
        plus the free vibration (``free_vibration`` [s], default FREE_VIBRATION_PERIODS periods of
        n₀), or, when the runner's outputs read car bodies ('car_body_accel'), until every car
        body has stopped counting (:meth:`body_windows_end`) if that is later. A governing case
        re-run with other outputs (:meth:`~vtsi.sweep.Sweep.record_histories`) runs as long as
        the sweep's passage."""
        s = self.settings
        travel = self.track.x_end - self.track.x_begin + self.approach(train) + train.length
        free = s.free_vibration if s.free_vibration is not None else FREE_VIBRATION_PERIODS / self.frequencies[0]
        end = travel / train.speed + free
        if any(o.response == "car_body_accel" for o in self.outputs):
            end = max(end, self.body_windows_end(train))
        return int(math.ceil(end / s.dt - 1e-9))

    def body_windows_end(self, train):
        """The time [s] at which the last of ``train``'s car bodies stops counting in its envelope
        (:meth:`counted`): the latest over its cars of their last wheel leaving the decks' last end
        plus :func:`body_runout`. A car whose run-out is infinite is left out (it counts to the
        end of the run, however long); 0 when no car is left, for a train without car bodies
        (moving forces) and on a track without a deck (every sample counts)."""
        ends = np.asarray(self.deck_ends, dtype=float).reshape(-1, 2)
        cars = self.columns(Output("body", "car_body_accel"), train)
        if not len(ends) or not len(cars):
            return 0.0
        runouts = self.body_runouts(train)
        cars = [i for i in cars if math.isfinite(runouts[i])]
        if not cars:
            return 0.0
        x_head0, offsets = self.start_position(train), np.asarray(train.wheel_offsets, dtype=float)
        return max((float(ends.max()) - x_head0 + offsets[np.asarray(train.wheel_car) == i].max()) / train.speed
                   + runouts[i] for i in cars)

    def check_resolution(self, name, speed_kmh):
        """A :class:`~vtsi.errors.SettingError` (setting 'dt') unless the passage of train ``name``
        at ``speed_kmh`` [km/h] is resolved by Δt: Δt <= T₁/STEPS_PER_PERIOD, an axle crossing the
        track in at least STEPS_ON_TRACK steps, and at most MAX_PASSAGE_STEPS steps in all."""
        dt, f1 = self.settings.dt, float(self.frequencies[0])
        if dt > 1.0 / (STEPS_PER_PERIOD * f1):
            raise SettingError(f"time step dt = {dt:g} s does not resolve the bridge's first mode ({f1:.4g} Hz, "
                               f"period {1.0 / f1:.4g} s): take dt <= {1.0 / (STEPS_PER_PERIOD * f1):.3g} s "
                               f"(T1/{STEPS_PER_PERIOD})", "dt")
        train = self.train(name, speed_kmh / 3.6)
        length = self.track.x_end - self.track.x_begin
        if length / train.speed < STEPS_ON_TRACK * dt:
            raise SettingError(f"{name} at {speed_kmh:g} km/h crosses the {length:g} m track in "
                               f"{length / train.speed:.3g} s, fewer than {STEPS_ON_TRACK} steps of dt = {dt:g} s: "
                               "lower the speed or dt", "dt")
        n = self.n_steps(train)
        if n > MAX_PASSAGE_STEPS:
            given = self.settings.approach is not None         # the default's is at most V x MAX_SETTLE_TIME
            start = self.approach(train)
            where = f" (its first wheel starts {start:.4g} m before the {length:g} m track)" if start > 0 else ""
            raise SettingError(f"{name} at {speed_kmh:g} km/h needs {n:.3g} steps of dt = {dt:g} s, more than "
                               f"{MAX_PASSAGE_STEPS:.0e}{where}: raise the speed or dt"
                               + (", or shorten the settings' approach" if given else ""),
                               "approach" if given and start > length + train.length else "dt")

    def _irregularity(self, seed, x_first, x_last, start):
        """The seed's profile over [x_first, x_last] (at least), faded in over TAPER metres from
        ``start`` (the first wheel's position at t = 0). Sampled at whole multiples of
        PROFILE_STEP in fixed blocks of PROFILE_BLOCK points on that grid (n_waves from a fixed
        length), each block computed once per seed and kept: a case's profile is the same to the
        bit whatever range the cases before it asked (a sweep's speeds each asked a few metres
        more and re-sampled the whole profile: 0.5 s of a 0.9 s passage)."""
        blocks = self._profiles.setdefault(seed, {})
        first = math.floor((x_first - 1.0) / PROFILE_STEP) // PROFILE_BLOCK
        last = math.ceil((x_last + 1.0) / PROFILE_STEP) // PROFILE_BLOCK
        for j in range(first, last + 1):
            if j not in blocks:
                x = PROFILE_STEP * np.arange(j * PROFILE_BLOCK, (j + 1) * PROFILE_BLOCK)
                blocks[j] = sample_profile(_psd(self.settings.irregularity), x, n_waves=4000, rng=seed)
        x = PROFILE_STEP * np.arange(first * PROFILE_BLOCK, (last + 1) * PROFILE_BLOCK)
        r = np.concatenate([blocks[j] for j in range(first, last + 1)])
        ramp = np.clip((x - start) / TAPER, 0.0, 1.0)
        return Irregularity(x, r * 0.5 * (1.0 - np.cos(np.pi * ramp)))

    def run(self, train_name, speed_kmh, seed=-1, outputs=None):
        """Run one passage of the catalogue train ``train_name`` at ``speed_kmh`` [km/h] (rail
        sample ``seed``, -1 for a smooth rail) and return its :class:`CaseResult`; ``outputs``
        replaces the runner's (e.g. histories of a governing case)."""
        clock = time.perf_counter()
        s = self.settings
        speed_kmh = as_number(speed_kmh, "sweep", "speed [km/h]")
        if not (math.isfinite(speed_kmh) and speed_kmh > 0):
            raise ModelError(f"sweep: speed must be > 0 km/h, got {speed_kmh}")
        if not is_int(seed):
            raise ModelError(f"sweep: a seed is an integer (-1: a smooth rail), got {seed!r}")
        train = self.train(train_name, speed_kmh / 3.6)
        if s.bridge == "modal" and train.n_dof == 0 and not s.bridge_self_weight:
            return self._modal_passage(train_name, train, float(speed_kmh), int(seed),
                                       self.outputs if outputs is None else outputs, clock)
        approach = self.approach(train)
        x_head0 = self.start_position(train)
        n_steps = self.n_steps(train)
        irregularity = None
        if s.irregularity is not None and train.n_dof:
            if seed < 0:
                raise ModelError(f"sweep: an irregular rail ({s.irregularity}) needs seeds >= 0, got {seed}")
            # beyond the wheels' travel by a margin and the B-spline rows' reach, 4 V Δt (at 300 km/h
            # and Δt = 19 ms 6.3 m, past a fixed 5 m margin: MovingLoadConstraint refused the case)
            margin = PROFILE_MARGIN + SPLINE_REACH_STEPS * train.speed * s.dt
            x_first = x_head0 - float(train.wheel_offsets[-1]) - margin
            x_last = x_head0 + train.speed * (n_steps + 2) * s.dt + margin
            irregularity = self._irregularity(seed, x_first, x_last, self.track.x_begin - approach)
        sub = TrainSubdomain(train, x_head0)
        tie = MovingLoadConstraint(self.track, sub, irregularity, s.interpolation)
        outputs = self.outputs if outputs is None else outputs
        corrected = self._stepped_corrections(outputs) if train.n_dof == 0 else {}
        averaged = {o for o in outputs if o.response == "contact_force"}
        bodies = {o for o in outputs if o.response == "car_body_accel"}
        processed = set(corrected) | averaged | bodies      # their envelopes come from the processed history
        recorders = self._recorders(sub, tie, outputs, keep=processed)
        state = domain_state(self.model)
        state.time = 0.0
        state.u[:], state.v[:], state.a[:] = 0.0, 0.0, 0.0
        analysis = CoupledAnalysis(self.model, tie, s.integrator, dt=s.dt, contact=s.contact,
                                   bridge_self_weight=s.bridge_self_weight, recorders=[r for _, r in recorders],
                                   exact_events=s.exact_events, bridge_cache=self.cache, chunk_steps=4000,
                                   bridge=self.modal)
        # the catalogue name, not train.name: two entries may build trains of one name. On a smooth
        # rail the dead-load state with every wheel on rigid ground is the same at every speed; on
        # an irregular one it is not (the wheels' rates V r', V² r'' and, with B-spline rows, the
        # profile smoothed over V Δt: reused, it moved a case's contact forces by 2e-5), so it is
        # computed for each case there
        key = (train_name, approach)
        if irregularity is None and key in self._dead_load:
            analysis.start_from(self._dead_load[key])
        else:
            static = self._dead_load_state(analysis, sub)
            if irregularity is None and np.all(sub.wheel_x0(np.arange(train.n_wheels)) <= self.track.x_begin):
                self._dead_load[key] = static   # all wheels on rigid ground: the same at every speed
        analysis.run(n_steps)
        result = CaseResult(train_name, float(speed_kmh), int(seed), n_steps, 0.0, x_head0)
        for output, rec in recorders:
            env, history = rec.envelope, None
            if output.history or output in processed:
                history = (np.asarray(rec.time).copy(), np.asarray(rec.values).copy())
            if output in corrected:       # the truncated modes' quasi-static share, under the wheels' forces
                history[1][:] += self.modal.static_correction(corrected[output], train.wheel_offsets,
                                                              train.static_wheel_loads, train.speed, x_head0,
                                                              n_steps, s.dt)
            if output in averaged:
                history = (history[0], contact_force_mean(history[1], s.dt))
            kept = history
            counted = (self.counted(output, train, x_head0, history[0])
                       if output in averaged or output in bodies else None)
            if output in bodies:       # envelopes of the largest point, the history of the governing one
                points = self._body_points(train, history[1], counted)
                history, kept = (history[0], points.largest), (history[0], points.governing)
            if output in processed:
                env = Envelope(history[1].shape[1])
                env.update(*history)
            result.envelopes[output.name] = np.array([env.min, env.max, env.absmax, env.time_of_min,
                                                      env.time_of_max, env.time_of_absmax])
            if output in averaged or output in bodies:     # what the bridge does: on its decks only
                result.whole_run[output.name] = result.envelopes[output.name]
                result.envelopes[output.name] = windowed_envelope(*history, counted)
            result.columns[output.name] = self.columns(output, train)
            if output.history:
                result.histories[output.name] = kept
        if s.contact == "lcp":           # raw flights on a deck (whatever the outputs), which a 10 ms mean may hide
            t = np.asarray(analysis.time)
            window = self.counted(Output("contact", "contact_force"), train, x_head0, t)
            result.deck_flights = int(np.sum(np.any((np.asarray(analysis.gap) > analysis.gap_tol) & window, axis=0)))
        result.seconds = time.perf_counter() - clock
        return result

    def _dead_load_state(self, analysis, sub):
        """Start ``analysis`` from the passage's dead-load state at t = 0, every wheel of ``sub``
        (a TrainSubdomain) on rigid ground (the module docstring), and return it. A wheel at the
        track's first point (approach 0) is on the track's rows at t = 0, so the state is then
        solved with the wheels a step earlier (t = −Δt), before that wheel steps on, and the
        model's patterns at t = 0 (a Path series starting at 0 is 0 before it): the wheel's load
        enters in the first step, as every later axle's and as the exact modal passages take it
        (from rest). Solved
        at t = 0, an HSLM-A1's first axle stood on the track's first node from the start: on a
        10 + 13 + 10 m deck on 5 GN/m bearings both time-stepped bridges read the deflection 2 %
        low, whatever Δt, against every mode superposed (tests/test_viaduct_fidelities.py)."""
        if np.all(sub.wheel_x0(np.arange(sub.train.n_wheels)) < self.track.x_begin):
            return analysis.static()
        domain_state(self.model).time = -self.settings.dt
        static = dict(analysis.static(patterns_at=0.0), time=0.0)
        analysis.start_from(static)
        return static

    def _modal_passage(self, name, train, speed_kmh, seed, outputs, clock):
        """A passage of moving forces over the modal bridge, exact in the modal coordinates
        (:mod:`vtsi.modal_passage`): every node output's columns from one pass, sampled every Δt."""
        s, modal = self.settings, self.modal
        n_steps = self.n_steps(train)
        x_head0 = self.start_position(train)
        rows, parts, shares = self._modal_plan(outputs)
        values = modal.passage(train.wheel_offsets, train.static_wheel_loads, train.speed, x_head0, n_steps, s.dt, rows)
        if shares.shape[1]:     # the quasi-static shares of the first columns, one pass for every output
            add_quasi_static(np.ascontiguousarray(x_head0 - train.wheel_offsets, dtype=np.float64),
                             np.ascontiguousarray(train.static_wheel_loads, dtype=np.float64), float(train.speed),
                             self.track.x_start, self.track.length, shares, s.dt, values[:, :shares.shape[1]])
        envelopes = peaks(values, s.dt)
        result = CaseResult(name, speed_kmh, seed, n_steps, 0.0, x_head0)
        times = s.dt * np.arange(1, n_steps + 1)      # [s], shared by the histories kept
        for o, columns, nodes in parts:
            result.envelopes[o.name] = envelopes[:, columns].copy()
            result.columns[o.name] = nodes
            if o.history:
                part = values[:, columns]
                if part.shape[1] < values.shape[1]:
                    part = part.copy()     # a kept history holds its own columns, not every output's
                result.histories[o.name] = (times, part)
        result.seconds = time.perf_counter() - clock
        return result

    def _modal_plan(self, outputs):
        """The node outputs of ``outputs`` as one map of the modal coordinates for
        :meth:`ModalBridge.passage <vtsi.modal_bridge.ModalBridge.passage>`: ``rows (3, n_modes,
        n_columns)``; per output, in the order of ``outputs``, (output, its column slice, node
        tags); and ``shares (n_el, n_shared, 4)``, the quasi-static share of the first n_shared
        columns for :func:`~vtsi.modal_passage.add_quasi_static` (a unit axle's on each track
        element, cubics of ξ): the truncated modes' −N G (G the residual flexibility, with
        ``static_correction``: displacements, rotations and bending moments without a cut-off)
        and a bending moment's fixed-end share of the axles inside the elements next to its nodes
        (:class:`~vtsi.recorders.moment.FixedEndMoments`, the weights of its table on each
        element's Hermite slots). The outputs with a share take the first columns. An output with
        a cut-off reads the modes up to it only. Computed once per outputs."""
        key = (tuple(outputs), self.settings.static_correction)
        if key not in self._modal_plans:
            order = {"accel": 2, "vel": 1}
            track, n_el = self.track, len(self.track.elements)
            slots = np.arange(4 * n_el).reshape(n_el, 4)       # each element's own Hermite slots
            planned = []
            for o in outputs:
                if o.vehicle:
                    continue
                nodes = self.output_nodes(o.nodes)
                output_map = self._output_map(o.response, nodes)
                weights = np.zeros((3, self.modal.n_modes, output_map.shape[1]))
                weights[order.get(o.response, 0)] = self.modal.shapes[self.model.build().full_of_free].T @ output_map
                if o.cutoff is not None:       # the modes above the output's cut-off are left out
                    weights[:, self.modal.frequencies > self.cutoff_hz(o.cutoff) * (1.0 + 1e-9)] = 0.0
                share = None
                residual = self._residual(o) if self.settings.static_correction else None
                if residual is not None:
                    share = -shape_polynomials(residual, track.dofs, track.length)
                if o.response == "moment":
                    fixed = self._fixed_end(nodes)
                    on_slots = np.zeros((4 * n_el, len(nodes)))
                    element = np.repeat(np.arange(n_el), np.diff(fixed.ptr))
                    np.add.at(on_slots, (slots[element, fixed.slot], fixed.column), fixed.weight)
                    fixed_share = shape_polynomials(on_slots, slots, track.length)
                    share = fixed_share if share is None else share + fixed_share
                tags = np.array(nodes, dtype=np.int64)
                tags.flags.writeable = False          # shared by every passage's result
                planned.append((o, tags, weights, share))
            shared = sorted(planned, key=lambda p: p[3] is None)      # stable: those with a share first
            columns, start = {}, 0
            for o, _, weights, _ in shared:
                columns[o.name] = slice(start, start + weights.shape[2])
                start += weights.shape[2]
            rows = np.concatenate([p[2] for p in shared], axis=2) if shared else np.zeros((3, self.modal.n_modes, 0))
            shares = [p[3] for p in shared if p[3] is not None]
            shares = np.concatenate(shares, axis=1) if shares else np.zeros((n_el, 0, 4))
            parts = [(o, columns[o.name], tags) for o, tags, _, _ in planned]
            self._modal_plans[key] = (np.ascontiguousarray(rows), parts, np.ascontiguousarray(shares))
        return self._modal_plans[key]

    def _output_map(self, response, nodes):
        """``(n_free, n_columns)``: the node response ``response`` at ``nodes`` from the free dofs
        (a selection for a displacement, velocity, acceleration or rotation; moment rows)."""
        asm = self.model.build()
        if response == "moment":
            free, P = moment_rows(asm, self.track, nodes)
            output_map = np.zeros((asm.n_free, P.shape[1]))
            output_map[free] = P
            return output_map
        dof = 3 if response == "rotation" else 2
        output_map = np.zeros((asm.n_free, len(nodes)))
        for c, n in enumerate(nodes):
            f = asm.free_of_full[asm.full_dof(n, dof)]
            if f >= 0:
                output_map[f, c] = 1.0
        return output_map

    def output_nodes(self, nodes):
        """Node tags of an output's ``nodes`` (a place of PLACES, or tags)."""
        if nodes == "deck":
            return list(self.deck_nodes)
        if nodes == "track":
            return list(self.track_nodes)
        if nodes == "midspan":
            return list(self.midspan_nodes)
        if nodes == "supports":
            return list(self.support_nodes)
        if nodes == "piers":
            return list(self.pier_nodes)
        return list(nodes)

    def columns(self, output, train):
        """What the columns of ``output`` are for ``train``: node tags of a node output, the
        contact-wheel indices (0 … n_c − 1) of a contact-force output, the indices of the cars
        with a body of a car-body output (empty when the train has none: not produced)."""
        if output.response == "contact_force":
            return np.arange(len(train.contact_wheels), dtype=np.int64)
        if output.response == "car_body_accel":
            return np.array([i for i, car in enumerate(train.cars) if "body_y" in car.dof_names], dtype=np.int64)
        return np.array(self.output_nodes(output.nodes), dtype=np.int64)

    def _stepped_corrections(self, outputs):
        """The outputs that a time-stepped passage of moving forces on the modal bridge gets the
        truncated modes' quasi-static share back in, as in an exact passage (displacements,
        rotations and bending moments without a cut-off, with ``static_correction``, no self
        weight), each with its residual flexibility G (n_track, n_columns); empty for the FE
        bridge. Not for cars: the contact forces of a truncated basis carry its own dynamics, and
        their quasi-static share did not reliably bring an ICE3's mid-span moment closer to the
        every-mode bridge's (docs/modal.md)."""
        s = self.settings
        if self.modal is None or not s.static_correction or s.bridge_self_weight:
            return {}
        return {o: G for o in outputs if (G := self._residual(o)) is not None}

    def _fixed_end(self, nodes):
        """The :class:`~vtsi.recorders.moment.FixedEndMoments` of the bending moments at ``nodes``
        (tags), computed once per set of nodes."""
        key = tuple(int(n) for n in nodes)
        if key not in self._fixed_ends:
            self._fixed_ends[key] = fixed_end_moments(self.model.build(), self.track, list(key))
        return self._fixed_ends[key]

    def _residual(self, output):
        """The residual flexibility G (n_track, n_columns) of ``output``'s static correction (a
        displacement, rotation or bending moment without a cut-off; None for others), computed
        once per output."""
        if output.vehicle or output.cutoff is not None or output.response not in ("disp", "rotation", "moment"):
            return None
        if output not in self._residuals:
            output_map = self._output_map(output.response, self.output_nodes(output.nodes))
            self._residuals[output] = self.modal.residual_flexibility(output_map)
        return self._residuals[output]

    def _recorders(self, sub, tie, outputs, keep=()):
        """The recorders of ``outputs`` as (output, recorder) pairs; those of ``keep`` (and of the
        outputs with a history) keep their values."""
        out = []
        for o in outputs:
            kwargs = dict(envelope=True, history=o.history or o in keep)
            if o.response == "moment":
                if o.cutoff is not None:
                    raise ModelError(f"output {o.name!r}: bending moments take no cut-off")
                # with the fixed-end share of the forces and contact forces inside the elements
                rec = BendingMomentRecorder(self.track, self.output_nodes(o.nodes), constraint=tie, **kwargs)
            elif o.response in NODE_RESPONSES:
                dof, response = (3, "disp") if o.response == "rotation" else (2, o.response)
                nodes = self.output_nodes(o.nodes)
                if o.cutoff is None:
                    rec = NodeRecorder(nodes, [dof], response, **kwargs)
                else:
                    cutoff, shapes = self.modes_up_to(o.cutoff)
                    rec = ModalNodeRecorder(nodes, dof, response, shapes, f"modes up to {cutoff:.4g} Hz", **kwargs)
            elif sub.train.n_dof == 0:
                continue      # a train of moving forces has no contact forces or car bodies
            elif o.response == "contact_force":
                rec = ContactRecorder(tie, response="force", **kwargs)
            else:
                cars = [sub.train.cars[i] for i in self.columns(o, sub.train)]
                dofs = [f"car{i}.{name}" for i, car in zip(self.columns(o, sub.train), cars)
                        for name in ("body_y", "body_rz") if name in car.dof_names]
                if not dofs:
                    continue
                rec = TrainRecorder(sub, dofs, "accel", **kwargs)
            out.append((o, rec))
        return out

    def on_deck(self, x, margin=0.0):
        """Where positions ``x`` [m] (any shape) lie on a deck of the bridge, within ``margin`` [m]
        of its ends (``deck_ends``: its spans and overhangs, :mod:`vtsi.deck`; a joint between two
        decks and the approaches are no deck). A track without a deck counts everywhere."""
        x = np.asarray(x, dtype=float)
        ends = np.asarray(self.deck_ends, dtype=float).reshape(-1, 2)
        if not len(ends):
            return np.ones(x.shape, dtype=bool)
        tol = 1e-9 * max(1.0, float(np.max(np.abs(ends))))
        inside = np.zeros(x.shape, dtype=bool)
        for a, b in ends:
            inside |= (x >= min(a, b) - margin - tol) & (x <= max(a, b) + margin + tol)
        return inside

    def body_runouts(self, train):
        """:func:`body_runout` [s] of each of ``train``'s cars, computed once per train."""
        key = id(train.cars)               # the cars a train shares with its copies at every speed
        if key not in self._runouts or self._runouts[key][0] is not train.cars:
            self._runouts[key] = (train.cars, np.array([body_runout(car) for car in train.cars]))
        return self._runouts[key][1]

    def counted(self, output, train, x_head0, time):
        """Where (n_samples, n_columns) a vehicle output's samples at ``time`` [s] count in its
        envelope (EN 1990 A2.4.4.3 and the wheel-rail criteria judge what the bridge does; on
        an irregular rail the run over the ground before and after it, most of the passage, has
        its own peaks: an ICE3 at 300 km/h over a 20 m span (x = 0 to 20 m) on a 'german-high'
        rail read ΔQ/Q 0.236 with the wheel at x = 110 m and a car-body acceleration of 1.013
        m/s² with the head at x = 213 m, and 0.240 and 1.003 on an almost rigid bridge; on the
        bridge they are 0.1525 and 0.802, docs/check.md):

        * a contact wheel's force (its 10 ms mean) while the mean's window holds the wheel on
          a deck: its x within :func:`contact_force_reach` × V of a deck's ends (the mean a
          few decimetres before a deck holds the rail's kink at the deck's end: an ICE3 at 300
          km/h on a 3 Hz span, smooth rail, read ΔQ/Q 0.447 there, 0.404 from the wheel on the deck);
        * a car body's acceleration while any of its wheels is on a deck, and for
          :func:`body_runout` (half a period of its lowest mode) after its last wheel left it
          (a sweep reading car bodies runs until every car's has ended, :meth:`n_steps`).
        """
        t = np.asarray(time, dtype=float)
        offsets = np.asarray(train.wheel_offsets, dtype=float)
        if output.response == "contact_force":     # the contact wheels' positions only
            x = x_head0 + train.speed * t[:, None] - offsets[train.contact_wheels][None, :]
            return self.on_deck(x, margin=contact_force_reach(self.settings.dt) * train.speed)
        on = self.on_deck(x_head0 + train.speed * t[:, None] - offsets[None, :])
        runouts = self.body_runouts(train)
        cars = self.columns(output, train)
        out = np.zeros((len(t), len(cars)), dtype=bool)
        index = np.arange(len(t))
        for c, i in enumerate(cars):
            car_on = on[:, np.asarray(train.wheel_car) == i].any(axis=1)
            last = np.maximum.accumulate(np.where(car_on, index, -1))    # the last sample on a deck so far
            since = t - t[np.maximum(last, 0)]
            out[:, c] = (last >= 0) & (since <= runouts[i] * (1 + 1e-12) + 1e-12)
        return out

    def _body_points(self, train, values, counted):
        """Each car body's vertical acceleration [m/s²] from its recorded bounce and pitch
        (``values`` (n_steps, the recorder's dofs)) at its centre and over either bogie pivot (a
        four-dof car: over either wheel); a body of another kind has its bounce only. EN 1990
        A2.4.4.3.1 reads the acceleration inside the coach: the bounce at the centre alone read
        an ICE3 coach on a German 'high' rail 0.50 m/s², 1.03 over the bogies. Returns a
        :class:`BodyPoints` of (n_steps, n_cars) arrays:

        * ``largest``: at each step the signed value of whichever point has the largest |a|,
          the signal the envelopes are taken of (its absmax is the largest of any point's; its
          min and max are those of this spliced signal). Not a physical point's history: it
          jumps when another point takes over (by 1.1 m/s² within 1 ms on an ICE3 at 360 km/h);
        * ``governing``: the whole history of the one point (centre, front or rear pivot) whose
          |a| is the largest where ``counted`` (n_steps, n_cars) is True (where the car's
          envelope counts, :meth:`counted`; over every step for a car never counted): the
          stored history, continuous, whose peak over the counted steps is the envelope's
          absmax. ``point`` (n_cars,) names it: 0 centre, 1 front pivot, 2 rear pivot."""
        largest, governing, point, k = [], [], [], 0
        counted = np.asarray(counted, dtype=bool)
        for c, i in enumerate(self.columns(Output("body", "car_body_accel"), train)):
            car = train.cars[i]
            bounce, pitch = values[:, k], "body_rz" in car.dof_names
            k += 2 if pitch else 1
            if not pitch or car.kind not in BODY_ON_TWO_SUPPORTS:    # where its bogies are is not known
                largest.append(bounce)
                governing.append(bounce)
                point.append(0)
                continue
            half = 0.5 * (np.mean(car.wheel_offsets[len(car.wheel_offsets) // 2:])
                          - np.mean(car.wheel_offsets[: len(car.wheel_offsets) // 2]))
            points = (bounce, bounce + half * values[:, k - 1], bounce - half * values[:, k - 1])
            size = [np.abs(p) for p in points]
            # the first point of the largest |a| at each step (np.argmax over the three)
            front, top = size[1] > size[0], np.maximum(size[0], size[1])
            largest.append(np.where(size[2] > top, points[2], np.where(front, points[1], points[0])))
            mine = counted[:, c] if counted[:, c].any() else slice(None)
            j = int(np.argmax([np.max(a[mine]) for a in size]))
            governing.append(points[j])
            point.append(j)
        n = len(values)
        stack = (lambda a: np.stack(a, axis=1) if a else np.zeros((n, 0)))
        return BodyPoints(stack(largest), stack(governing), np.array(point, dtype=np.int64))

"""vtsi's own OpenSees-style commands for the coupled train-bridge analysis (a mixin of
:class:`vtsi.commands.session.Session`; documented in docs/commands.md, section 'Trains').

    track(tag, '-ele', e1, e2, ...)  |  track(tag, '-eleRange', first, last)
    car(tag, 'movingForce', P)  |  car(tag, 'movingMass', m)
    car(tag, 'sprungMass', m_s, k_s, ['-c', c_s], ['-wheelMass', m_w])
    car(tag, 'fourDof', m_c, J_c, m_w, k_s, c_s, l_c)  |  car(tag, 'catalogue', name)
    train(tag, speed, '-cars', car1, offset1, car2, offset2, ...)
    train(tag, speed, '-ICE3', nCars)  |  train(tag, speed, '-HSLM', 'A1')  |  train(tag, speed, '-axleFile', path)
    irregularity(tag, 'profile', '-x', x..., '-r', r...)  |  irregularity(tag, 'file', path)
    irregularity(tag, 'german', 'low'|'high', x_first, x_last, ['-seed', s])
    irregularity(tag, 'fra', class, x_first, x_last, ['-seed', s])
    movingLoadConstraint(tag, trainTag, trackTag, xHead0, ['-irregularity', irrTag], ['-bspline'])
    contact('bilateral'|'lcp')
    deadLoad()
    recorder('Contact', '-file'|'-h5', f, ['-time'], ['-wheel', i...], 'force'|'gap'|'inContact')
    recorder('Train', '-file'|'-h5', f, ['-time'], ['-dof', name_or_index...], 'disp'|'vel'|'accel')

    units(force, length)        the model's units ('N'|'kN'|'MN', 'm'|'cm'|'mm'; default N, m)

Every number is in the model's units (declared with ``units``, default N, m, kg, s; mass is
force·s²/length); the catalogue's SI data (cars, HSLM, ICE3, axle files, irregularity spectra,
g) are converted into them (:mod:`vtsi.units`); a speed is a number (length/s) or a text with its
unit ('300km/h'); offsets are measured backwards from the train's head; xHead0 is the
head's position at t = 0. With a moving-load constraint defined, ``analyze(n, dt)`` of a
Transient analysis runs the coupled analysis (the dead-load equilibrium is computed first,
at the first ``analyze``, unless ``deadLoad()`` was called).
"""
import numpy as np

from vtsi import recorders as rec
from vtsi.analysis import domain_state
from vtsi.constraint import MovingLoadConstraint
from vtsi.coupled import CoupledAnalysis, coupled_integrator
from vtsi.errors import CommandError, ModelError, as_positive, is_int
from vtsi.models import Irregularity, cars, fra_psd, german_psd, trains
from vtsi.vehicle import MAX_TRAIN_SPEED, Train, moving_force
from vtsi.track import Track
from vtsi.train import TrainSubdomain
from vtsi.units import FORCE_UNITS, LENGTH_UNITS, Units, deck_mass_per_length

from .analysis_commands import equilibrium_point
from .args import Args, is_option
from .base import SessionBase

TRAIN_COMMANDS = ("units", "track", "car", "train", "irregularity", "movingLoadConstraint", "contact", "deadLoad")
CAR_TYPES = ("movingForce", "movingMass", "sprungMass", "fourDof", "catalogue")
CONTACT_RESPONSES = {"force": "force", "gap": "gap", "inContact": "in_contact"}
TRAIN_RESPONSES = ("disp", "vel", "accel")
IRREGULARITY_STEP = 0.05
"""[m] The spacing of a random irregularity profile's samples."""
MAX_IRREGULARITY_SAMPLES = 200_000
"""The most samples of a random profile (10 km at 5 cm; the sampling time grows with the square)."""
MAX_IRREGULARITY_M = 0.1
"""[m] The deepest rail profile accepted: a deeper one is in other units (mm in an m model)."""


class TrainCommands(SessionBase):
    """Track, cars, trains, irregularities, the moving-load constraint and contact strategy."""

    def _clear_train(self):
        self._tracks, self._cars, self._trains, self._irregularities = {}, {}, {}, {}
        self._constraint = None
        self._contact = "bilateral"
        self._self_weight = False
        self._units = Units()
        self._coupled = None
        self._coupled_state = None
        self._run_dt = None          # [s] the coupled run's Δt, from analyze or deadLoad -dt (None: not given yet)
        self._dead_load_dt = None    # [s] the Δt the dead load's B-spline rows were solved for, until a step

    def _new(self, registry, command, tag):
        if tag in registry:
            raise CommandError(f"{command}: {command} {tag} already exists")

    def units(self, *args):
        """``units(force, length)``: the model's units, 'N'|'kN'|'MN' and 'm'|'cm'|'mm' (time s,
        mass force·s²/length: kN and m give t). Declare them before any car, train or
        irregularity: the SI catalogue data are converted as they are built."""
        a = Args("units", args)
        force, length = a.word("force unit", tuple(FORCE_UNITS)), a.word("length unit", tuple(LENGTH_UNITS))
        a.done()
        if self._cars or self._trains or self._irregularities:
            raise CommandError("units: declare the units before any car, train or irregularity "
                               "(their data are converted as they are built)")
        self._units = Units(force, length)
        self._coupled = None

    def track(self, *args):
        """``track(tag, '-ele', e...)`` or ``track(tag, '-eleRange', first, last)``: the chain of
        beam elements the wheels run along (horizontal, ordered along +x, no gaps)."""
        model = self._model("track")
        a = Args("track", args)
        tag = a.int("track tag")
        self._new(self._tracks, "track", tag)
        a.command = f"track {tag}"
        opt = a.option(("-ele", "-eleRange"), once=True)
        if opt == "-ele":
            elements = a.ints("element tag")
        else:
            lo, hi = a.int("-eleRange start"), a.int("-eleRange end")
            elements = [e for e in model.element_tags() if lo <= e <= hi]
        a.done()
        if not elements:
            raise CommandError(f"track {tag}: no elements")
        self._tracks[tag] = elements   # resolved when the analysis is built (the model may still grow)

    def car(self, *args):
        """``car(tag, type, ...)``: a vehicle (see the module docstring for the types)."""
        a = Args("car", args)
        tag = a.int("car tag")
        self._new(self._cars, "car", tag)
        kind = a.word("car type", CAR_TYPES)
        a.command = f"car {tag} {kind}"
        g = self._units.gravity
        try:
            if kind == "movingForce":
                car = moving_force(a.float("P"))
            elif kind == "movingMass":
                car = cars.moving_mass(a.float("m"), g)
            elif kind == "sprungMass":
                m_s, k_s = a.float("m_s"), a.float("k_s")
                extra = {"-c": 0.0, "-wheelMass": 0.0}
                while a.more():
                    opt = a.option(tuple(extra), once=True)
                    extra[opt] = a.float(opt)
                car = cars.sprung_mass(m_s, k_s, extra["-c"], extra["-wheelMass"], g)
            elif kind == "fourDof":
                car = cars.four_dof_car(*(a.float(n) for n in ("m_c", "J_c", "m_w", "k_s", "c_s", "l_c")), g)
            else:
                car = self._units.car(cars.car_from_catalogue(a.word("catalogue name")))
        except CommandError:   # a CommandError is a ValueError too: already named
            raise
        except (ValueError, KeyError) as exc:
            raise CommandError(f"car {tag}: {exc}") from None
        a.done()
        self._cars[tag] = car

    def train(self, *args):
        """``train(tag, speed, '-cars', car, offset, ...)``, ``'-ICE3', n``, ``'-HSLM', 'A1'`` or
        ``'-axleFile', path`` (CSV: position_m, load_kN)."""
        a = Args("train", args)
        tag = a.int("train tag")
        self._new(self._trains, "train", tag)
        try:
            speed = self._units.speed(a.take("speed"), f"train {tag}: speed")
        except ModelError as exc:
            raise CommandError(str(exc)) from None
        a.command = f"train {tag}"
        opt = a.option(("-cars", "-ICE3", "-HSLM", "-axleFile"), once=True)
        try:
            if opt == "-cars":
                pairs = []
                while a.more() and not is_option(a.peek()):
                    car_tag = a.int("car tag")
                    if car_tag not in self._cars:
                        raise CommandError(f"train {tag}: car {car_tag} does not exist")
                    pairs.append((self._cars[car_tag], a.float(f"offset of car {car_tag}")))
                if not pairs:
                    raise CommandError(f"train {tag}: no cars after -cars")
                built = Train([c for c, _ in pairs], [o for _, o in pairs], speed, name=f"train {tag}",
                              max_speed=MAX_TRAIN_SPEED * self._units.f_length)     # speeds in model units
            elif opt == "-ICE3":
                built = self._units.train(trains.ice3(a.int("number of cars"), speed=1.0), speed)
            elif opt == "-HSLM":
                built = self._units.train(trains.hslm_a(a.word("HSLM-A train (A1..A10)"), 1.0), speed)
            else:
                built = self._units.train(Train.from_csv(a.word("axle file"), 1.0), speed)
        except CommandError:   # a CommandError is a ValueError too: already named
            raise
        except (ValueError, KeyError, OSError) as exc:
            raise CommandError(f"train {tag}: {exc}") from None
        a.done()
        self._trains[tag] = built

    def irregularity(self, *args):
        """``irregularity(tag, 'profile', '-x', x..., '-r', r...)``, ``(tag, 'file', path)``, or a
        random profile ``(tag, 'german', 'low'|'high', x_first, x_last, ['-seed', s])`` /
        ``(tag, 'fra', class, x_first, x_last, ['-seed', s])`` (one-sided PSDs, 3-150 m); without
        ``-seed`` the seed is 0 (a sweep's default seed too), so that a script gives the same
        profile on every run."""
        a = Args("irregularity", args)
        tag = a.int("irregularity tag")
        self._new(self._irregularities, "irregularity", tag)
        a.command = f"irregularity {tag}"
        kind = a.word("irregularity type", ("profile", "file", "german", "fra"))
        try:
            if kind == "profile":
                a.option(("-x",), once=True)
                x = a.number_list("-x")
                a.option(("-r",), once=True)
                r = a.number_list("-r")
                if len(x) != len(r) or len(x) < 2:
                    raise CommandError(f"irregularity {tag}: -x and -r need the same number (>= 2) of values, "
                                       f"got {len(x)} and {len(r)}")
                profile = Irregularity(x, r)
                r = np.asarray(r, dtype=float)
            elif kind == "file":
                path = a.word("file name")
                try:
                    data = np.loadtxt(path, ndmin=2)
                except OSError as exc:
                    reason = exc.strerror or ("no such file" if isinstance(exc, FileNotFoundError) else exc)
                    raise CommandError(f"irregularity {tag}: cannot read {path}: {reason}") from None
                if data.shape[1] != 2:
                    raise CommandError(f"irregularity {tag}: the file needs two columns x r, got {data.shape[1]}")
                profile = Irregularity(data[:, 0], data[:, 1])
                r = data[:, 1]
            else:
                level = a.word("level", ("low", "high")) if kind == "german" else a.int("FRA class")
                x0, x1 = a.float("x_first"), a.float("x_last")
                seed = 0
                if a.more():
                    a.option(("-seed",), once=True)
                    seed = a.int("-seed")
                    if seed < 0:
                        raise CommandError(f"irregularity {tag}: -seed must be a non-negative integer, got {seed}")
                if not x1 > x0:
                    raise CommandError(f"irregularity {tag}: x_last must exceed x_first, got {x0:g} .. {x1:g}")
                psd = (lambda w: german_psd(w, level)) if kind == "german" else (lambda w: fra_psd(w, level))
                f = self._units.f_length            # the spectra are SI: sampled in m
                n = int(np.ceil((x1 - x0) / f / IRREGULARITY_STEP)) + 1
                if n > MAX_IRREGULARITY_SAMPLES:
                    raise CommandError(f"irregularity {tag}: x_first .. x_last = {x0:g} .. {x1:g} needs {n:.3g} "
                                       f"samples at {IRREGULARITY_STEP * f:g} {self._units.length} steps, more than "
                                       f"{MAX_IRREGULARITY_SAMPLES} (a profile of about 10 km at most)")
                x = np.linspace(x0 / f, x1 / f, n)
                si = Irregularity.from_psd(psd, x, rng=np.random.default_rng(seed))
                profile = Irregularity(x * f, si(x) * f)
        except CommandError:   # a CommandError is a ValueError too: already named
            raise
        except ValueError as exc:
            raise CommandError(f"irregularity {tag}: {exc}") from None
        a.done()
        if kind in ("profile", "file"):
            deepest = float(np.max(np.abs(r))) / self._units.f_length           # [m]
            if deepest > MAX_IRREGULARITY_M:
                raise CommandError(f"irregularity {tag}: a rail profile of {deepest * self._units.f_length:g} "
                                   f"{self._units.length} ({1e3 * deepest:.4g} mm), more than any track's "
                                   f"{1e3 * MAX_IRREGULARITY_M:g} mm: is it in other units than the model's "
                                   f"({self._units.length})?")
        self._irregularities[tag] = profile

    def movingLoadConstraint(self, *args):
        """``movingLoadConstraint(tag, trainTag, trackTag, xHead0, ['-irregularity', t], ['-bspline'],
        ['-exactEvents'])``."""
        a = Args("movingLoadConstraint", args)
        tag = a.int("constraint tag")
        if self._constraint is not None:
            raise CommandError(f"movingLoadConstraint {tag}: a constraint is already defined (one train per model)")
        train_tag, track_tag, x_head0 = a.int("train tag"), a.int("track tag"), a.float("xHead0")
        if train_tag not in self._trains:
            raise CommandError(f"movingLoadConstraint {tag}: train {train_tag} does not exist")
        if track_tag not in self._tracks:
            raise CommandError(f"movingLoadConstraint {tag}: track {track_tag} does not exist")
        irregularity, interpolation, exact_events = None, "hermite", False
        a.command = f"movingLoadConstraint {tag}"
        while a.more():
            opt = a.option(("-irregularity", "-bspline", "-exactEvents"), once=True)
            if opt == "-bspline":
                interpolation = "bspline"
            elif opt == "-exactEvents":
                exact_events = True
            else:
                t = a.int("irregularity tag")
                if t not in self._irregularities:
                    raise CommandError(f"movingLoadConstraint {tag}: irregularity {t} does not exist")
                irregularity = self._irregularities[t]
        model = self._model("movingLoadConstraint")
        try:
            mass = deck_mass_per_length(model, self._tracks[track_tag])
        except ModelError as exc:     # Track's own messages begin 'track: '; the tag takes its place
            raise CommandError(f"movingLoadConstraint {tag}: track {track_tag}: "
                               f"{str(exc).removeprefix('track: ')}") from None
        try:
            self._units.check_deck_mass(mass, f"movingLoadConstraint {tag}")
        except ModelError as exc:
            raise CommandError(str(exc)) from None
        self._constraint = dict(train=train_tag, track=track_tag, x_head0=x_head0,
                                irregularity=irregularity, interpolation=interpolation, exact_events=exact_events)
        self._coupled = None

    def contact(self, *args):
        """``contact('bilateral')`` (wheels always on the rail) or ``contact('lcp')`` (contact loss)."""
        a = Args("contact", args)
        self._contact = a.word("contact strategy", ("bilateral", "lcp"))
        a.done()
        self._coupled = None

    def deadLoad(self, *args):
        """``deadLoad [-selfWeight] [-dt dt]``: static equilibrium of bridge and train under the
        train's weight and the patterns; with ``-selfWeight`` also under the bridge's own weight
        (-g M in y, g = 9.81 m/s²), the results then being totals. Without it they are the response
        to the train and the patterns (a script that applies the deck's weight by a pattern gets
        totals). ``-dt``: the Δt [s] of the run that follows, which B-spline rows of a moving train
        need (they spread each wheel over 2 V Δt): refused without it before the first ``analyze``,
        and an ``analyze`` at another Δt right after it is refused. An option given twice is refused
        (as ``timeSeries Path``'s)."""
        a = Args("deadLoad", args)
        self_weight, dt = False, None
        while a.more():
            opt = a.option(("-selfWeight", "-dt"), once=True)
            if opt == "-selfWeight":
                self_weight = True
            else:
                dt = as_positive(a.option_floats("-dt", 1, "the run's time step [s]")[0], "deadLoad", "-dt",
                                 CommandError)
        if self_weight != self._self_weight:
            self._self_weight, self._coupled = self_weight, None
        spread = self._spread_rows()
        if spread and dt is None and self._run_dt is None:
            raise CommandError("deadLoad: the train's B-spline rows (movingLoadConstraint -bspline) spread each wheel "
                               "over 2 V dt, so the dead load depends on the run's time step: give it, deadLoad -dt "
                               "<dt> (the dt of the analyze that follows)")
        analysis = self._coupled_analysis("deadLoad", dt=dt if dt is not None else self._run_dt)
        self._run_dt = analysis.dt if dt is not None else self._run_dt
        self._dead_load_dt = analysis.dt if spread else None
        self._load_time = analysis.static()["time"]   # the loads applied now
        self._coupled_state = (analysis.coupled_loads, domain_state(analysis.model))    # the queries' train loads
        self._dead_load_done = True

    # -- the analysis ----------------------------------------------------------------------------
    def _spread_rows(self):
        """Whether the constraint's rows depend on Δt: B-spline rows of a moving train."""
        spec = self._constraint
        return (spec is not None and spec["interpolation"] == "bspline"
                and self._trains[spec["train"]].speed > 0.0)

    def _coupled_analysis(self, command, dt):
        if self._constraint is None:
            raise CommandError(f"{command}: no movingLoadConstraint defined")
        model = self._model(command)
        kind, integ = self._transient_integrator or ("Newmark", None)
        if kind in ("TRBDF2", "CentralDifference"):
            raise CommandError(f"{command}: integrator {kind} is not available for a coupled analysis; "
                               "use Newmark, HHT, GeneralizedAlpha or Bathe")
        bridge = self._modal_bridge(command)
        if self._coupled is None or self._coupled.model is not model or self._coupled.bridge is not bridge:
            spec = self._constraint
            subdomain = TrainSubdomain(self._trains[spec["train"]], spec["x_head0"])
            constraint = MovingLoadConstraint(Track(model, self._tracks[spec["track"]]), subdomain,
                                              spec["irregularity"], spec["interpolation"])
            self._coupled = CoupledAnalysis(model, constraint, integ, dt or 1.0, contact=self._contact,
                                            exact_events=spec["exact_events"], bridge=bridge,
                                            bridge_self_weight=self._self_weight, gravity=self._units.gravity)
            self._dead_load_done = False
        analysis = self._coupled
        if dt is not None:
            analysis.dt = float(dt)
        if integ is not None and analysis.integrator is not integ:
            analysis.integrator = coupled_integrator(integ, analysis.contact, command)
        return analysis

    def _analyze_coupled(self, n, dt):
        """``analyze(n, dt)`` with a moving-load constraint. The load time after it (``getLoadFactor``,
        ``loadConst``, the loads of ``nodeResponse`` id 7 and ``eleForce``) is where the last step
        applied the loads, as in the transient analysis without a train (:func:`equilibrium_point`):
        HHT and GeneralizedAlpha ``t_n + αΔt``, the others the step's end."""
        if self._dead_load_dt is not None and dt != self._dead_load_dt:
            raise CommandError(f"analyze: dt = {dt:g} s, but deadLoad solved the train's B-spline rows (spread over "
                               f"2 V dt) for dt = {self._dead_load_dt:g} s; give deadLoad -dt {dt:g}")
        analysis = self._coupled_analysis("analyze", dt)
        self._run_dt, self._dead_load_dt = dt, None
        if not self._dead_load_done:
            self._load_time = analysis.static()["time"]
            self._dead_load_done = True
        analysis.recorders = self._recorder_list()
        start = domain_state(analysis.model).time
        self._coupled_state = (analysis.coupled_loads, domain_state(analysis.model))    # the queries' train loads
        state = analysis.run(n)
        if n > 0:
            alpha = equilibrium_point(analysis.integrator)
            # the last step's start as the run computed it: the time before the run, or the end of
            # the step before (its record), bit for bit
            last_start = analysis.time[-2] if n > 1 else start
            self._load_time = state.time if alpha is None else last_start + alpha * dt
        return 0

    def _vehicle_recorder(self, *args):
        """``recorder('Contact', ...)`` or ``recorder('Train', ...)`` (see the module docstring)."""
        a = Args("recorder", args)
        kind = a.word("recorder type", ("Contact", "Train"))
        name = f"recorder {kind}"
        a.command = name
        opts = {"-time": False, "-precision": 6, "-dT": None, "-closeOnWrite": False}
        picks = None
        response = None
        responses = tuple(CONTACT_RESPONSES) if kind == "Contact" else TRAIN_RESPONSES
        valid = ["-file", "-h5", "-hdf5", "-time", "-precision", "-dT", "-wheel" if kind == "Contact" else "-dof"]
        given = set()
        while a.more():
            x = a.peek()
            if isinstance(x, str) and x.startswith("-"):
                opt = a.option(valid)
                given.add(opt)
                if opt in ("-file", "-h5", "-hdf5"):
                    self._file_option(a, name, opt, opts)
                elif opt == "-time":
                    opts["-time"] = True
                elif opt == "-precision":
                    opts[opt] = a.int("-precision")
                elif opt == "-dT":
                    opts[opt] = a.float("-dT")
                elif opt == "-wheel":
                    picks = a.ints("-wheel index")
                    if a.more() and a.peek() not in responses and not str(a.peek()).startswith("-"):
                        raise CommandError(f"{name}: -wheel index must be an integer, got {a.peek()!r}")
                else:
                    picks = []
                    while a.more() and not (isinstance(a.peek(), str) and (a.peek().startswith("-")
                                                                          or a.peek() in TRAIN_RESPONSES)):
                        pick = a.take("train dof")
                        if not (isinstance(pick, str) or is_int(pick)):
                            raise CommandError(f"{name}: -dof must be a train dof name or an integer index, "
                                               f"got {pick!r}")
                        picks.append(pick if isinstance(pick, str) else int(pick))
            else:
                if response is not None:
                    raise CommandError(f"{name}: give one response, got {response!r} and {a.peek()!r}")
                response = a.word("response", responses)
        if response is None:
            raise self._no_response(name, opts, responses)
        self._refuse_text_options(name, opts, given)
        analysis = self._coupled_analysis(name, dt=None)
        sink = self._recorder_sink(name, opts)
        if kind == "Contact":
            recorder = rec.ContactRecorder(analysis.constraint, picks, CONTACT_RESPONSES[response], sink=sink,
                                           dt=opts["-dT"])
        else:
            recorder = rec.TrainRecorder(analysis.train, picks, response, sink=sink, dt=opts["-dT"])
        return self._register_recorder(recorder)

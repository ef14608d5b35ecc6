"""The ``vtsi`` command (also ``python -m vtsi``); docs/cli.md.

    vtsi run SCRIPT.tcl [args ...]      run an OpenSees Tcl script with vtsi's command layer
    vtsi SCRIPT.tcl [args ...]          the same (the original form)
    vtsi sweep BRIDGE --trains ... --speeds ...   a speed sweep into an HDF5 results file
    vtsi check BRIDGE --trains ... --line-speed ...   the EN 1990 A2 / EN 1991-2 design check and report
    vtsi trains                         the train catalogue

Exit status of ``run``: the script's ``exit`` code, 0 when it ends normally; 2 a bad command line
or a command of the script that fails on its input (one line on standard error: the script, its
line and vtsi's message; ``--traceback`` adds the Tcl traceback); 1 an analysis of the script that
diverged (the line names the step and time) or a file it cannot write.
Exit status of ``sweep``: 0 done; 2 a bad command line or input (one line on standard error,
nothing written), or a results file another run is writing; 1 a passage failed while the sweep
ran (the finished cases stay in the results file); 130 interrupted (Ctrl-C) and 143 terminated
(SIGTERM, as Slurm and systemd stop a job): the finished cases stay in the results file
(``--resume``). A reader that closes standard output early (``| head``) changes nothing: the
results file is complete and the status is what it would have been.
Exit status of ``check``: 0 every criterion passes (PASS); 1 a criterion fails (FAIL), or no verdict
(NO VERDICT: an incomplete sweep, a criterion with a limit left not checked, or none held to a
limit; :meth:`vtsi.check.CheckResult.verdict`); 2 and 130, 143 as ``sweep``; 3 a passage failed.
"""
import argparse
import contextlib
import dataclasses
import os
import re
import signal
import sys
import threading

COMMANDS = ("run", "sweep", "check", "trains")
DEFAULT_OUT = "sweep.h5"
CHECK_OUT = "check.h5"
EXIT_FAILED, EXIT_USAGE, EXIT_INTERRUPTED, EXIT_TERMINATED = 1, 2, 130, 143
EXIT_CHECK_FAILS, EXIT_PASSAGE = 1, 3

SWEEP_EPILOG = """\
BRIDGE is a description file (.toml; .yaml/.yml with PyYAML) naming a built-in bridge, e.g.
  [bridge]
  kind = "beam"
  spans_m = [20.0]
  E_Pa = 3.5e10
  I_m4 = 1.9          # or f1_Hz = 5.0
  mu_kg_m = 15000.0
  elements_per_span = 10
  [analysis]          # optional defaults of the options below
  damping = 0.0125
  dt_s = 0.0005       # optional: by default Newmark's period error at the EN cut-off <= 0.1 zeta
or an OpenSees model script (.tcl, or .py using 'import vtsi.opensees as ops') that builds
the bridge and defines its track ('track 1 -eleRange 1 40'). Scripts must be in SI units
(N, kg, m, s, Pa): a model lighter than 500 kg/m along its track is refused.

TRAINS: catalogue names (see 'vtsi trains'; 'A1' for 'HSLM-A1'), 'HSLM-A' for all of
HSLM-A1 .. HSLM-A10, or axle-table CSV files (columns position_m, load_kN).
SPEEDS [km/h]: START:STOP:STEP (STOP included when on the grid), v1,v2,..., or en:LINE_SPEED
for the EN 1991-2 6.4.6.2 series (144 km/h to 1.2 x LINE_SPEED in 10 km/h steps, plus every
resonance speed n D / i itself (n each deck's first three vertical frequencies, D each train's
characteristic length, i = 1..4) and 2 km/h steps within +-10 % of it; rounded to 0.01 km/h);
at most 10000 speeds.

Prints the table of envelope maxima with the governing train and speed per quantity, and a
note when dt is coarser than the default's rule at the EN cut-off (20 steps a period and
Newmark's period error at most 0.1 zeta: what 'vtsi check' calls not converged). Exit status: 0 done; 2 bad command line or input (nothing written), or a results file another
run is writing or that cannot be created (nor its lock file); 1 a passage failed during the run (finished cases stay in the file); 130
interrupted (Ctrl-C), 143 terminated (SIGTERM): finished cases stay in the file, --resume
continues. --overwrite keeps the old file until the new sweep is complete (it is written to
FILE.h5.new meanwhile; --overwrite again continues it). A closed standard output (| head) does
not change the status."""


CHECK_EPILOG = """\
BRIDGE, TRAINS and SPEEDS as for 'vtsi sweep' (see 'vtsi sweep --help'); without --speeds the
EN 1991-2 6.4.6.2 series up to 1.2 x --line-speed. Damping: --damping ZETA, or --bridge-type
for the EN 1991-2 Table 6.6 lower bound of the longest span (+ --additional-damping, Eq. 6.13,
for moving forces: 0 on spans of 30 m or more). Writes the results file (--out), the checks in it, the
governing cases' time histories, a 3-D scene (when off-screen rendering works) and the report
(report.html, self-contained, and report.md with PNGs) in --report DIR. Prints the table of
checks: value, limit, utilisation, pass/fail, the governing train, speed and place."""


class _UsageError(Exception):
    """A bad value on the sweep's command line (reported like the API's errors, exit 2)."""


class _Terminated(KeyboardInterrupt):
    """SIGTERM (Slurm, systemd, kill), raised where Ctrl-C raises KeyboardInterrupt, so that a
    terminated sweep stops as an interrupted one does (exit 143)."""


def _on_sigterm(signum, frame):
    signal.signal(signal.SIGTERM, signal.SIG_IGN)      # once: the clean-up is not interrupted again
    raise _Terminated()


_SWALLOWED = []     # interrupts raised where Python ignores exceptions, to be raised again


def _unraisable_interrupt(unraisable, previous):
    """An interrupt raised while Python ran a callback whose exceptions it ignores (a weakref's,
    a __del__): raised again 50 ms later (SIGALRM), in the sweep's own code."""
    if isinstance(unraisable.exc_value, KeyboardInterrupt) and hasattr(signal, "setitimer"):
        _SWALLOWED.append(type(unraisable.exc_value))
        signal.setitimer(signal.ITIMER_REAL, 0.05)
        return
    previous(unraisable)


def _on_alarm(signum, frame):
    if _SWALLOWED:
        raise _SWALLOWED.pop()()


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """SIGTERM raises :class:`_Terminated` while a sweep or check runs, and an interrupt that
    Python swallowed is raised again (the main thread only; the previous handlers are
    restored after)."""
    if not hasattr(signal, "SIGTERM") or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    alarm = signal.signal(signal.SIGALRM, _on_alarm) if hasattr(signal, "SIGALRM") else None
    hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: _unraisable_interrupt(unraisable, hook)
    try:
        yield
    finally:
        sys.unraisablehook = hook
        if alarm is not None:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, alarm)
        signal.signal(signal.SIGTERM, previous)
        _SWALLOWED.clear()


def main(argv=None):
    """Entry point; ``argv`` defaults to ``sys.argv[1:]``. Returns the exit status."""
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    parser = _parser()
    if argv and argv[0] == "run":
        return _run(parser, argv[1:])
    if argv and not argv[0].startswith("-") and argv[0] not in COMMANDS:
        return _run(parser, argv)                 # the original form: vtsi SCRIPT.tcl [args]
    ns, unknown = parser.parse_known_args(argv)   # -h, --version, sweep, check, trains
    if unknown:                                   # told by the command's parser: its name and help
        parser.commands.get(ns.command, parser).error(f"unrecognized arguments: {' '.join(unknown)}")
    if ns.command is None:
        parser.error("a command (run, sweep, check, trains) or a Tcl script is required")
    if ns.command in ("sweep", "check"):
        with _sigterm_as_interrupt():
            return ns.func(ns)
    return ns.func(ns)


class _Parser(argparse.ArgumentParser):
    """argparse with a bad command line told in one line (status 2), as every other bad input."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} -h')\n")


def _parser():
    import vtsi

    parser = _Parser(
        prog="vtsi", usage="vtsi [-h] [--version] {run,sweep,check,trains} ...\n       vtsi SCRIPT.tcl [args ...]",
        description="vtsi: trains crossing railway bridges (vehicle-track-structure interaction). "
                    "'vtsi SCRIPT.tcl [args]' is 'vtsi run SCRIPT.tcl [args]'. Details: docs/cli.md.")
    parser.add_argument("--version", action="version", version=f"vtsi {vtsi.__version__}")
    sub = parser.add_subparsers(dest="command", title="commands", metavar="{run,sweep,check,trains}")

    run = sub.add_parser("run", prog="vtsi run",
                         help="run an OpenSees-style Tcl model script (its $argv: the arguments after it)",
                         usage="vtsi run [-h] [--traceback] SCRIPT.tcl [args ...]",
                         description="Run an OpenSees-style Tcl model script with vtsi; the arguments after the "
                                     "script are its $argv. Exit status: the script's 'exit' code, 0 when it ends "
                                     "normally; 2 a bad command line or a script command that fails on its input "
                                     "(one line: script, line, message); 1 an analysis that diverges or a file "
                                     "that cannot be written.")
    run.add_argument("--traceback", action="store_true",
                     help="after the one-line message of a failing command, print the Tcl traceback")
    run.add_argument("script", help="Tcl script to run (e.g. model.tcl)")
    run.add_argument("args", nargs="*", default=[], help="the script's $argv")
    parser.run_parser = run
    parser.commands = sub.choices

    sweep = sub.add_parser("sweep", prog="vtsi sweep",
                           help="run every train at every speed over a bridge into an HDF5 results file",
                           description="Run a speed sweep: every train at every speed (and every rail sample) over "
                                       "BRIDGE, in parallel, into a resumable HDF5 results file; print the table of "
                                       "envelope maxima.",
                           epilog=SWEEP_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    _sweep_options(sweep, check=False)
    sweep.set_defaults(func=_sweep)

    check = sub.add_parser("check", prog="vtsi check",
                           help="the EN 1990 A2 / EN 1991-2 dynamic design check: sweep, check, report",
                           description="The dynamic design check of a railway bridge: every train at every speed "
                                       "(EN 1991-2 6.4.6), the EN 1990 A2 / EN 1991-2 criteria on the results, the "
                                       "governing cases' histories, a 3-D scene and an HTML + Markdown report; prints "
                                       "a one-screen summary. Exit status: 0 every criterion passes (PASS); 1 a "
                                       "criterion fails (FAIL), or no verdict (NO VERDICT: an incomplete sweep, a "
                                       "criterion with a limit left not checked, or none held to a limit); 2 bad "
                                       "command line or input (nothing written), or a results file another run is "
                                       "writing or that cannot be created (nor its lock file); 3 a passage failed; 130 interrupted (Ctrl-C), 143 terminated "
                                       "(SIGTERM): finished cases stay in the file, --resume continues.",
                           epilog=CHECK_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    _sweep_options(check, check=True)
    rules = check.add_argument_group("code rules (EN 1990 A2, EN 1991-2)")
    rules.add_argument("--line-speed", metavar="KMH",
                       help="maximum line speed [km/h]: the speeds run from 144 km/h to 1.2 x it (EN 1991-2 "
                            "6.4.6.2), finer near resonances; needed unless --speeds is given")
    rules.add_argument("--bridge-type", metavar="TYPE",
                       help="EN 1991-2 Table 6.6 damping: steel, composite, prestressed_concrete, filler_beam, "
                            "reinforced_concrete (its lower bound for the longest span); or give --damping")
    rules.add_argument("--additional-damping", action="store_true",
                       help="add Delta zeta of EN 1991-2 Eq. 6.13 (moving forces; 0 for spans of 30 m or more)")
    rules.add_argument("--track-form", default="ballasted", metavar="FORM",
                       help="ballasted (3.5 m/s^2, default) or direct_fastening (5 m/s^2)")
    rules.add_argument("--comfort", default="good", metavar="LEVEL",
                       help="EN 1990 A2 Table A2.9 level: very_good, good (default), acceptable")
    rules.add_argument("--maintenance", default="careful", metavar="M",
                       help="careful (Phi2, phi''/2; default) or standard (Phi3, phi'')")
    rules.add_argument("--alpha", default="1.0", metavar="A", help="LM71 classification factor (default 1.0)")
    rules.add_argument("--unloading-limit", default="0.6", metavar="X",
                       help="wheel unloading Delta Q/Q limit (a project criterion; default 0.6)")
    check.add_argument("--report", metavar="DIR", help="report directory (default: <out>_report beside the results)")
    check.add_argument("--animation", action="store_true",
                       help="also a GIF of the governing passage (scene.gif in the report directory)")
    check.add_argument("--animation-frames", type=_int_at_least(2), metavar="N",
                       help="the GIF's number of frames, >= 2 (default: 4 n0 T + 1 over the passage's T seconds, "
                            "a quarter period of n0 apart, at most 400)")
    check.set_defaults(func=_check)

    trains = sub.add_parser("trains", prog="vtsi trains",
                            help="list the train catalogue: name, fidelities, description; or what vtsi reads "
                                 "of axle tables",
                            description="List the train catalogue (names for 'vtsi sweep --trains'); given axle "
                                        "tables, what vtsi reads of each: axles, total load, length, D.")
    trains.add_argument("tables", nargs="*", metavar="TABLE.csv",
                        help="axle tables (columns position_m, load_kN) to read as 'vtsi sweep --trains' does")
    trains.set_defaults(func=_trains)
    return parser


def _sweep_options(p, check):
    """The options ``vtsi sweep`` and ``vtsi check`` share."""
    p.add_argument("bridge", metavar="BRIDGE", help="bridge file: .toml/.yaml description or .tcl/.py model "
                                                    "script (SI units)")
    p.add_argument("--trains", required=True, metavar="T1,T2,...",
                   help="trains: catalogue names, HSLM-A (= HSLM-A1..A10) or axle CSV files, comma-separated")
    p.add_argument("--speeds", required=not check, metavar="SPEEDS",
                   help="speeds [km/h]: START:STOP:STEP, v1,v2,..., or en:LINE_SPEED (EN 1991-2 series)")
    p.add_argument("--out", metavar="FILE.h5", default=CHECK_OUT if check else DEFAULT_OUT,
                   help=f"results file (default: {CHECK_OUT if check else DEFAULT_OUT} in the current directory)")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--resume", action="store_true",
                      help="continue the sweep in an existing results file (a file of another sweep is refused)")
    mode.add_argument("--overwrite", action="store_true", help="replace an existing results file")
    p.add_argument("--workers", type=_int_at_least(1), metavar="N", help="processes (default: every core; 1: serial)")
    p.add_argument("--track", type=int, metavar="TAG", help="the track of a model script that defines several")
    settings = p.add_argument_group("passage settings (default: the bridge file's [analysis], else as shown)")
    settings.add_argument("--dt", type=float, metavar="S",
                          help="time step [s]; default 0.001 or finer: 20 steps a period of the EN cut-off frequency f "
                               "and, time-stepped, Newmark's period error there at most 0.1 zeta, dt <= sqrt(1.2 "
                               "zeta)/(2 pi f) (zeta the damping, at least 0.005; exact modal passages of moving "
                               "forces take the 20 samples a period only), with --cars full on an irregular rail also "
                               "20 steps a period of its shortest wavelength, 3 m, passed at the top speed; rounded down "
                               "to 1, 2, 2.5, 4 or 5 x 10^k s. A coarser dt is noted")
    settings.add_argument("--integrator", metavar="NAME",
                          help="Newmark, HHT(ALPHA) (e.g. 'HHT(0.9)'), GeneralizedAlpha or Bathe, parameters in "
                               "brackets; default: Newmark, or HHT(0.9) with --contact lcp (which refuses an "
                               "integrator without numerical damping)")
    settings.add_argument("--cars", choices=("force", "full"),
                          help="trains as moving axle forces (default) or multibody cars (catalogue trains with cars)")
    settings.add_argument("--contact", choices=("bilateral", "lcp"), help="bilateral (default) or lcp (contact loss)")
    settings.add_argument("--interpolation", choices=("hermite", "bspline"),
                          help="rail shape functions: hermite or bspline (default: bspline with --cars full, "
                               "hermite for moving forces)")
    settings.add_argument("--exact-events", action=argparse.BooleanOptionalAction, default=None,
                          help="take each kink of the rail line (a span's end next to rigid ground or to another "
                               "span's end, the rail profile's declared kinks) at its own time, for cars on hermite "
                               "rows (their default with it; bspline rows refuse it); --no-exact-events: the step "
                               "that holds a kink takes it (the default, over a bridge file's [analysis] "
                               "exact_events)")
    settings.add_argument("--bridge-model", choices=_bridge_models(),
                          help="fe (the FE bridge, time-stepped; default), modal (its modes up to --modal-hz, the "
                               "damping ratio on every mode: exact passages for moving forces, time-stepped for "
                               "cars) or modal-stepped (the modes, time-stepped for moving forces too)")
    settings.add_argument("--modal-hz", type=float, metavar="HZ",
                          help="the modal bridge's highest frequency [Hz] (default: 1.1 x the EN cut-off; with a "
                               "bending-moment output 1.1 x the larger of the cut-off and twice the trains' closest "
                               "axles' frequency at the top speed)")
    settings.add_argument("--damping", type=float, metavar="ZETA",
                          help="damping ratio of the bridge, e.g. 0.0125 (Rayleigh through n0 and the EN cut-off; with "
                               "--bridge-model modal: on every mode); " + (
                                   "required unless --bridge-type or the bridge file's [analysis] damping gives it "
                                   "(a bridge script's own damping is replaced, with a note)" if check else
                                   "default: the bridge as built (a beam: undamped)"))
    settings.add_argument("--irregularity", metavar="NAME",
                          help=f"rail irregularity spectrum: {', '.join(_irregularities())} (default: smooth rail)")
    settings.add_argument("--seeds", metavar="S1,S2,...",
                          help="rail samples with --irregularity: 0,1,2 or FIRST:LAST (default 0)")
    settings.add_argument("--hslm-b", type=_hslm_b_pair, metavar="N,d",
                          help="HSLM-B's N forces and their spacing d [m] for the span, read from EN 1991-2 Figure "
                               "6.13, e.g. 15,3.0 (default: vtsi's straight-line reading of the figure, not verified "
                               "against it, which the check says)")
    p.add_argument("--quiet", action="store_true",
                   help="on standard error no progress bar (else shown when a terminal), no "
                        "line of an axle table's D, " + ("no line of what the damping replaces, " if check else "")
                        + "no closing 'results in' line (errors and what a bridge script prints still show)")


def _int_at_least(low):
    """The argparse type of an integer >= ``low`` (else argparse's one-line error, naming the value)."""
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low:
            raise argparse.ArgumentTypeError(f"expected an integer >= {low}, got {text!r}")
        return value
    return parse


def _hslm_b_pair(text):
    """The argparse type of ``--hslm-b N,d``: (N, d [m]) checked (:func:`vtsi.models.trains.hslm_b_given`),
    else argparse's one-line error naming the value."""
    from vtsi.errors import ModelError
    from vtsi.models.trains import hslm_b_given

    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise ValueError
        pair = tuple(float(part) for part in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected N,d (N forces, spacing d in m, from EN 1991-2 Figure 6.13), e.g. "
                                         f"15,3.0; got {text!r}") from None
    try:
        return hslm_b_given(pair, "N,d")
    except ModelError as exc:
        raise argparse.ArgumentTypeError(f"{exc} (got {text!r})") from None


def _irregularities():
    from vtsi.passage import IRREGULARITIES
    return IRREGULARITIES


def _bridge_models():
    from vtsi.passage import BRIDGE_MODELS
    return BRIDGE_MODELS


# -- vtsi run ----------------------------------------------------------------------------------
def _run(parser, argv):
    from vtsi.commands.tcl import script_line
    from vtsi.errors import DivergenceError, VtsiError
    from vtsi.tcl import run_file

    split = next((k + 1 for k, word in enumerate(argv) if not word.startswith("-")), len(argv))
    ns = parser.run_parser.parse_args(argv[:split])
    if not os.path.isfile(ns.script) or not os.access(ns.script, os.R_OK):
        parser.run_parser.error(f"script {ns.script}: " + ("not a readable file" if os.path.exists(ns.script)
                                                            else "no such file"))
    if ns.script.endswith(".py"):
        parser.run_parser.error(f"script {ns.script}: a Python script; 'vtsi run' runs Tcl scripts "
                                f"(run it with: python {ns.script})")
    try:
        interp = run_file(ns.script, argv=argv[split:])
    except ImportError as exc:
        if "tkinter" not in str(exc):
            raise
        _print_err("vtsi: running Tcl scripts needs Python's tkinter, which this Python lacks "
                   "(Debian/Ubuntu: apt-get install python3-tk)")
        return EXIT_FAILED
    except (VtsiError, OSError) as exc:
        sys.stdout.flush()
        line = script_line(exc, ns.script)
        message = " ".join(str(exc).split("\n"))
        _print_err(f"vtsi: {ns.script}" + (f" line {line}" if line else "") + f": {message}")
        if ns.traceback:
            _print_err("\n".join(getattr(exc, "__notes__", ())))
        return EXIT_FAILED if isinstance(exc, (DivergenceError, OSError)) else EXIT_USAGE
    return interp.exit_code or 0


# -- vtsi trains -------------------------------------------------------------------------------
def _trains(ns):
    from vtsi.errors import VtsiError
    from vtsi.models.catalogue import describe, fidelities, train_names
    from vtsi.vehicle import Train

    if ns.tables:                      # what a sweep reads of each axle table, one line each
        status = 0
        for path in ns.tables:
            try:
                train = Train.from_csv(path, speed=1.0)
            except (VtsiError, OSError) as exc:      # named on standard error; the others still read
                status = _fail(exc, EXIT_USAGE, "trains")
                continue
            loads, peak = train.static_wheel_loads, train.signature_peak
            _print_out(f"{path}: {len(loads)} axle{'s' * (len(loads) > 1)}, {loads.sum() / 1e3:g} kN in all "
                       f"({loads.min() / 1e3:g} to {loads.max() / 1e3:g} kN an axle), {train.length:g} m from the "
                       "first axle to the last; "
                       + (peak.text() if peak is not None else f"D = {train.characteristic_length:g} m"))
        return status
    rows = [("name", "fidelities", "description")]
    for name in train_names():
        text = describe(name)
        rows.append((name, ",".join(fidelities(name)), text[len(name) + 2:] if text.startswith(name + ": ") else text))
    widths = [max(len(r[j]) for r in rows) for j in range(2)]
    _print_out("\n".join(f"{r[0].ljust(widths[0])}  {r[1].ljust(widths[1])}  {r[2]}" for r in rows)
               + "\n\nIn 'vtsi sweep --trains': names ignore case, 'A1' stands for 'HSLM-A1', 'HSLM-A' for "
                 "HSLM-A1 .. HSLM-A10;\na path to a .csv axle table (columns position_m, load_kN) is a train of "
                 "moving forces.")
    return 0


# -- vtsi sweep --------------------------------------------------------------------------------
def _sweep(ns):
    """Check everything, then run; see the module docstring for the exit statuses."""
    from vtsi.errors import VtsiError

    out = os.path.abspath(ns.out)
    try:
        sweep = _prepare_sweep(ns, out)
    except (VtsiError, OSError, _UsageError) as exc:
        return _fail(exc, EXIT_USAGE)
    except KeyboardInterrupt as exc:
        return _stopped(exc)
    return _run_sweep(sweep, ns, out)


def _speeds_reach(spec, line_kmh):
    """A usage error unless the --speeds ``spec`` reaches 1.2 × the line speed [km/h], as EN
    1991-2 6.4.6.2(1) asks of a check (an en:LINE_SPEED spec must name the same line speed)."""
    from vtsi.sweep import speeds

    text = spec.strip()
    if text.lower().startswith("en:"):
        try:
            same = float(text[3:]) == line_kmh
        except ValueError:
            return                              # _prepare_sweep names the malformed spec
        if not same:
            raise _UsageError(f"--speeds {spec!r} and --line-speed {line_kmh:g} name two line speeds; give one")
        return
    top = float(speeds(spec).max())
    if top < 1.2 * line_kmh * (1 - 1e-9):
        raise _UsageError(f"--speeds reach {top:g} km/h, short of 1.2 x --line-speed {line_kmh:g} = {1.2 * line_kmh:g} "
                          "km/h that EN 1991-2 6.4.6.2(1) asks; extend them, or leave --speeds out (the EN series)")


def _prepare_sweep(ns, out):
    from vtsi.bridge_file import ANALYSIS_KEYS, read_bridge_file
    from vtsi.errors import BridgeError, SettingError
    from vtsi.passage import PassageRunner, PassageSettings
    from vtsi.sweep import Sweep, en_speed_grid, speeds
    from vtsi.sweep_results import ResultsWriter

    trains = _train_list(ns.trains)
    spec = ns.speeds.strip()
    en_line = None
    if spec.lower().startswith("en:"):
        try:
            en_line = float(spec[3:])
        except ValueError:
            raise _UsageError(f"--speeds {spec!r}: expected en:LINE_SPEED_KMH, e.g. en:300") from None
    else:
        speeds(spec)                                   # fail fast, before the bridge is built
    _check_out_path(out, ns)
    with _stdout_to_stderr():                          # stdout carries only the results table
        source = read_bridge_file(ns.bridge, ns.track)
    values = dict(source.settings)
    given = {name: getattr(ns, name) for name in ("dt", "integrator", "cars", "contact", "interpolation", "damping",
                                                  "irregularity", "modal_hz", "hslm_b", "exact_events")
             if getattr(ns, name) is not None}
    if ns.bridge_model is not None:
        given["bridge"] = ns.bridge_model
    values.update(given)
    try:                                               # the bridge is analysed from here on
        if getattr(ns, "command", None) == "check":
            values["damping"] = _code_damping(ns, source, values)
        settings = PassageSettings(**values)
        seeds = source.seeds
        if source.seeds is not None and ns.seeds is None and settings.irregularity is None:
            raise _UsageError(f"bridge file {source.path}: [analysis] seeds: rail samples need an irregular rail "
                              "([analysis] irregularity, or --irregularity NAME)")
        if ns.seeds is not None:
            if settings.irregularity is None:
                raise _UsageError("--seeds: rail samples need an irregular rail (--irregularity NAME)")
            seeds = _seed_list(ns.seeds)
        if en_line is not None:
            runner = PassageRunner(source.bridge.model, source.bridge.track_elements, settings, outputs=())
            lengths = [runner.train(t, 40.0).characteristic_length for t in trains]   # None: fine steps throughout
            spec = en_speed_grid(en_line, runner.deck_frequencies.ravel(), lengths)    # every deck's resonances
        sweep = Sweep(source.bridge, ns.trains, spec, settings, seeds=seeds)     # its refusals quote the text given
    except BridgeError as exc:
        # what the analysis found wrong with the bridge (a BridgeError, whatever its words) names the
        # file it came from (a script's model has no other name): 'bridge file b.tcl: bridge (its
        # track: ...): vertical frequencies ...'; any other error is the trains', speeds' or settings'
        text = _message(exc)
        if str(source.path) in text:
            raise
        raise _UsageError(f"bridge file {source.path}: {text}") from None
    except SettingError as exc:                        # a setting the bridge file gave: its key named
        key = next((k for k, name in ANALYSIS_KEYS.items() if name == exc.setting), None)
        if key is None or exc.setting not in source.settings or exc.setting in given:
            raise
        raise _UsageError(f"bridge file {source.path}: [analysis] {key} = {source.settings[exc.setting]!r}: "
                          f"{_message(exc)}") from None
    sweep.prepare()                                    # integrator, contact ...: refused before any file is written
    if not ns.quiet:                                   # where each axle table's D came from, once
        for name in trains:
            peak = sweep.runner.train(name, 40.0).signature_peak
            if peak is not None:
                _print_err(f"vtsi {ns.command}: {name}: {peak.text()}" + (
                    "" if peak.length_m is not None else
                    ": its resonances are unknown; the EN series steps 2 km/h throughout for it"))
    if os.path.exists(out) and not ns.overwrite:      # refuses, or checks the file to resume (and its lock)
        ResultsWriter(out, sweep.identity(), sweep.runner, resume=ns.resume).close()
    return sweep


def _code_damping(ns, source, values):
    """The check's damping ratio: --damping (or the bridge file's), else EN 1991-2 Table 6.6 for
    --bridge-type at the longest span (+ Eq. 6.13 with --additional-damping). Sets
    ``ns.damping_source``, where it came from in words, with what it replaces (the bridge file's
    [analysis] damping, a bridge script's own damping: :func:`_script_damping`); stored with the
    check, printed in the report. Notes on standard error (unless --quiet) when --bridge-type
    replaces the bridge file's [analysis] damping, and when --bridge-type or --damping replaces
    a bridge script's own damping."""
    from vtsi.codes.en1991_2 import additional_damping, additional_damping_text, damping_lower_bound
    from vtsi.passage import PassageRunner, PassageSettings

    in_file = source.settings.get("damping")
    runner = None                                       # the bridge's spans and frequencies, read once
    if ns.bridge_type is not None and ns.damping is None:
        runner = PassageRunner(source.bridge.model, source.bridge.track_elements, PassageSettings(), outputs=())
    in_script = _script_damping(source.bridge, runner)  # '' unless a bridge script damps its model
    file_text = None if in_file is None else f"the bridge file's [analysis] damping = {in_file:g}"
    if ns.bridge_type is None:
        if values.get("damping") is None:
            raise _UsageError("the bridge's damping is needed: --bridge-type TYPE (EN 1991-2 Table 6.6) or "
                              "--damping ZETA" + (f"; a check does not take {in_script}" if in_script else ""))
        if ns.additional_damping:
            raise _UsageError("--additional-damping adds to the Table 6.6 value: give --bridge-type")
        zeta = values["damping"]
        if ns.damping is None:                          # the bridge file's, over its script's: no note
            ns.damping_source = f"{file_text} ({os.path.basename(source.path)})" + (
                f"; it replaces {in_script}" if in_script else "")
            return zeta
        how = option = f"--damping {ns.damping:g}"
        noted = [in_script]                             # [analysis] damping is the option's default: no note
    else:
        if ns.damping is not None:
            raise _UsageError("give either --bridge-type (EN 1991-2 Table 6.6) or --damping, not both")
        span = float(max(runner.span_lengths))
        zeta = base = damping_lower_bound(ns.bridge_type, span)
        how = f"EN 1991-2 Table 6.6, {ns.bridge_type.replace('_', ' ')}, longest span L = {span:g} m: {_percent(base)}"
        if ns.additional_damping:
            if values.get("cars", "force") != "force":
                raise _UsageError("--additional-damping (EN 1991-2 Eq. 6.13) is for moving forces; the cars' "
                                  "interaction is in the model with --cars full")
            extra = additional_damping(span)
            zeta += extra
            how += f" + {additional_damping_text(span)} = {_percent(zeta)}"
        option = f"--bridge-type {ns.bridge_type}"
        noted = [file_text and f"{file_text} ({os.path.basename(source.path)})", in_script]
    replaced = [text for text in (file_text and f"{file_text} ({_percent(in_file)})", in_script) if text]
    noted = [text for text in noted if text]
    ns.damping_source = how + (f"; it replaces {' and '.join(replaced)}" if replaced else "")
    if noted and not ns.quiet:
        _print_err(f"vtsi check: {option} replaces {' and '.join(noted)} by ζ = {_percent(zeta)}" +
                   ("" if how == option else f": {how}"))
    return zeta


def _script_damping(bridge, runner=None):
    """The damping a bridge script gives its model, in words naming the script (a sweep with a
    damping ratio of its own replaces it: :class:`~vtsi.passage.PassageRunner`), or '' (none,
    or a bridge that is not a script): its ``rayleigh`` factors αM [1/s], βK [s] (βK the sum of
    OpenSees's three) with the ratio ζ they give at the bridge's n₀ and at the EN cut-off
    (:func:`vtsi.damping.rayleigh_ratio`; the frequencies of ``runner``, a
    :class:`~vtsi.passage.PassageRunner` of the bridge, else of one built here) and its
    ``modalDamping`` ratios on the modes of its latest ``eigen``."""
    from vtsi.damping import rayleigh_ratio
    from vtsi.passage import PassageRunner, PassageSettings
    from vtsi.sweep_results import significant_text

    if bridge.description.get("kind") != "script":
        return ""
    parts = []
    alpha_m, beta_k = bridge.model.rayleigh_factors
    if alpha_m or beta_k:
        if runner is None:
            runner = PassageRunner(bridge.model, bridge.track_elements, PassageSettings(), outputs=())
        n0, cutoff = float(runner.frequencies[0]), float(runner.en_cutoff_hz)
        at_n0, at_cutoff = rayleigh_ratio([n0, cutoff], alpha_m, beta_k)
        parts.append(f"rayleigh αM = {alpha_m:g} 1/s, βK = {beta_k:g} s (ζ = {_percent(at_n0)} at n0 = "
                     f"{significant_text(n0)} Hz, {_percent(at_cutoff)} at the EN cut-off "
                     f"{significant_text(cutoff)} Hz)")
    if bridge.modal_damping:
        ratios = [z for _, z in bridge.modal_damping]
        n = len(ratios)
        parts.append("modalDamping " + (f"{ratios[0]:g}" if len(set(ratios)) == 1 else " ".join(f"{z:g}" for z in ratios))
                     + (" on mode 1 of its eigen" if n == 1 else f" on modes 1-{n} of its eigen"))
    if not parts:
        return ""
    return f"the bridge script's {' and '.join(parts)} ({os.path.basename(bridge.description['path'])})"


def _damping_text(sweep, ns):
    """The damping a sweep's passages had, in words for the bridge line of ``vtsi sweep``'s
    summary and of ``vtsi check``'s table: the ratio ζ of its settings and where it came from
    (``vtsi check``: ``ns.damping_source``, as its report says it; ``vtsi sweep``: --damping or
    the bridge file's [analysis] damping), with the Rayleigh anchors of the FE bridge's
    ``damping_hz`` when given, as the report's table says them; else the bridge script's own
    (:func:`_script_damping`), else none."""
    from vtsi.sweep_results import significant_text

    zeta = sweep.settings.damping
    in_script = _script_damping(sweep.bridge, sweep.runner)
    if zeta is not None:
        where = getattr(ns, "damping_source", "")
        if not where:
            where = ("--damping" if ns.damping is not None else "the bridge file's [analysis] damping") + (
                ", over the script's own" if in_script else "")
        pair = sweep.settings.damping_hz if sweep.settings.bridge == "fe" else None
        anchors = f"Rayleigh, through {significant_text(pair[0])} and {significant_text(pair[1])} Hz; " if pair else ""
        return f"damping ζ = {_percent(zeta)} ({anchors}{where})"
    if in_script:
        return f"damping: {in_script}"
    script = sweep.bridge.description.get("kind") == "script"
    return f"damping: none ({'the script defines' if script else 'the bridge file gives'} none; --damping ZETA)"


def _percent(zeta):
    """A damping ratio [-] in percent, three significant digits: 0.012965 -> '1.3 %'."""
    return f"{100 * float(zeta):.3g} %"


def _check_numbers(ns):
    """The check's settings from the command line (numbers read here, with one-line errors)."""
    from vtsi.check import CheckSettings

    numbers = {}
    for option, name in (("--alpha", "alpha"), ("--unloading-limit", "unloading_limit")):
        text = getattr(ns, name)
        try:
            numbers[name] = float(text)
        except ValueError:
            raise _UsageError(f"{option} {text!r}: expected a number") from None
    return CheckSettings(track=ns.track_form, comfort=ns.comfort, maintenance=ns.maintenance, **numbers)


def _check(ns):
    """Sweep, check, histories of the governing cases, scene and report; see ``vtsi check -h``."""
    from vtsi.check import SELF_WEIGHT_REFUSED
    from vtsi.errors import SweepError, VtsiError
    from vtsi.workflow import refuse_before_sweep

    out = os.path.abspath(ns.out)
    report_dir = os.path.abspath(ns.report or os.path.splitext(out)[0] + "_report")
    try:
        settings = _check_numbers(ns)
        if ns.speeds is None and ns.line_speed is None:
            raise _UsageError("the line speed is needed: --line-speed KMH (the speeds run up to 1.2 x it), "
                              "or --speeds")
        if ns.line_speed is not None:
            try:
                line = float(ns.line_speed)
            except ValueError:
                raise _UsageError(f"--line-speed {ns.line_speed!r}: expected a speed in km/h") from None
            if ns.speeds is None:
                ns.speeds = f"en:{line}"
            else:
                _speeds_reach(ns.speeds, line)
        if os.path.exists(report_dir) and not os.path.isdir(report_dir):
            raise _UsageError(f"--report {report_dir}: exists and is not a directory")
        if ns.animation_frames is not None and not ns.animation:
            raise _UsageError(f"--animation-frames {ns.animation_frames}: the frames of the GIF of --animation; "
                              "give --animation too")
        ns.damping_source = ""
        sweep = _prepare_sweep(ns, out)
        settings = dataclasses.replace(settings, damping_source=ns.damping_source,     # provenance: in the report
                                       line_speed_kmh=None if ns.line_speed is None else line)
        if sweep.settings.bridge_self_weight:
            raise _UsageError(SELF_WEIGHT_REFUSED.removeprefix("check: "))
        try:                                           # what the check would refuse after the sweep: refused now
            refuse_before_sweep(sweep, settings)       # (once: design_check is told, refuse_first=False)
        except SweepError as exc:
            raise _UsageError(_message(exc).removeprefix("check: ")) from None
    except (VtsiError, OSError, _UsageError) as exc:
        return _fail(exc, EXIT_USAGE, "check")
    except KeyboardInterrupt as exc:
        return _stopped(exc, "check")
    status = _run_sweep(sweep, ns, out, summary=False, command="check")
    if status != 0:
        return EXIT_PASSAGE if status == EXIT_FAILED else status
    try:
        return _check_and_report(sweep, out, report_dir, settings, ns)
    except (VtsiError, OSError) as exc:
        return _fail(exc, EXIT_PASSAGE, "check")
    except KeyboardInterrupt as exc:
        return _stopped(exc, "check", " (the results are in the file; --resume)")


def _check_and_report(sweep, out, report_dir, settings, ns):
    from vtsi.workflow import design_check

    result, paths = design_check(sweep, out, settings, report_dir, workers=ns.workers, resume=True,
                                 animation=ns.animation, animation_frames=ns.animation_frames, refuse_first=False)
    _print_out(dataclasses.replace(result, bridge=f"{result.bridge}; {_damping_text(sweep, ns)}").text())
    if not ns.quiet:
        _print_err(f"vtsi check: results in {out}; report in {paths['html']}" +
                   ("" if paths["scene"] else " (no 3-D scene: off-screen rendering is not available)"))
    return 0 if result.passed else EXIT_CHECK_FAILS


def _train_list(text):
    from vtsi.sweep import train_list

    out = train_list(text)
    if not out:
        raise _UsageError(f"--trains {text!r}: no train")
    return out


def _seed_list(text):
    """The seeds of ``--seeds`` (0,1,2 or FIRST:LAST); the sweep checks their range and count."""
    from vtsi.sweep import MAX_SEEDS

    try:
        if ":" in text:
            first, last = (int(p) for p in text.split(":"))
            if first < 0 or last < first:
                raise ValueError
            if last - first >= MAX_SEEDS:
                raise _UsageError(f"--seeds {text!r}: {last - first + 1} rail samples; at most {MAX_SEEDS}")
            seeds = list(range(first, last + 1))
        else:
            seeds = [int(p) for p in text.split(",") if p.strip()]
    except ValueError:
        raise _UsageError(f"--seeds {text!r}: expected integers >= 0: 0,1,2 or FIRST:LAST") from None
    if not seeds or min(seeds) < 0:
        raise _UsageError(f"--seeds {text!r}: expected integers >= 0: 0,1,2 or FIRST:LAST")
    return seeds


def _check_out_path(out, ns):
    """Refuse, before anything is computed, a results file that cannot be written or that
    exists without --resume/--overwrite (the sweep would refuse it too, after building)."""
    from vtsi.errors import SweepError

    if os.path.isdir(out):
        raise SweepError(f"results file {out} is a directory")
    if os.path.exists(out) and not (ns.resume or ns.overwrite):
        raise SweepError(f"results file {out} exists; --resume continues its sweep, --overwrite replaces it")
    parent = os.path.dirname(out)
    if not os.path.isdir(parent):
        raise SweepError(f"results file {out}: the directory {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise SweepError(f"results file {out}: cannot write in {parent}")


def _run_sweep(sweep, ns, out, summary=True, command="sweep"):
    from vtsi.errors import VtsiError
    from vtsi.sweep_results import ResultsFileRefused, SweepResults, staging_path

    replacing = bool(ns.overwrite) and os.path.exists(out)     # the old file stays until the new sweep is complete
    where = staging_path(out) if replacing else out            # the new sweep's file meanwhile
    fresh = ns.overwrite or not os.path.exists(out)
    try:
        results = sweep.run(out, workers=ns.workers, progress=False if ns.quiet else None, resume=ns.resume,
                            overwrite=ns.overwrite)
    except ResultsFileRefused as exc:       # before any passage ran (a bad input); another run's files left alone
        return _fail(exc, EXIT_USAGE, command)
    except (VtsiError, OSError, KeyboardInterrupt) as exc:
        done = 0
        if os.path.exists(where):
            try:
                done = SweepResults(where).n_done
            except (VtsiError, OSError):
                done = -1
            if fresh and done == 0:
                os.remove(where)                        # nothing computed: leave nothing behind
        if done > 0 and replacing:
            kept = (f" ({done} of {len(sweep.cases)} cases of the new sweep are in {where}; {out} keeps the old "
                    "sweep until the new one is complete: --overwrite again continues it")
        elif done > 0:
            kept = f" ({done} of {len(sweep.cases)} cases are in {out}" + ("; --resume runs the rest"
                                                                           if isinstance(exc, KeyboardInterrupt) else "")
        else:
            kept = f" ({out} is as it was" if replacing else ""
        if isinstance(exc, KeyboardInterrupt):
            return _stopped(exc, command, kept + ")" if kept else "")
        return _fail(_message(exc) + (kept + ")" if kept else ""), EXIT_FAILED, command)
    if summary:                                     # a dt the check would call unconverged; a free track end
        notes = [note for note in (sweep.resolution_note(), sweep.free_end_note()) if note]
        _print_out(results.summary(_damping_text(sweep, ns)) + "".join(f"\n{note}" for note in notes))
        if not ns.quiet:
            _print_err(f"vtsi sweep: results in {out}")
    return 0


def _stopped(exc, command="sweep", detail=""):
    """The line and status of a run stopped by Ctrl-C (130) or by SIGTERM (143)."""
    if isinstance(exc, _Terminated):
        return _fail("terminated" + detail, EXIT_TERMINATED, command)
    return _fail("interrupted" + detail, EXIT_INTERRUPTED, command)


def _print_out(text, stream=None):
    """Print ``text`` on standard output (or ``stream``, standard error). A reader that closed it
    (``vtsi sweep ... | head -1``, or ``2>&1 | head -1``) is not an error: the rest of the text
    is dropped (the stream goes to the null device, so that nothing fails again when Python
    flushes it at exit), and the exit status stays what the run's outcome makes it."""
    stream = stream or sys.stdout
    try:
        print(text, file=stream)
        stream.flush()
    except BrokenPipeError:
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            os.dup2(null, stream.fileno())
            os.close(null)
        except (AttributeError, OSError, ValueError):
            pass


def _print_err(text):
    """Print ``text`` on standard error (:func:`_print_out`)."""
    _print_out(text, sys.stderr)


def _message(exc):
    """The error as one line, without the API's own 'sweep: ' prefix, naming the command line's
    options only ('overwrite=True (--overwrite)' is '--overwrite')."""
    text = " ".join(line.strip() for line in str(exc).splitlines() if line.strip())
    text = re.sub(r"\b\w+=True \((--[\w-]+)\)", r"\1", text)
    if isinstance(exc, OSError) and exc.filename and exc.strerror:
        text = f"{exc.filename}: {exc.strerror}"
    return text[len("sweep: "):] if text.startswith("sweep: ") else text


def _fail(exc, status, command="sweep"):
    try:
        sys.stdout.flush()
    except OSError:                 # a closed pipe: the line below still goes to standard error
        pass
    _print_err(f"vtsi {command}: {exc if isinstance(exc, str) else _message(exc)}")
    return status


@contextlib.contextmanager
def _stdout_to_stderr():
    """Send what a bridge script prints (Python's print and Tcl's puts, which writes to file
    descriptor 1) to standard error while it runs."""
    sys.stdout.flush()
    saved = None
    try:
        fd = sys.__stdout__.fileno()
        saved = os.dup(fd)
        os.dup2(sys.__stderr__.fileno(), fd)
    except (AttributeError, OSError, ValueError):
        saved = None
    try:
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        if saved is not None:
            os.dup2(saved, fd)
            os.close(saved)


if __name__ == "__main__":
    sys.exit(main())

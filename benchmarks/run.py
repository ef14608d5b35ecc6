"""Run vtsi's speed and accuracy benchmarks (one command, see benchmarks/README.md).

    python benchmarks/run.py --list               # the scenes, one line each
    python benchmarks/run.py S1                   # a table
    python benchmarks/run.py S1 --baseline        # + the 'python loop + scipy splu' column
    python benchmarks/run.py S1 --json            # one JSON object on stdout, nothing else
    python benchmarks/run.py S1 --json --quick    # reduced size (what the tests run)
    python benchmarks/run.py S3 --chart DIR       # + PNG charts in DIR, created if missing (implies --json)
    python benchmarks/run.py S10                  # a car sweep: CPU per passage against its compiled loop's

Exit status: 0 on success, 2 on a usage error (unknown scene, a --chart folder that cannot be
created: refused before the run), 3 when a module the scene needs
(e.g. openseespy, its peer) cannot be imported.
"""
import argparse
import contextlib
import importlib
import inspect
import json
import os
import platform
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

from scenes import discover  # noqa: E402

INSTALL_HINT = {"openseespy": "pip install openseespy (on Debian/Ubuntu it also needs: apt-get install libblas3 liblapack3)"}


@contextlib.contextmanager
def stdout_to_stderr():
    """Send everything written to file descriptor 1 (Python or C code, e.g. OpenSees) to stderr."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def check_requirements(scene):
    for module in scene.requires:
        try:
            importlib.import_module(module)
        except Exception as exc:       # ImportError, or OSError from a missing shared library
            hint = INSTALL_HINT.get(module, f"pip install {module}")
            sys.stderr.write(f"benchmarks/run.py: scene {scene.name} needs {module}, which is not importable "
                             f"({type(exc).__name__}: {exc}).\nInstall it: {hint}\n")
            sys.exit(3)


def versions():
    out = {"python": platform.python_version()}
    for name in ("vtsi", "numpy", "scipy", "numba", "openseespy"):
        try:
            from importlib.metadata import version
            out[name] = version(name)
        except Exception:
            out[name] = None
    return out


def format_table(result, columns):
    rows = [[header for _, header, _ in columns]]
    for case in result["cases"]:
        rows.append([fmt.format(case[key]) if key in case else "–" for key, _, fmt in columns])
    keep = [j for j in range(len(columns)) if any(r[j] != "–" for r in rows[1:])]
    rows = [[r[j] for j in keep] for r in rows]
    widths = [max(len(r[j]) for r in rows) for j in range(len(keep))]
    line = lambda r: "  ".join(c.rjust(w) for c, w in zip(r, widths))
    out = [line(rows[0]), "  ".join("-" * w for w in widths)]
    out += [line(r) for r in rows[1:]]
    return "\n".join(out)


def main(argv=None):
    scenes = discover()
    parser = argparse.ArgumentParser(prog="benchmarks/run.py", description="vtsi benchmarks")
    parser.add_argument("scene", nargs="?", help="scene name (" + ", ".join(scenes) + ")")
    parser.add_argument("--list", action="store_true", help="list the scenes and exit")
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    parser.add_argument("--quick", action="store_true", help="reduced size (fewer steps, smallest model only)")
    parser.add_argument("--baseline", action="store_true",
                        help="also time a plain Python loop with scipy splu (factored once)")
    parser.add_argument("--repeats", type=int, default=3, help="best of this many repetitions (default 3)")
    parser.add_argument("--chart", metavar="DIR",
                        help="write the scene's PNG charts to DIR, created if missing (scenes that draw charts: S3, S8); "
                             "implies --json")
    args = parser.parse_args(argv)

    if args.list:
        for name, scene in scenes.items():
            print(f"{name}  {scene.description}")
        return 0
    if args.scene is None:
        parser.error("name a scene (or --list)")
    name = args.scene.upper()
    if name not in scenes:
        parser.error(f"unknown scene {args.scene!r}; known: {', '.join(scenes)}")
    if args.repeats < 1:
        parser.error(f"--repeats must be >= 1, got {args.repeats}")
    scene = scenes[name]
    options = {}
    if args.chart is not None:
        if "chart" not in inspect.signature(scene.run).parameters:
            parser.error(f"scene {name} draws no charts (--chart)")
        try:       # now, not after a run of minutes: the scene writes its PNGs into an existing folder
            os.makedirs(args.chart, exist_ok=True)
        except OSError as exc:
            what = "is a file, not a folder" if os.path.isfile(args.chart) else \
                f"cannot be created ({exc.strerror or exc})"
            parser.error(f"--chart {args.chart!r} {what}")
        options["chart"] = args.chart
        args.json = True
    check_requirements(scene)

    guard = stdout_to_stderr() if args.json else contextlib.nullcontext()
    with guard:
        result = scene.run(quick=args.quick, baseline=args.baseline, repeats=args.repeats, **options)
    result["versions"] = versions()
    result["cpu_count"] = os.cpu_count()
    result["load_average"] = list(os.getloadavg()) if hasattr(os, "getloadavg") else None
    if args.json:
        print(json.dumps(result))
    else:
        print(f"{name}: {scene.description}")
        timed = getattr(scene, "timed", "time loop only")      # what the scene's times hold (S10: whole passages)
        print(f"best of {args.repeats}; {timed}; load average {result['load_average']}")
        print(format_table(result, scene.columns))
    return 0


if __name__ == "__main__":
    sys.exit(main())

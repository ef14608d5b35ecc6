"""``python -m vtsi model.tcl [args...]`` (and the ``vtsi`` console script): run an OpenSees
Tcl script with vtsi's command layer (:mod:`vtsi.tcl`).

Exit status: the script's ``exit`` code, 0 when it ends normally, 1 when a command fails (the
message, with the Tcl traceback, goes to standard error), 2 for a bad command line.
"""
import argparse
import sys


def main(argv=None):
    """Entry point; ``argv`` defaults to ``sys.argv[1:]``. Returns the exit status."""
    import vtsi
    from vtsi.errors import VtsiError
    from vtsi.tcl import run_file

    parser = argparse.ArgumentParser(prog="vtsi", usage="vtsi [-h] [--version] script.tcl [args ...]",
                                     description="Run an OpenSees-style Tcl model script with vtsi; the "
                                                 "arguments after the script are its $argv.")
    parser.add_argument("script", help="Tcl script to run (e.g. model.tcl)")
    parser.add_argument("--version", action="version", version=f"vtsi {vtsi.__version__}")
    argv = sys.argv[1:] if argv is None else list(argv)
    split = 1 if argv and not argv[0].startswith("-") else len(argv)
    ns = parser.parse_args(argv[:split])
    try:
        interp = run_file(ns.script, argv=argv[split:])
    except (VtsiError, OSError) as exc:
        sys.stdout.flush()
        notes = "\n".join(getattr(exc, "__notes__", ()))
        print(f"vtsi: {ns.script}: {type(exc).__name__}: {exc}" + (f"\n{notes}" if notes else ""), file=sys.stderr)
        return 1
    return interp.exit_code or 0


if __name__ == "__main__":
    sys.exit(main())

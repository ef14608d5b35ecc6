"""Run OpenSees Tcl scripts with vtsi: ``from vtsi.tcl import run_file, Interpreter`` (the runner
is :mod:`vtsi.commands.tcl`; the Tcl word rules are in :mod:`vtsi.commands.args`)."""
from vtsi.commands.args import convert_word, split_list
from vtsi.commands.tcl import Interpreter, run_file

__all__ = ["Interpreter", "run_file", "convert_word", "split_list"]

"""Straightforward implementations of vtsi's algorithms (plain Python loops over numpy/scipy),
measured side by side with vtsi by the benchmark scenes (e.g. S5)."""

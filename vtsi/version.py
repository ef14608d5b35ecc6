"""vtsi's version (one place: the package, the results files and setup.cfg read it)."""
__version__ = "0.1.0"

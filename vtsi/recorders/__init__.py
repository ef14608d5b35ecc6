"""Recorders (``vtsi.recorders``): see :mod:`.base` for the contract."""
from .base import Recorder
from .node import NodeRecorder

__all__ = ["Recorder", "NodeRecorder"]

"""Recorders (``vtsi.recorders``): what is recorded (node, reaction, element responses), where it
goes (memory, HDF5, OpenSees text) and envelopes. See :mod:`.base` for the contract and
``docs/recorders.md`` for the columns, units and file layouts."""
from .base import Recorder
from .element import ElementRecorder
from .envelope import Envelope
from .modal import ModalNodeRecorder
from .node import NodeRecorder, ReactionRecorder
from .sinks import HDF5Sink, MemorySink, Sink, TextSink
from .vehicle import ContactRecorder, TrainRecorder

__all__ = ["Recorder", "NodeRecorder", "ReactionRecorder", "ElementRecorder", "ModalNodeRecorder", "Envelope",
           "Sink", "MemorySink", "HDF5Sink", "TextSink", "TrainRecorder", "ContactRecorder"]

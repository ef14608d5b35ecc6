"""The recorder contract.

A recorder names, once, the dof responses it needs; the analysis records them in compiled
code and hands each chunk of steps over. Recorders never slow the time loop down and never
lose what was computed: a chunk is written before the next one starts, and a run that fails
still delivers every completed step. A file that cannot be written (a full disk) stops the run
with a :class:`~vtsi.errors.RecorderError` naming the recorder, the file and what it
holds.

A recorder is three separate things (see ``docs/recorders.md``):

* **what** is recorded: a *response* (node disp/vel/accel, reactions, element forces), i.e. the
  dofs it requests and how it turns them into its columns (:meth:`Recorder.compute`);
* **where** it goes: a *sink* (:mod:`vtsi.recorders.sinks`: memory, HDF5, OpenSees text);
* **envelopes**: running min / max / absmax of every column with the time of each
  (:class:`~vtsi.recorders.envelope.Envelope`), kept next to the history or instead of it.

Contract of a recorder (what an analysis relies on)
---------------------------------------------------
1. ``requests(assembly)`` -> list of ``(quantity, full_dof)`` with quantity ``'u'``, ``'v'`` or
   ``'a'`` (displacement, velocity, acceleration), called when an analysis starts. Fixed dofs
   may be requested; they read 0.
2. ``start(assembly, model, info=None)``: called once per analysis run (an analysis run several
   times, as OpenSees's ``analyze`` in a loop, calls it every time: the record continues, it is
   not restarted). ``info`` (optional dict) describes the analysis: ``'analysis'``
   (``'static'``/``'transient'``/``'coupled'``), ``'integrator'`` (name), ``'dt'`` [s] (static:
   the load step dλ), ``'loads'``, and from a transient analysis ``'bridge'`` (None: the FE
   bridge; ``'modal, every mode'`` or ``'modal, truncated'``: a modal bridge of all the model's
   modes or fewer); sinks store it as metadata, the HDF5 sink per run. A coupled
   analysis adds ``'coupled_loads'`` (:class:`~vtsi.coupled.CoupledLoads`, not metadata): the
   loads it applies besides the patterns (the train's forces, the contact forces, the bridge's
   own weight), which a recorder whose values contain the applied loads (reactions, bending
   moments) takes from there.
3. ``write(times, columns, assembly)``: ``times (n,)`` [s] increasing, ``columns (n,
   len(requests))`` in the order requested; called after every chunk of steps. A recorder of
   another package gets ``columns`` of its own, to keep or change; vtsi's own recorders (of
   the ``vtsi`` package) are handed a read-only view of the analysis's table of the chunk,
   shared with the other recorders, and keep a copy of what they keep past the call
   (:meth:`Recorder.write` hands its sink values it owns).
4. ``close()``: flush and release; called when the run ends, also when it fails (files stay
   readable at every flush in between).
5. ``dt`` (optional, OpenSees ``-dT``): record a step iff ``t - t_next >= -1e-5 dt``, then
   ``t_next = t + dt`` (``t_next`` starts at 0 and is never reset, as in OpenSees).

Contract of a response subclass (what :class:`Recorder` needs to do the rest)
-----------------------------------------------------------------------------
a. ``requests(assembly)`` as above.
b. ``prepare(assembly, model)``: resolve names to indices (once per run); return the column
   description, a dict with

   - ``'units'``: list of str, one per column (their number is ``n_columns``);
   - ``'columns'``: dict of name -> array ``(n_columns,)`` labelling the columns (e.g. ``node``,
     ``dof``, ``dof_name``; may be empty);
   - ``'quantity'``: str, what the values are (``'displacement'``);
   - ``'response'`` (optional): str, the response's short name (``'disp'``); default the
     recorder's ``response`` attribute if it has one, else ``'quantity'``.

   :meth:`Recorder.start` checks it (ModelError naming the recorder and the key) before any
   sink sees it, and completes ``n_columns``, ``response``, ``attrs`` and ``run`` (the run's
   ``info``, its None entries left out).
c. ``compute(times, columns, assembly)`` -> ``(n, n_columns)`` float64 values of the kept steps
   (checked once per chunk: another shape is a ModelError naming the recorder); vtsi's own
   ``compute`` reads ``columns`` and never writes them (item 3); returning them as they are
   costs no copy.
"""
import numpy as np

from vtsi.errors import ModelError, as_flag
from vtsi.version import __version__

from .envelope import Envelope
from .sinks import MemorySink, Sink

DT_TOLERANCE = 1e-5   # OpenSees relDeltaTTol
NOT_METADATA = ("coupled_loads",)   # entries of an analysis's ``info`` that are objects for the recorders


class Recorder:
    """Base class: a response (subclass) + a sink + an optional envelope.

    Parameters
    ----------
    sink : :class:`~vtsi.recorders.sinks.Sink` or None (memory, :class:`MemorySink`).
    dt : record only every ``dt`` seconds (OpenSees ``-dT``); None or 0: every step.
    envelope : keep the running min / max / absmax of every column (``self.envelope``);
        ``"concurrent"``: also every column's value at the step of each extreme (M and V
        together: :class:`~vtsi.recorders.envelope.Envelope`).
    history : keep the time history (False with ``envelope=True``: OpenSees ``EnvelopeNode`` /
        ``EnvelopeElement``: only the envelope goes to the sink).
    tag : optional identifier (the command layer's recorder tag).
    """

    tag = None
    dt = None
    name = "Recorder"
    unit_label = None   # maps each column's SI unit label to the model's (the command layer's `units`)
    load_lag = 0.0      # [s] set by the analysis: how long before the record times the steps applied their
                        # loads (HHT, generalized-α: (1 − α)Δt); element loads are taken then

    def __init__(self, sink=None, dt=None, envelope=False, history=True, tag=None):
        if sink is None:
            sink = MemorySink()
        if not isinstance(sink, Sink):
            raise ModelError(f"{self.name}: sink must be a Sink (MemorySink, HDF5Sink, TextSink), got {sink!r}")
        if dt is not None:
            try:
                dt = float(dt)
            except (TypeError, ValueError):
                raise ModelError(f"{self.name}: dt must be a number, got {dt!r}") from None
            if not (np.isfinite(dt) and dt >= 0.0):
                raise ModelError(f"{self.name}: dt must be >= 0 and finite, got {dt}")
        concurrent = isinstance(envelope, str) and envelope == "concurrent"
        if not (concurrent or isinstance(envelope, (bool, np.bool_))):
            raise ModelError(f"{self.name}: envelope must be True, False or 'concurrent', got {envelope!r}")
        history, envelope = as_flag(history, self.name, "history"), bool(envelope)
        if not (history or envelope):
            raise ModelError(f"{self.name}: records nothing (history=False and envelope=False)")
        self.sink, self.dt, self.tag = sink, dt, tag
        self.history = history
        self.envelope = Envelope(concurrent=concurrent) if envelope else None
        sink.check(self)
        self._next_time = 0.0
        self._layout = None
        self.last_time = None       # [s] the last recorded step's time

    def __repr__(self):
        what = [f"{k}={getattr(self, k)!r}" for k in ("nodes", "elements", "dofs", "response") if hasattr(self, k)]
        return f"{type(self).__name__}({', '.join(what + [f'sink={type(self.sink).__name__}'])})"

    # -- analysis-facing contract ----------------------------------------------------------
    def requests(self, assembly):
        raise NotImplementedError

    def start(self, assembly, model, info=None):
        layout = self._checked_layout(self.prepare(assembly, model))
        n_columns = len(layout["units"])
        if self._layout is not None and self._layout["n_columns"] != n_columns:
            raise ModelError(f"{self.name}: the model now gives {n_columns} columns, the record "
                             f"started with {self._layout['n_columns']}")
        layout["n_columns"] = n_columns
        if self.unit_label is not None:
            layout["units"] = [self.unit_label(u) for u in layout["units"]]
        layout["run"] = {key: value for key, value in (info or {}).items()
                         if value is not None and key not in NOT_METADATA}
        layout.setdefault("attrs", {}).update(_model_metadata(assembly, layout["run"]))
        layout["attrs"].update(recorder=type(self).__name__, record_dt=float(self.dt or 0.0))
        self._layout = layout
        if self.envelope is not None:
            self.envelope.resize(n_columns)
        self.sink.open(layout, self)

    def write(self, times, columns, assembly):
        table = columns
        if self.dt:
            keep = self._select(times)
            if not keep.any():
                return
            times, columns = times[keep], columns[keep]
        times = np.ascontiguousarray(times, dtype=np.float64)
        values = np.ascontiguousarray(self.compute(times, columns, assembly), dtype=np.float64)
        if values.shape != (len(times), self._layout["n_columns"]):
            raise ModelError(f"{self!r}: compute() returned values of shape {values.shape} for {len(times)} steps; "
                             f"prepare() declared {self._layout['n_columns']} columns (one unit each), so "
                             f"({len(times)}, {self._layout['n_columns']}) was expected")
        if self.envelope is not None:
            self.envelope.update(times, values)
        if self.history and np.may_share_memory(values, table):
            values = values.copy()      # the sink may keep it; the chunk's table is the analysis's
        self.sink.write(times, values if self.history else None, self.envelope)
        self.last_time = float(times[-1]) if len(times) else self.last_time

    def close(self):
        self.sink.close(self.envelope)

    def _checked_layout(self, layout):
        """``prepare()``'s column description checked against contract item (b), ``response``
        defaulted; a ModelError naming the recorder and the key otherwise."""
        who = f"{self!r}: prepare()"
        if not isinstance(layout, dict):
            raise ModelError(f"{who} returned {type(layout).__name__}; it must return a dict with 'units', "
                             "'columns', 'quantity' (and optionally 'response')")
        missing = [key for key in ("units", "columns", "quantity") if key not in layout]
        if missing:
            raise ModelError(f"{who} returned no {', '.join(repr(k) for k in missing)}; the column description "
                             "needs 'units' (one str per column), 'columns' (name -> array per column) and "
                             "'quantity' (str), 'response' (str) optional")
        units, columns = layout["units"], layout["columns"]
        if isinstance(units, str) or not all(isinstance(u, str) for u in units):
            raise ModelError(f"{who}: 'units' must be a list of str, one per column, got {units!r}")
        if not isinstance(columns, dict):
            raise ModelError(f"{who}: 'columns' must be a dict of name -> array (n_columns,), got {columns!r}")
        for name, labels in columns.items():
            if np.shape(labels) != (len(units),):
                raise ModelError(f"{who}: 'columns'[{name!r}] has shape {np.shape(labels)}; 'units' gives "
                                 f"{len(units)} columns")
        layout.setdefault("response", str(getattr(self, "response", layout["quantity"])))
        return layout

    # -- response-facing contract (override) -----------------------------------------------
    def prepare(self, assembly, model):
        raise NotImplementedError

    def compute(self, times, columns, assembly):
        raise NotImplementedError

    # -- results of the memory sink --------------------------------------------------------
    @property
    def time(self):
        """Recorded times ``(n,)`` [s] (memory and HDF5 sinks)."""
        return self.sink.time

    @property
    def values(self):
        """Recorded values ``(n, n_columns)`` (memory and HDF5 sinks)."""
        return self.sink.values

    # -- helpers ---------------------------------------------------------------------------
    def _select(self, times):
        """Mask of the steps to keep under OpenSees's ``-dT`` rule (see the module docstring; ``dt`` set)."""
        keep = np.zeros(len(times), dtype=bool)
        tol = DT_TOLERANCE * self.dt
        i, n = 0, len(times)
        while True:
            i += int(np.searchsorted(times[i:], self._next_time - tol, side="left"))
            if i >= n:
                return keep
            keep[i] = True
            self._next_time = times[i] + self.dt
            i += 1


def _model_metadata(assembly, run):
    """The model's metadata and the run's description ``run`` (a dict), as one dict."""
    meta = {"vtsi_version": __version__, "n_nodes": int(len(assembly.node_tags)),
            "n_elements": sum(len(block[1]) for block in assembly.blocks), "ndf": int(assembly.ndf)}
    meta.update(run)
    return meta

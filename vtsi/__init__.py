"""vtsi: dynamic analysis of trains crossing railway bridges (vehicle-track-structure interaction).

``import vtsi`` loads the first two layers below (the names listed in ``__all__``); the others
are modules of their own, imported where they are used. The layers, lowest first:

Model and elements
    :class:`Model` (2-D, ndf 3: ux, uy, rz; nodes, fixities, masses, elements, time series
    :class:`Constant`, :class:`Linear`, :class:`Path`, load patterns); element types by name
    ('elasticBeamColumn', 'ElasticTimoshenkoBeam', 'truss', 'zeroLength', 'pointMass'), their
    contract and registry in :mod:`vtsi.elements`; bridges ready-made in :mod:`vtsi.models.bridges`.
Analyses and integrators
    :class:`StaticAnalysis`, :class:`TransientAnalysis`, :func:`eigen`, :func:`domain_state`;
    integrators by name or class (:mod:`vtsi.integrators`: Newmark, HHT, GeneralizedAlpha, Bathe,
    TRBDF2, CentralDifference); recorders (:mod:`vtsi.recorders`: node, element, reaction, modal,
    contact and train responses, to memory, HDF5 or OpenSees text, with envelopes).
Trains and coupling
    cars and trains (:class:`vtsi.models.Car`, :class:`vtsi.models.Train`, the catalogue:
    ``vtsi.models.catalogue_train('HSLM-A1', speed [m/s])``), rail irregularity
    (:class:`vtsi.models.Irregularity`); :class:`vtsi.track.Track` (the beam elements the wheels run
    on), :class:`vtsi.train.TrainSubdomain` (a train placed on the line),
    :class:`vtsi.constraint.MovingLoadConstraint` (ties them: the contact forces are its
    multipliers) and :class:`vtsi.coupled.CoupledAnalysis` (steps bridge and train, with contact
    loss: contact='lcp'; :mod:`vtsi.contact` reads lift-offs and landings).
Modal bridge
    :class:`vtsi.modal_bridge.ModalBridge` (the FE bridge's modes, a damping ratio each), stepped by
    a CoupledAnalysis (``bridge=``) or solved exactly for moving forces (:mod:`vtsi.modal_passage`).
Sweeps, check and report
    :class:`vtsi.sweep.Sweep` (every train at every speed over a bridge: :func:`vtsi.sweep.beam_bridge`,
    :class:`vtsi.passage.PassageSettings`, :class:`vtsi.passage.Output`) runs into a results file
    (:class:`vtsi.sweep_results.SweepResults`); :func:`vtsi.check.check` evaluates the EN 1990 A2 /
    EN 1991-2 criteria on it (rules in :mod:`vtsi.codes`); :func:`vtsi.report.write_report` lays
    them out; :func:`vtsi.workflow.design_check` runs the three (and the 3-D scene,
    :mod:`vtsi.scene3d`); the command line ``vtsi run | sweep | check | trains`` does the same.
OpenSees command layer
    :mod:`vtsi.opensees` (``import vtsi.opensees as ops`` runs OpenSeesPy scripts) and
    :mod:`vtsi.tcl` (OpenSees Tcl scripts), a thin layer over the object API above.

Errors (:mod:`vtsi.errors`, all :class:`VtsiError`; docs/bad_inputs.md): :class:`ModelError` a
definition, :class:`AnalysisError` (:class:`DivergenceError`) an analysis, :class:`CommandError`
a command, :class:`RecorderError` a recorder's file, :class:`SweepError` (:class:`SettingError`,
:class:`PassageError`) a sweep, :class:`BridgeError` the bridge (:class:`BridgeModelError`,
:class:`BridgeSweepError`).

Glossary (used throughout): K, C, M stiffness, damping, mass matrices; u, v, a displacement,
velocity, acceleration; P load; λ contact force (compression positive); SI units.
"""
from vtsi.analysis import StaticAnalysis, TransientAnalysis, domain_state, eigen
from vtsi.errors import (AnalysisError, BridgeError, BridgeModelError, BridgeSweepError, CommandError, DivergenceError,
                         ModelError, PassageError, RecorderError, SettingError, SweepError, VtsiError)
from vtsi.model import Model
from vtsi.timeseries import Constant, Linear, Path
from vtsi.version import __version__
from vtsi import recorders  # vtsi.recorders.NodeRecorder etc.

__all__ = ["__version__", "recorders", "Model", "StaticAnalysis", "TransientAnalysis", "eigen", "domain_state",
           "Constant", "Linear", "Path",
           "VtsiError", "ModelError", "AnalysisError", "DivergenceError", "CommandError", "RecorderError",
           "SweepError", "SettingError", "PassageError", "BridgeError", "BridgeModelError", "BridgeSweepError"]

"""The recorder contract.

A recorder names, once, the dof responses it needs; the analysis records them in compiled
code and hands each chunk of steps over. Recorders never slow the time loop down and never
lose what was computed: a chunk is written before the next one starts, and a run that fails
still delivers every completed step.

Contract of a recorder
----------------------
1. ``requests(assembly)`` -> list of ``(quantity, full_dof)`` with quantity ``'u'``, ``'v'`` or
   ``'a'`` (displacement, velocity, acceleration), called when an analysis starts.
2. ``start(assembly, model)``: open the sink (file, memory); called once per analysis run.
3. ``write(times, columns, assembly)``: ``times (n,)`` [s], ``columns (n, len(requests))`` in the
   order requested; called after every chunk of steps.
4. ``close()``: flush and release (files stay readable at every flush in between).
5. ``dt`` (optional, OpenSees ``-dT``): record only when at least ``dt`` has elapsed.
"""
import numpy as np


class Recorder:
    """Base class; see the module docstring."""

    tag = None
    dt = None

    def requests(self, assembly):
        raise NotImplementedError

    def start(self, assembly, model):
        self._last_time = -np.inf

    def write(self, times, columns, assembly):
        raise NotImplementedError

    def close(self):
        pass

    def _select(self, times):
        """Mask of the steps to keep under the ``-dT`` rule (OpenSees: record when
        ``t - t_last >= dT``)."""
        if not self.dt:
            return np.ones(len(times), dtype=bool)
        keep = np.zeros(len(times), dtype=bool)
        last = self._last_time
        tol = 1e-10 * self.dt
        for i, t in enumerate(times):
            if t - last >= self.dt - tol:
                keep[i] = True
                last = t
        self._last_time = last
        return keep

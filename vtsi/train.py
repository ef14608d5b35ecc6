"""TrainSubdomain: the train as a subdomain of its own, coupled to the bridge only through
MovingLoadConstraint. It owns the train dofs, their matrices and state."""
import numpy as np

from vtsi.errors import ModelError
from vtsi.vehicle import Train


class TrainSubdomain:
    """A :class:`~vtsi.models.Train` placed on the line: its head at ``x_head0`` [m] at t = 0.

    Attributes
    ----------
    train : Train
    M, C, K : CSR (n_dof, n_dof) block-diagonal train matrices [kg, N·s/m, N/m].
    gravity_load : (n_dof,) gravity load P_t [N] (negative, downwards).
    contact_wheels : (n_c,) int64 indices (into the train's wheels) of the wheels with a dof:
        each is tied to the rail by one constraint row; ``wheel_dofs`` are their train dofs.
    force_wheels : (n_f,) int64 indices of the wheels of force-only cars: they load the rail
        with ``wheel_forces`` [N, downward positive] and have no dof.
    u, v, a : (n_dof,) committed train state (total: dead load + dynamic).
    """

    def __init__(self, train, x_head0=0.0):
        if not isinstance(train, Train):
            raise ModelError(f"TrainSubdomain: expected a vtsi.models.Train, got {type(train).__name__}")
        x_head0 = float(x_head0)
        if not np.isfinite(x_head0):
            raise ModelError(f"TrainSubdomain: x_head0 must be finite, got {x_head0}")
        self.train, self.x_head0 = train, x_head0
        self.M, self.C, self.K = train.M.tocsr(), train.C.tocsr(), train.K.tocsr()
        self.gravity_load = np.asarray(train.gravity_load, dtype=float)
        self.contact_wheels = train.contact_wheels
        self.force_wheels = np.flatnonzero(train.force_wheels).astype(np.int64)
        self.wheel_dofs = np.asarray(train.wheel_dofs, dtype=np.int64)
        self.wheel_forces = np.asarray(train.static_wheel_loads, dtype=float)[self.force_wheels]
        self.u = np.zeros(train.n_dof)
        self.v = np.zeros(train.n_dof)
        self.a = np.zeros(train.n_dof)

    def __repr__(self):
        return (f"TrainSubdomain({self.train!r}, x_head0 = {self.x_head0:g} m, {len(self.contact_wheels)} contact "
                f"wheels, {len(self.force_wheels)} force wheels)")

    @property
    def n_dof(self):
        return self.train.n_dof

    @property
    def speed(self):
        return self.train.speed

    def wheel_x0(self, wheels):
        """Positions at t = 0 of the given wheels [m]."""
        return self.x_head0 - self.train.wheel_offsets[wheels]

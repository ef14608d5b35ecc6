"""Recorders of a coupled analysis: train dof responses and wheel-rail contact quantities.

They follow the recorder contract (:mod:`vtsi.recorders.base`) with the coupled analysis's
channels: ``'train_u'``, ``'train_v'``, ``'train_a'`` (train dof index) and
``'contact_force'``, ``'gap'`` (contact wheel index), and write to any sink.
"""
import numpy as np

from vtsi.contact import gap_tolerance
from vtsi.errors import ModelError
from vtsi.recorders.base import Recorder

TRAIN_RESPONSES = {"disp": ("train_u", "m", "rad"), "vel": ("train_v", "m/s", "rad/s"),
                   "accel": ("train_a", "m/s^2", "rad/s^2")}
CONTACT_RESPONSES = {"force": ("contact_force", "N"), "gap": ("gap", "m"), "in_contact": ("gap", "1")}


class TrainRecorder(Recorder):
    """Records ``response`` ('disp', 'vel', 'accel') of train dofs.

    Parameters
    ----------
    train : TrainSubdomain (resolves dof names).
    dofs : dof names (``'car0.body_y'``, see ``Train.dof_names``) or indices; None = all.
    """

    name = "train recorder"

    def __init__(self, train, dofs=None, response="disp", **kwargs):
        if response not in TRAIN_RESPONSES:
            raise ModelError(f"train recorder: unknown response {response!r}; valid: {', '.join(TRAIN_RESPONSES)}")
        names = list(train.train.dof_names)
        if dofs is None:
            dofs = range(len(names))
        index = []
        for d in dofs:
            if isinstance(d, str):
                if d not in names:
                    raise ModelError(f"train recorder: unknown train dof {d!r}; valid: {', '.join(names)}")
                index.append(names.index(d))
            elif 0 <= int(d) < len(names):
                index.append(int(d))
            else:
                raise ModelError(f"train recorder: train dof {d} out of range 0..{len(names) - 1}")
        self.train, self.dofs, self.response = train, index, response
        self.dof_names = [names[i] for i in index]
        super().__init__(**kwargs)

    def requests(self, assembly):
        return [(TRAIN_RESPONSES[self.response][0], i) for i in self.dofs]

    def prepare(self, assembly, model):
        _, translation, rotation = TRAIN_RESPONSES[self.response]
        units = [rotation if name.endswith("_rz") else translation for name in self.dof_names]
        return {"response": self.response, "quantity": f"train {self.response}", "units": units,
                "columns": {"train_dof": np.array(self.dofs, dtype=np.int64), "dof_name": np.array(self.dof_names)}}

    def compute(self, times, columns, assembly):
        return columns


class ContactRecorder(Recorder):
    """Records ``response`` of the contact wheels: ``'force'`` (λ [N], compression positive),
    ``'gap'`` (position gap [m], > 0 in flight) or ``'in_contact'`` (1 on the rail, 0 in flight:
    gap <= ``gap_tol`` [m], 0 to :data:`~vtsi.contact.MAX_GAP_TOL`, as the analysis's flight
    criterion). ``wheels``: contact-wheel indices (None = all ``n_contact``)."""

    name = "contact recorder"

    def __init__(self, constraint, wheels=None, response="force", gap_tol=1e-9, **kwargs):
        if response not in CONTACT_RESPONSES:
            raise ModelError(f"contact recorder: unknown response {response!r}; valid: {', '.join(CONTACT_RESPONSES)}")
        n_c = constraint.n_contact
        wheels = list(range(n_c)) if wheels is None else [int(w) for w in wheels]
        bad = [w for w in wheels if not 0 <= w < n_c]
        if bad:
            raise ModelError(f"contact recorder: wheel {bad[0]} out of range 0..{n_c - 1}")
        self.gap_tol = gap_tolerance(gap_tol, self.name, ModelError)
        self.constraint, self.wheels, self.response = constraint, wheels, response
        super().__init__(**kwargs)

    def requests(self, assembly):
        return [(CONTACT_RESPONSES[self.response][0], w) for w in self.wheels]

    def prepare(self, assembly, model):
        unit = CONTACT_RESPONSES[self.response][1]
        train_wheels = self.constraint.train.contact_wheels[self.wheels]
        return {"response": self.response, "quantity": f"contact {self.response}", "units": [unit] * len(self.wheels),
                "columns": {"contact_wheel": np.array(self.wheels, dtype=np.int64),
                            "train_wheel": np.asarray(train_wheels, dtype=np.int64)}}

    def compute(self, times, columns, assembly):
        if self.response == "in_contact":
            return (columns <= self.gap_tol).astype(np.float64)
        return columns

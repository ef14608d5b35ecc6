"""Reference solutions (``vtsi.reference``): closed-form solutions and independent solvers that
tests and benchmarks compare the finite-element analyses with.

- :mod:`.fryba`: a constant force crossing a simply supported Euler-Bernoulli beam at constant
  speed (Frýba 1972, ch. 1), modal series with free vibration after the force leaves; DAF.
- :mod:`.elimination` (R1): the coupled train-bridge problem with the wheel dofs eliminated,
  integrated by DOP853 with restarts at every element crossing.
- :mod:`.ida` (R2): the same problem as an index-1 DAE integrated by SUNDIALS IDA
  (scikit-sundae).
- :mod:`.events`: one wheel that may lose contact, with lift-off and landing located as events.
"""
from .elimination import ReferenceSolution, RigidGround, average_contact_force
from .elimination import solve as solve_elimination
from .events import solve_single_wheel
from .fryba import daf, first_frequency, moving_force_midspan, speed_of_alpha, static_midspan
from .ida import solve as solve_ida

__all__ = ["moving_force_midspan", "daf", "first_frequency", "speed_of_alpha", "static_midspan",
           "solve_elimination", "solve_ida", "solve_single_wheel", "ReferenceSolution", "RigidGround",
           "average_contact_force"]

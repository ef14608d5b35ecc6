"""Reference solutions (``vtsi.reference``): closed-form and modal solutions that tests and
benchmarks compare the finite-element analyses with.

- :mod:`.fryba`: a constant force crossing a simply supported Euler-Bernoulli beam at constant
  speed (Frýba 1972, ch. 1), modal series with free vibration after the force leaves; DAF.
"""
from .fryba import daf, first_frequency, moving_force_midspan, speed_of_alpha, static_midspan

__all__ = ["moving_force_midspan", "daf", "first_frequency", "speed_of_alpha", "static_midspan"]

"""Units where trains meet a model.

vtsi's train, car, gravity and irregularity data are SI (N, kg, m, s): the catalogue cars and
trains, HSLM and ICE3 axle loads, g = 9.81 m/s², the rail-irregularity spectra. An OpenSees
script may use any consistent units; the command layer's ``units(force, length)`` declares
them (time is always s, mass is force·s²/length: kN and m give t, N and mm give t, kN and mm give
1000 t), and everything SI that meets the model is converted on the way in:

- a matrix entry of a car between dofs i and j scales by f_M s_i s_j, f_M = f_F / f_L the mass
  factor and s = f_L on a rotation (rz) dof, 1 on a translation (so kg, kg·m, kg·m², N/m,
  N·m/rad, N·s/m all come out right); its gravity load by f_F (× f_L on a rotation);
- lengths (wheel and car offsets, a train's D and its signature peak's wavelengths,
  irregularity profiles) by f_L, speeds by f_L, g by f_L, the signature's G by f_F;

with f_F, f_L the model's units per N and per m. Numbers a script gives itself (a
``movingForce`` P, a ``sprungMass`` m and k, a speed as a number, ``xHead0``) are already in its
units. A speed may carry its unit instead, as text: ``'300km/h'`` or ``'83.3m/s'``.

A model's mass per metre of track is checked against what a railway deck weighs
(:data:`MIN_MASS_PER_METRE`, in kg/m once converted): a kN-t-m model with undeclared units is
1000 times too light for SI trains, which would otherwise give train loads 1000 times too large
in silence.
"""
import math
import re
from dataclasses import dataclass, replace

import numpy as np

from vtsi.deck import deck_layout
from vtsi.errors import ModelError
from vtsi.vehicle import GRAVITY, MAX_TRAIN_SPEED, Car, Train
from vtsi.track import Track

FORCE_UNITS = {"N": 1.0, "kN": 1e-3, "MN": 1e-6}
"""Model force units per newton."""
LENGTH_UNITS = {"m": 1.0, "cm": 1e2, "mm": 1e3}
"""Model length units per metre."""
MIN_MASS_PER_METRE = 500.0
"""[kg/m] The lightest mass per metre of track accepted where trains meet a model: railway decks
weigh more than 1000 kg/m; a model written in t/m but read as kg/m shows 1000 times less."""
MAX_MASS_PER_METRE = 1e6
"""[kg/m] The heaviest (1000 t/m): a kN, t, m model declared N, mm reads 10⁶ times heavier."""
COMMON_UNITS = (("kN", "m"), ("N", "mm"), ("N", "m"), ("kN", "mm"), ("MN", "m"), ("kN", "cm"), ("N", "cm"),
                ("MN", "mm"), ("MN", "cm"))
"""(force, length) systems, the commonest first: a deck's mass in the wrong ones names the first
that makes it plausible."""
MIN_FIRST_FREQUENCY_HZ = 0.1
"""[Hz] The lowest first vertical frequency of a bridge a sweep accepts: railway bridges are
stiffer; E in GPa or MPa with the rest in SI shows a 3·10⁴ to 10³ times lower frequency."""
_SPEED = re.compile(r"^\s*([-+0-9.eE]+)\s*(km/h|kmh|m/s)\s*$")


def deck_mass_per_length(model, track_elements):
    """The model's whole vertical (uy) mass divided by the length of its decks along
    ``track_elements`` [model mass / model length] (:func:`vtsi.deck.deck_layout`: the track's
    approaches on the ground, a light rail on springs, do not count; the whole track where the
    layout cannot be read yet, e.g. before the supports are given)."""
    asm = model.build()
    uy = np.zeros(asm.n_full)
    uy[1::asm.ndf] = 1.0
    track = Track(model, list(track_elements))
    length = track.x_end - track.x_begin
    if not length > 0.0:
        raise ModelError(f"elements {list(track_elements)} have no length along x ({track.x_begin:g} to "
                         f"{track.x_end:g}); a track is a chain of beam elements")
    try:
        decks = sum(b - a for a, b in deck_layout(model, track).deck_ends)
    except ModelError:
        decks = 0.0
    return float(uy @ (asm.M_full @ uy)) / (decks if decks > 0.0 else length)


@dataclass(frozen=True)
class Units:
    """A consistent unit system: ``force`` ('N', 'kN', 'MN') and ``length`` ('m', 'cm', 'mm'),
    time in s, mass = force·s²/length."""

    force: str = "N"
    length: str = "m"

    def __post_init__(self):
        if self.force not in FORCE_UNITS:
            raise ModelError(f"units: unknown force unit {self.force!r}; valid: {', '.join(FORCE_UNITS)}")
        if self.length not in LENGTH_UNITS:
            raise ModelError(f"units: unknown length unit {self.length!r}; valid: {', '.join(LENGTH_UNITS)}")

    @property
    def f_force(self):
        return FORCE_UNITS[self.force]

    @property
    def f_length(self):
        return LENGTH_UNITS[self.length]

    @property
    def f_mass(self):
        """Model mass units per kg."""
        return self.f_force / self.f_length

    @property
    def gravity(self):
        """g in the model's units (length/s²)."""
        return GRAVITY * self.f_length

    @property
    def mass_unit(self):
        kg = 1.0 / self.f_mass
        return {1.0: "kg", 1e3: "t", 1e6: "kt"}.get(kg, f"{kg:g} kg")

    def __str__(self):
        return f"{self.force}, {self.length}, {self.mass_unit} (= {self.force}·s²/{self.length}), s"

    def label(self, si):
        """The SI unit label ``si`` ('m', 'N m', 'm/s^2', 'kg', 'rad') in these units ('mm',
        'kN mm', 'mm/s^2', 't', 'rad'): what a recorder's column holds in a model of these units."""
        names = {"N": self.force, "m": self.length, "kg": self.mass_unit}
        return re.sub(r"\b(N|m|kg)\b", lambda match: names[match.group(1)], si)

    def speed(self, value, what="speed"):
        """A speed in the model's units (length/s): a number as it is, or a text with its unit
        ('300km/h', '83.3m/s')."""
        if isinstance(value, str):
            match = _SPEED.match(value)
            if not match:
                raise ModelError(f"{what}: {value!r} is not a speed; give a number in {self.length}/s or a text "
                                 "such as '300km/h' or '83.3m/s'")
            number = float(match.group(1))
            number *= (1.0 / 3.6 if match.group(2) in ("km/h", "kmh") else 1.0) * self.f_length
        else:
            if isinstance(value, (bool, np.bool_)):
                raise ModelError(f"{what}: {value!r} is not a speed")
            try:
                number = float(value)
            except (TypeError, ValueError):
                raise ModelError(f"{what}: {value!r} is not a speed") from None
        if not math.isfinite(number):
            raise ModelError(f"{what}: must be finite, got {number}")
        si = abs(number) / self.f_length
        if si > MAX_TRAIN_SPEED:
            hint = ("" if isinstance(value, str) else f"; a speed in km/h is written '{number:g}km/h'"
                    if self.f_length == 1.0 else f"; a bare number is in {self.length}/s: write km/h as text, e.g. "
                    "'300km/h'")
            raise ModelError(f"{what}: {number:g} {self.length}/s ({3.6 * si:.4g} km/h) is faster than any train "
                             f"(at most {MAX_TRAIN_SPEED:g} m/s){hint}")
        return number

    def car(self, car):
        """An SI :class:`~vtsi.vehicle.Car` in these units (see the module docstring)."""
        if self.f_force == 1.0 and self.f_length == 1.0:
            return car
        s = np.array([self.f_length if name.endswith("_rz") else 1.0 for name in car.dof_names])
        scale = self.f_mass * np.outer(s, s)
        loads = None if car.n_dof else car.static_wheel_loads * self.f_force
        return Car(car.name, car.kind, car.M * scale, car.C * scale, car.K * scale,
                   car.gravity_load * self.f_force * s, car.wheel_dofs, car.wheel_offsets * self.f_length,
                   car.dof_names, loads)

    def train(self, train, speed):
        """An SI :class:`~vtsi.vehicle.Train` in these units, at ``speed`` (model units); its D and
        :attr:`~vtsi.vehicle.Train.signature_peak` (the one D came from) in them too."""
        if self.f_force == 1.0 and self.f_length == 1.0:
            return train.with_speed(speed)

        def length(value):                # [model length] of ``value`` [m], None as it is
            return None if value is None else value * self.f_length
        built = Train([self.car(c) for c in train.cars], np.asarray(train.car_offsets) * self.f_length, speed,
                      name=train.name, characteristic_length=length(train.characteristic_length),
                      max_speed=MAX_TRAIN_SPEED * self.f_length)
        peak = train.signature_peak
        if peak is not None:
            built.signature_peak = replace(
                peak, wavelength_m=length(peak.wavelength_m), signature=peak.signature * self.f_force,
                length_m=length(peak.length_m), below_m=length(peak.below_m),
                wavelength_range_m=tuple(length(x) for x in peak.wavelength_range_m), length_unit=self.length)
        return built

    def check_deck_mass(self, mass_per_length, what):
        """Refuse a deck lighter than :data:`MIN_MASS_PER_METRE` or heavier than
        :data:`MAX_MASS_PER_METRE` once its mass per length (model units) is read in these units,
        naming the units that would make it a railway deck's."""
        per_metre = mass_per_length * self.f_length / self.f_mass
        if MIN_MASS_PER_METRE <= per_metre <= MAX_MASS_PER_METRE:
            return
        bound = (f"below {MIN_MASS_PER_METRE:g} kg/m (no railway deck is that light)" if per_metre < MIN_MASS_PER_METRE
                 else f"above {MAX_MASS_PER_METRE:g} kg/m (no railway deck is that heavy)")
        def weight(u):                 # [kg/m] the deck's mass per metre read in the units u
            return mass_per_length * u.f_length / u.f_mass

        fits = [u for u in (Units(f, L) for f, L in COMMON_UNITS)
                if MIN_MASS_PER_METRE <= weight(u) <= MAX_MASS_PER_METRE]
        remedy = (f"; in {fits[0]} it would weigh {weight(fits[0]):.4g} kg/m: declare them first (Tcl: units "
                  f"{fits[0].force} {fits[0].length}; Python: units('{fits[0].force}', '{fits[0].length}'))"
                  if fits else "")
        raise ModelError(f"{what}: the deck weighs {per_metre:.4g} kg/m along the track read in {self}, {bound}; "
                         f"the trains' data are SI{remedy}")

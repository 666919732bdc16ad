"""A vehicle of the rotor-speed plant (:mod:`quadcruise.model.rotor_plant`): frozen,
validated, with units; its field names are RotorPy's and the issue's (``kf``, ``km``,
``tau_up``, ``w_max``, ``c_Dx``, ``k_d``, ...).

Beyond each field's own check, a vehicle must be able to fly: its rotors at full speed lift it
(n kf w_max^2 > m g), and they surround its centre of mass (seen from above, no half-plane
through the centre holds them all: otherwise some tilt cannot be commanded). Ready-made ones
with their sources: :meth:`RotorVehicle.preset` (``RotorVehicle.preset("crazyflie")``), or
:meth:`quadcruise.Vehicle.preset` for any preset.

Examples
--------
>>> v = RotorVehicle.preset("crazyflie")
>>> v.n_rotors, round(float(v.hover_speed), 1)
(4, 1788.6)
>>> v.replace(w_max=1000.0)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: vehicle cannot lift itself: 4 rotors x kf w_max^2 = 0.092 N, its weight m g = 0.2943 N
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from quadcruise.errors import InputError
from quadcruise.fields import Check, Validated
from quadcruise.fields import unit_field as _f
from quadcruise.model.rotor_plant import ROTOR_ARM, ROTOR_PARAMS
from quadcruise.model.vehicle_files import load_vehicle

MAX_THRUST_TO_WEIGHT = 100.0
"""The largest full thrust over weight, ``n kf w_max^2 / (m g)``, a vehicle file may give: racing
quadrotors reach about 15, the presets 1.9 to 10.2; beyond it a coefficient is out of physical range
(``kf = 1e300`` had left a yaw column 1e-308 of the thrust's: an allocation "of rank 3")."""
AERO_FIELDS = ("c_Dx", "c_Dy", "c_Dz", "k_d", "k_z", "k_h", "k_flap")
"""The aerodynamic coefficients (RotorPy's names); all zero is RotorPy's ``aero=False``."""


class _Rotors(Check):
    """Rotor rows ``(x, y, z, s)``: finite positions [m], direction s = +1 or -1; stored as a
    tuple of 4-tuples of floats."""

    def __init__(self) -> None:
        super().__init__("rotors", "a list of at least 3 rows [x, y, z, direction], direction +1 or -1")

    def convert(self, site, value: Any) -> tuple:
        try:
            rows = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            site.fail(self.want, repr(value)[:80])
        if rows.ndim != 2 or rows.shape[0] < 3 or rows.shape[1] != 4:
            site.fail(self.want, f"shape {rows.shape}")
        for k, row in enumerate(rows):
            if not np.all(np.isfinite(row)):
                site.fail(self.want, f"a non-finite entry in rotor {k + 1}: {row.tolist()}")
            if row[3] not in (1.0, -1.0):
                site.fail(self.want, f"direction {row[3]:g} for rotor {k + 1}")
        return tuple(tuple(float(v) for v in row) for row in rows)


_TEXT = Check("text", "a string", lambda v: isinstance(v, str))


@dataclass(frozen=True)
class RotorVehicle(Validated):
    """Physical parameters of a multirotor for the rotor-speed plant.

    Parameters
    ----------
    m : float
        Mass [kg], > 0.
    Jxx, Jyy, Jzz : float
        Principal moments of inertia about the body axes [kg m^2], > 0.
    kf : float
        Thrust coefficient: a rotor's thrust is kf w^2 [N/(rad/s)^2], > 0.
    km : float
        Yaw moment coefficient: a rotor's drag moment is km w^2 [N m/(rad/s)^2], >= 0.
    tau_up, tau_down : float
        Motor time constants [s] while speeding up and slowing down, > 0.
    w_min, w_max : float
        Rotor speed range [rad/s], 0 <= w_min < w_max.
    rotors : sequence of (x, y, z, s)
        Each rotor's hub in the body frame [m] (x forward, y left, z up) and its direction s:
        +1 when its drag moment pushes the body about +z (it spins clockwise seen from above),
        -1 otherwise. The order is the order of the commands.
    g : float
        Gravitational acceleration [m/s^2], >= 0.
    c_Dx, c_Dy, c_Dz : float
        Parasitic drag coefficients along the body axes [N/(m/s)^2], >= 0.
    k_d : float
        Rotor drag coefficient [N/(rad/s m/s)], >= 0.
    k_z : float
        Induced inflow coefficient [N/(rad/s m/s)], >= 0.
    k_h : float
        Translational lift coefficient [N/(m/s)^2], >= 0.
    k_flap : float
        Flapping moment coefficient [N m/(rad/s m/s)], >= 0.
    J_rotor : float
        One rotor's (with its motor's rotating part) inertia about its axis [kg m^2], >= 0.
    control_bandwidth : float
        The actuator bandwidth [rad/s] that the controllers' gains are designed for
        (:mod:`quadcruise.model.equivalent`); 0, the default: the motors' own,
        1 / max(tau_up, tau_down). A preset sets it where gains designed for the motors' lag
        do not fly (the Hummingbird's 5 ms motors).
    touchdown_speed : float
        The fastest vertical speed [m/s] at which it may meet the ground (when a flight has
        one); faster is a crash. 1 m/s by default: PX4 lands at 0.7 m/s (``MPC_LAND_SPEED``).
    source : str
        Where the numbers come from.
    """

    m: float = _f(unit="kg", doc="mass", check="pos")
    Jxx: float = _f(unit="kg m^2", doc="moment of inertia about body x", check="pos")
    Jyy: float = _f(unit="kg m^2", doc="moment of inertia about body y", check="pos")
    Jzz: float = _f(unit="kg m^2", doc="moment of inertia about body z", check="pos")
    kf: float = _f(unit="N/(rad/s)^2", doc="thrust coefficient", check="pos")
    km: float = _f(unit="N m/(rad/s)^2", doc="yaw moment coefficient", check="nonneg")
    tau_up: float = _f(unit="s", doc="motor time constant speeding up", check="pos")
    tau_down: float = _f(unit="s", doc="motor time constant slowing down", check="pos")
    w_min: float = _f(unit="rad/s", doc="lowest rotor speed", check="nonneg")
    w_max: float = _f(unit="rad/s", doc="highest rotor speed", check="pos")
    rotors: tuple = _f(unit="m, m, m, -", doc="rotor positions and directions", check=_Rotors())
    g: float = _f(9.81, "m/s^2", "gravitational acceleration", "nonneg")
    c_Dx: float = _f(0.0, "N/(m/s)^2", "parasitic drag along body x", "nonneg")
    c_Dy: float = _f(0.0, "N/(m/s)^2", "parasitic drag along body y", "nonneg")
    c_Dz: float = _f(0.0, "N/(m/s)^2", "parasitic drag along body z", "nonneg")
    k_d: float = _f(0.0, "N/(rad/s m/s)", "rotor drag coefficient", "nonneg")
    k_z: float = _f(0.0, "N/(rad/s m/s)", "induced inflow coefficient", "nonneg")
    k_h: float = _f(0.0, "N/(m/s)^2", "translational lift coefficient", "nonneg")
    k_flap: float = _f(0.0, "N m/(rad/s m/s)", "flapping moment coefficient", "nonneg")
    J_rotor: float = _f(0.0, "kg m^2", "a rotor's inertia about its axis", "nonneg")
    control_bandwidth: float = _f(0.0, "rad/s", "bandwidth the controllers are designed for (0: the motors')", "nonneg")
    touchdown_speed: float = _f(1.0, "m/s", "fastest descent its landing gear survives", "pos")
    source: str = _f("", "-", "where the numbers come from", _TEXT)

    name: ClassVar[str] = "vehicle"

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.w_max > self.w_min:
            raise InputError(
                f"vehicle field 'w_max' ({self.w_max:g} rad/s) must be above 'w_min' ({self.w_min:g} rad/s)"
            )
        lift, weight = self.n_rotors * self.kf * self.w_max * self.w_max, self.m * self.g
        if not (math.isfinite(self.w_max * self.w_max) and math.isfinite(lift)):  # w_max**2: an OverflowError
            raise InputError(
                f"vehicle field 'w_max' ({self.w_max:g} rad/s) is out of range: w_max^2 "
                f"or {self.n_rotors} rotors x kf w_max^2 is not a finite number"
            )
        if not lift > weight:
            raise InputError(
                f"vehicle cannot lift itself: {self.n_rotors} rotors x kf w_max^2 = {lift:.4g} N, "
                f"its weight m g = {weight:.4g} N"
            )
        if lift > MAX_THRUST_TO_WEIGHT * weight:
            raise InputError(
                f"vehicle field 'kf' ({self.kf:g} N/(rad/s)^2) is out of physical range: {self.n_rotors} rotors x "
                f"kf w_max^2 = {lift:.4g} N is {lift / weight:.3g} times the weight m g = {weight:.4g} N "
                f"(at most {MAX_THRUST_TO_WEIGHT:g}; a rotor's kf is about 1e-8 to 1e-4)"
            )
        angles = sorted(math.atan2(y, x) for x, y, _, _ in self.rotors if math.hypot(x, y) > 0.0)
        gaps = (
            [b - a for a, b in zip(angles, angles[1:] + [angles[0] + 2.0 * math.pi], strict=False)] if angles else [7.0]
        )
        if max(gaps) >= math.pi - 1e-9:
            raise InputError(
                "vehicle field 'rotors': the rotors do not surround the centre of mass (seen from "
                "above they all lie on one side of a line through it), so some tilt cannot be "
                "commanded"
            )

    # --- constructors ---------------------------------------------------------------------
    @classmethod
    def preset(cls, name: str) -> RotorVehicle:
        """A rotor-plant vehicle from the presets (:mod:`quadcruise.model.vehicle_files`).

        Parameters
        ----------
        name : str
            A preset's name: ``crazyflie``, ``hummingbird``, ``iris``.

        Returns
        -------
        RotorVehicle

        Raises
        ------
        InputError
            An unknown name, or the paper's preset (the paper's plant flies it:
            :meth:`quadcruise.Vehicle.preset`).
        """
        return load_vehicle(name, {"rotor": cls})

    def replace(self, **changes: Any) -> RotorVehicle:
        """A copy with some fields changed (validated again).

        Parameters
        ----------
        **changes : Any
            Field name -> new value, in the field's unit.

        Returns
        -------
        RotorVehicle

        Raises
        ------
        InputError
            A name that is not a field, or a bad value.
        """
        unknown = set(changes) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise InputError(f"unknown vehicle field(s): {', '.join(sorted(unknown))}")
        return dataclasses.replace(self, **changes)

    def without_aero(self) -> RotorVehicle:
        """The same vehicle with every aerodynamic coefficient zero (RotorPy's ``aero=False``).

        Returns
        -------
        RotorVehicle
        """
        return self.replace(**dict.fromkeys(AERO_FIELDS, 0.0))

    # --- views ----------------------------------------------------------------------------
    @property
    def n_rotors(self) -> int:
        """Number of rotors."""
        return len(self.rotors)

    def command_speed(self, duty):
        """The rotor speed a normalised motor command (a duty) asks for: w = duty w_max [rad/s].

        The vehicle's command-to-speed map: PX4's normalised motor command with ``THR_MDL_FAC``
        = 1 (thrust kf w_max^2 duty^2, quadratic in the command), as ``to_ulog`` writes a rotor
        flight's ``actuator_outputs`` (its ``actuator_motors``: the relative thrust duty^2).

        Parameters
        ----------
        duty : float or array_like
            Commands in [0, 1].

        Returns
        -------
        float or numpy.ndarray
            Commanded rotor speeds [rad/s].

        Examples
        --------
        >>> RotorVehicle.preset("iris").command_speed(0.5)
        550.0
        """
        return np.asarray(duty, dtype=float) * self.w_max if np.ndim(duty) else float(duty) * self.w_max

    @property
    def hover_speed(self) -> float:
        """Rotor speed [rad/s] at which the rotors together carry the weight: sqrt(m g / (n kf))."""
        return math.sqrt(self.m * self.g / (self.n_rotors * self.kf))

    def row(self) -> np.ndarray:
        """The parameter row the compiled plant reads (:mod:`quadcruise.model.rotor_plant`).

        Returns
        -------
        numpy.ndarray
            Shape (ROTOR_P_ROTORS + 4 n,), float64: the fields of ``ROTOR_PARAMS`` in SI units (at
            ``ROTOR_P_*``), then each rotor's ``ROTOR_ARM``: x, y, z [m] and direction s.
        """
        head = ROTOR_PARAMS.pack({name: getattr(self, name) for name, _ in ROTOR_PARAMS.all_fields})
        arms = [ROTOR_ARM.pack(dict(zip(("x", "y", "z", "s"), rotor, strict=True))) for rotor in self.rotors]
        return np.concatenate([head, *arms])

    def to_dict(self) -> dict:
        """The fields as plain values (rotors as a list of lists), for result bundles and TOML.

        Returns
        -------
        dict
            Field name -> value, SI units.
        """
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        out["rotors"] = [list(r) for r in self.rotors]
        return out

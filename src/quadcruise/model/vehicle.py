"""Vehicle parameters: frozen, validated, with units, and able to carry a batch axis.

The default is the paper's Table I (the Quanser Qball-X4 of its reference [8]), with the
yaw moment arm ``d`` the paper leaves out derived from the Qball-X4's documented yaw
torque gain (4 N m per unit duty) divided by the thrust gain K: d = 4/120 m. The paper's
model has no aerodynamic drag, so both drag coefficients default to zero; wind acts on the
vehicle only through them (see :mod:`quadcruise.disturbances`).

A field may be a scalar (every vehicle alike) or a 1-D array of length N (each vehicle its
own value). :meth:`Vehicle.rows` turns either into the ``(N, PARAM_SIZE)`` array the
compiled engine reads.

Examples
--------
>>> from quadcruise import Vehicle
>>> v = Vehicle.paper()
>>> round(v.hover_duty, 4)
0.0715
>>> v.replace(m=1.4).m
1.4
>>> import numpy as np
>>> batch = v.replace(m=np.array([3.0, 3.5, 4.0]))
>>> batch.batch_size, batch.rows().shape
(3, (3, 21))
>>> Vehicle.paper().replace(m=0.0)
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: vehicle field 'm' (mass, kg) must be > 0, got 0.0
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from quadcruise import layout as L
from quadcruise.errors import InputError
from quadcruise.fields import Validated
from quadcruise.fields import unit_field as _f


@dataclass(frozen=True)
class Vehicle(Validated):
    """Physical parameters of a quadrotor (the paper's Table I by default).

    Each field is a float, or a 1-D array giving one value per vehicle of a batch; fields are
    checked by :func:`quadcruise.fields.validate` and their units listed by :meth:`units`.

    Parameters
    ----------
    m : float or array
        Mass [kg], > 0.
    Jxx, Jyy, Jzz : float or array
        Moments of inertia about the body axes [kg m^2], > 0.
    l : float or array
        Arm length, rotor to centre [m], > 0.
    K : float or array
        Thrust per unit PWM duty [N], > 0.
    omega : float or array
        Actuator bandwidth [rad/s], > 0.
    d : float or array
        Yaw moment per unit thrust [m], > 0.
    g : float or array
        Gravitational acceleration [m/s^2], >= 0.
    drag_linear : float or array
        Linear drag coefficient on the air-relative velocity [N s/m], >= 0.
    drag_quadratic : float or array
        Quadratic drag coefficient on the air-relative velocity [N s^2/m^2], >= 0.

    Examples
    --------
    >>> Vehicle(m=1.4).m, Vehicle.units()["Jxx"]
    (1.4, 'kg m^2')
    >>> Vehicle(K=[120, -1])
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: vehicle field 'K' (thrust per unit PWM duty (Table I's K), N) must be > 0, ...
    """

    m: Any = _f(3.499, "kg", "mass", "pos", batch=True)
    Jxx: Any = _f(0.03, "kg m^2", "moment of inertia about body x", "pos", batch=True)
    Jyy: Any = _f(0.03, "kg m^2", "moment of inertia about body y", "pos", batch=True)
    Jzz: Any = _f(0.04, "kg m^2", "moment of inertia about body z", "pos", batch=True)
    l: Any = _f(0.2, "m", "arm length, rotor to centre (Table I's L)", "pos", batch=True)
    K: Any = _f(120.0, "N", "thrust per unit PWM duty (Table I's K)", "pos", batch=True)
    omega: Any = _f(15.0, "rad/s", "actuator bandwidth (first-order rotor lag)", "pos", batch=True)
    d: Any = _f(4.0 / 120.0, "m", "yaw moment per unit thrust, eq (4)", "pos", batch=True)
    g: Any = _f(9.81, "m/s^2", "gravitational acceleration", "nonneg", batch=True)
    drag_linear: Any = _f(0.0, "N s/m", "linear drag coefficient (air-relative velocity)", "nonneg", batch=True)
    drag_quadratic: Any = _f(0.0, "N s^2/m^2", "quadratic drag coefficient", "nonneg", batch=True)

    name: ClassVar[str] = "vehicle"

    # --- constructors -------------------------------------------------------------------
    @classmethod
    def paper(cls) -> Vehicle:
        """The paper's Table I (Qball-X4) with d = 4/120 m.

        Returns
        -------
        Vehicle
            One shared, frozen instance (:func:`shared_default`), unbatched.

        Examples
        --------
        >>> Vehicle.paper() is Vehicle.paper(), Vehicle.paper().m
        (True, 3.499)
        """
        return shared_default(cls)

    @classmethod
    def preset(cls, name: str) -> Any:
        """A preset vehicle from published data (:mod:`quadcruise.model.vehicle_files`).

        Parameters
        ----------
        name : str
            ``paper`` (Table I: a :class:`Vehicle`, flown by the paper's plant) or a rotor-plant
            vehicle: ``crazyflie``, ``hummingbird``, ``iris``.

        Returns
        -------
        Vehicle or quadcruise.model.rotor_vehicle.RotorVehicle

        Raises
        ------
        InputError
            An unknown name.

        Examples
        --------
        >>> Vehicle.preset("paper") == Vehicle.paper(), type(Vehicle.preset("iris")).__name__
        (True, 'RotorVehicle')
        """
        return cls.load(name)

    @classmethod
    def load(cls, name_or_path: Any) -> Any:
        """A vehicle from a preset's name or a vehicle file (``[vehicle] preset = "iris"`` and
        the fields to change, or every field).

        Parameters
        ----------
        name_or_path : str or pathlib.Path
            A preset's name, or a TOML file (a name ending in ``.toml``).

        Returns
        -------
        Vehicle or quadcruise.model.rotor_vehicle.RotorVehicle

        Raises
        ------
        InputError
            An unknown preset, a missing or bad file, an unknown key or a bad value, naming
            the file and the key; an ``ArgumentTypeError`` (one) for anything but text or a path.
        """
        import os

        from quadcruise import checks
        from quadcruise.model.rotor_vehicle import RotorVehicle
        from quadcruise.model.vehicle_files import load_vehicle

        want = "a preset's name or the path of a vehicle file"
        checks.instance("Vehicle.load()", "name_or_path", name_or_path, (str, os.PathLike), optional=False, want=want)
        return load_vehicle(name_or_path, {"paper": cls, "rotor": RotorVehicle})

    def replace(self, **changes: Any) -> Vehicle:
        """A copy with some fields changed (validated again).

        Parameters
        ----------
        **changes : Any
            Field name -> new value (a float, or a 1-D array for one value per vehicle), in
            the field's unit (``m`` [kg], ``l`` [m], ...).

        Returns
        -------
        Vehicle

        Raises
        ------
        InputError
            A name that is not a field, or a bad value.
        """
        unknown = set(changes) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise InputError(f"unknown vehicle field(s): {', '.join(sorted(unknown))}")
        return dataclasses.replace(self, **changes)

    @classmethod
    def stack(cls, vehicles: list[Vehicle]) -> Vehicle:
        """One batched Vehicle from a list of vehicles, in order.

        Parameters
        ----------
        vehicles : list of Vehicle
            Single vehicles (one row each) or batched ones (their N rows each).

        Returns
        -------
        Vehicle
            Every field a 1-D array, one entry per row of the inputs.

        Raises
        ------
        InputError
            An empty list.

        Examples
        --------
        >>> v = Vehicle.paper()
        >>> Vehicle.stack([v, v.replace(m=[1.0, 2.0])]).m
        array([3.499, 1.   , 2.   ])
        """
        if not vehicles:
            raise InputError("cannot stack an empty list of vehicles")
        cols = {
            f.name: np.concatenate([np.atleast_1d(getattr(v, f.name)) * np.ones(v.batch_size or 1) for v in vehicles])
            for f in dataclasses.fields(cls)
        }
        return cls(**cols)

    # --- views --------------------------------------------------------------------------
    @property
    def batch_size(self) -> int | None:
        """N if any field carries a batch axis, else None."""
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, np.ndarray):
                return value.shape[0]
        return None

    @property
    def hover_duty(self) -> Any:
        """PWM duty per rotor that holds hover: m g / (4 K)."""
        return self.m * self.g / (4.0 * self.K)

    @property
    def k(self) -> tuple:
        """(k1, ..., k6) of the paper's Section III, eq (11)."""
        return (
            (self.Jyy - self.Jzz) / self.Jxx,
            self.l / self.Jxx,
            (self.Jzz - self.Jxx) / self.Jyy,
            self.l / self.Jyy,
            (self.Jxx - self.Jyy) / self.Jzz,
            1.0 / self.Jzz,
        )

    def rows(self, n: int | None = None) -> np.ndarray:
        """The ``(N, PARAM_SIZE)`` parameter array for the compiled engine.

        ``n`` broadcasts an unbatched vehicle to N rows; a batched one must match it.

        Parameters
        ----------
        n : int, optional
            Number of rows N; by default the batch size (1 for an unbatched vehicle).

        Returns
        -------
        numpy.ndarray
            Shape (N, PARAM_SIZE), float64, columns ``P_*`` of :mod:`quadcruise.layout`:
            the fields in SI units, k1..k6 of eq (11), the drag coefficients and 1/m
            [1/kg], 1/Jxx, 1/Jyy, 1/Jzz [1/(kg m^2)].

        Raises
        ------
        InputError
            A batched vehicle whose size is not ``n``.
        """
        size = self.batch_size
        if n is None:
            n = size or 1
        if size is not None and size != n:
            raise InputError(f"vehicle batch has {size} entries but {n} vehicles were asked for")
        out = np.empty((n, L.PARAM_SIZE))
        for col, name in (
            (L.P_M, "m"),
            (L.P_JXX, "Jxx"),
            (L.P_JYY, "Jyy"),
            (L.P_JZZ, "Jzz"),
            (L.P_L, "l"),
            (L.P_K, "K"),
            (L.P_OMEGA, "omega"),
            (L.P_D, "d"),
            (L.P_G, "g"),
        ):
            out[:, col] = getattr(self, name)
        for col, value in zip((L.P_K1, L.P_K2, L.P_K3, L.P_K4, L.P_K5, L.P_K6), self.k, strict=False):
            out[:, col] = value
        out[:, L.P_CD1] = self.drag_linear
        out[:, L.P_CD2] = self.drag_quadratic
        for col, src in ((L.P_INV_M, L.P_M), (L.P_INV_JXX, L.P_JXX), (L.P_INV_JYY, L.P_JYY), (L.P_INV_JZZ, L.P_JZZ)):
            out[:, col] = 1.0 / out[:, src]
        return out

    def to_dict(self) -> dict:
        """The fields as plain values, for result bundles.

        Returns
        -------
        dict
            Field name -> float, or list of floats for a batched field (SI units).
        """
        return {
            f.name: (
                getattr(self, f.name).tolist()
                if isinstance(getattr(self, f.name), np.ndarray)
                else getattr(self, f.name)
            )
            for f in dataclasses.fields(self)
        }


@functools.cache
def shared_default(cls: type) -> Any:
    """``cls()`` of a frozen dataclass, built and validated once and shared by every caller
    (the default vehicle, mission or controller of each ``fly``).

    Parameters
    ----------
    cls : type
        A frozen dataclass whose fields all have defaults.

    Returns
    -------
    object
        The shared instance (the same object on every call with the same ``cls``).
    """
    return cls()

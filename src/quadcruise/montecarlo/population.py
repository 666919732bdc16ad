"""The population of a Monte Carlo sweep: how each vehicle differs from the nominal one.

:class:`Population` holds relative spreads of the vehicle's parameters, an initial position
offset, a random steady wind, an :class:`~quadcruise.disturbances.Environment` and
:class:`~quadcruise.disturbances.SensorNoise`; :meth:`Population.draw` turns them into a
:class:`Draw`: the batched vehicles of one chunk.

A rotor-plant nominal vehicle (:class:`~quadcruise.model.rotor_vehicle.RotorVehicle`) is
perturbed field by field with the same draws (:data:`ROTOR_SPREADS`): the mass, each inertia,
``kf`` (the thrust spread), ``km`` (the yaw-arm spread: the paper's d is km / kf), the motor
time constants (the bandwidth spread: ``tau_up`` and ``tau_down`` are divided by one drawn
factor, so the bandwidth 1 / tau is spread as the paper's omega is, and the motor keeps the
ratio of its two lags), and with ``aero_spread`` its aerodynamic coefficients (one factor for
the body's parasitic drag, another for the rotor terms). The draws of vehicle i are the same
on both plants.

Randomness. Vehicle i's drawn parameters come only from
``numpy.random.SeedSequence([seed, i], spawn_key=(1,))`` (16 unit draws, always all of
them, in a fixed order, so changing one spread never moves another's draws); its sensor
noise and turbulence come from the engine's stream of ``(seed, i)``
(:mod:`quadcruise.sim.rng`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import ArgumentTypeError, InputError
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.montecarlo.sensor_spread import SENSOR_SPREADS, check_sensors, drawn_sensors
from quadcruise.sim import plants
from quadcruise.sim.fastmath import seeded_draws

__all__ = ["Population", "Draw", "DRAW_KEY", "N_DRAWS", "SLOTS", "SPREADS", "ROTOR_SPREADS", "ROTOR_SLOTS", "CLIP"]

DRAW_KEY = 1
"""spawn_key of the population's draws (the engine's own streams have none)."""
N_DRAWS = 16
SLOTS = {
    "m": 0,
    "Jxx": 1,
    "Jyy": 2,
    "Jzz": 3,
    "K": 4,
    "omega": 5,
    "d": 6,
    "dx0": 7,
    "dy0": 8,
    "dz0": 9,
    "wind_x": 10,
    "wind_y": 11,
}
"""Which of the 16 unit draws of a vehicle feeds which quantity (:data:`ROTOR_SLOTS`: 12, 13; the sensors'
spreads: 14, 15, :mod:`quadcruise.montecarlo.sensor_spread`)."""
SPREADS = {
    "mass_spread": ("m",),
    "inertia_spread": ("Jxx", "Jyy", "Jzz"),
    "thrust_spread": ("K",),
    "bandwidth_spread": ("omega",),
    "yaw_arm_spread": ("d",),
}
"""The paper vehicle's fields each spread perturbs."""
ROTOR_SPREADS = {
    "mass_spread": ("m",),
    "inertia_spread": ("Jxx", "Jyy", "Jzz"),
    "thrust_spread": ("kf",),
    "bandwidth_spread": ("tau_up", "tau_down"),
    "yaw_arm_spread": ("km",),
    "aero_spread": ("c_Dx", "c_Dy", "c_Dz", "k_d", "k_z", "k_h", "k_flap"),
}
"""A rotor-plant vehicle's fields each spread perturbs (the module says how)."""
ROTOR_SLOTS = {
    "m": 0,
    "Jxx": 1,
    "Jyy": 2,
    "Jzz": 3,
    "kf": 4,
    "km": 6,
    "tau_up": 5,
    "tau_down": 5,
    "c_Dx": 12,
    "c_Dy": 12,
    "c_Dz": 12,
    "k_d": 13,
    "k_z": 13,
    "k_h": 13,
    "k_flap": 13,
}
"""The unit draw that perturbs each field of a rotor-plant vehicle: the paper slot of the same
quantity (kf: K's, tau: omega's, km: d's); one draw for the body drag, one for the rotor terms."""
CLIP = {"normal": 3.0, "uniform": math.sqrt(3.0)}
"""Largest |unit draw|: normal draws are truncated at 3 sigma (a draw beyond is drawn again:
:meth:`Population.unit_draws`), uniform ones span +-sqrt(3) (unit standard deviation)."""


@dataclass(frozen=True)
class Population:
    """How the vehicles of a sweep differ from the nominal one.

    Parameters
    ----------
    mass_spread, inertia_spread, thrust_spread, bandwidth_spread, yaw_arm_spread : float
        Relative standard deviations of m; of Jxx, Jyy, Jzz (each drawn on its own); of the
        thrust gain K; of the rotor bandwidth omega; of the yaw moment arm d. A value is
        ``nominal * (1 + spread * z)`` with z a unit draw: normal truncated to [-3, 3], or
        uniform on [-sqrt 3, sqrt 3]. So that every value stays positive a spread must be
        < 1/3 (normal) or < 1/sqrt 3 (uniform).
    offset : float
        Standard deviation [m] of the initial position offset on each axis (same truncation).
    wind_spread : float
        Standard deviation [m/s] of a steady horizontal wind on x and on y, drawn per vehicle
        and added to the environment's steady wind.
    distribution : {"normal", "uniform"}
        The distribution of the unit draws.
    environment : Environment, optional
        Wind, gust, turbulence, rotor loss, the same for every vehicle (turbulence differs by
        vehicle through its random stream). Wind acts through drag: a vehicle without drag
        gets :data:`~quadcruise.disturbances.DEFAULT_DRAG` (with a warning).
    noise : SensorNoise, optional
        Sensor noise and delay, the same for every vehicle (the noise itself differs by
        vehicle through its random stream).
    model_error : bool
        The controller computes with the nominal vehicle (True) or knows each vehicle's
        drawn parameters (False).
    aero_spread : float
        Relative standard deviation of a rotor-plant vehicle's aerodynamic coefficients: one
        factor for c_Dx, c_Dy, c_Dz, another for k_d, k_z, k_h, k_flap. The paper's vehicle
        has none to spread (a sweep of it refuses a value > 0).
    identified : Identified, optional
        Parameters identified from a log, each vehicle's drawn from their estimate and
        covariance (:mod:`quadcruise.montecarlo.identified`; :meth:`from_identification`),
        instead of the nominal's; a spread of the same field is refused.
    sensors : Sensors, optional
        The sensor models every vehicle carries (:class:`~quadcruise.estimation.Sensors`; each
        vehicle's readings from its own stream); not with ``noise``.
    estimator : Ekf, optional
        The filter every controller flies on (:class:`~quadcruise.estimation.Ekf`; needs
        ``sensors`` with an IMU and a GPS): the sweep's table then holds the estimation error.
    imu_noise_spread, gps_noise_spread : float
        Relative standard deviations of each vehicle's IMU noise (densities, bias walks and
        switch-on spreads) and GPS noise, the filter matched to the nominal sensors
        (:mod:`quadcruise.montecarlo.sensor_spread`); same bounds as the vehicle's spreads.

    Raises
    ------
    InputError
        For a negative or too large spread, an unknown distribution, or an environment or
        noise that is not the same for every vehicle.

    Examples
    --------
    >>> p = Population(mass_spread=0.1)
    >>> d = p.draw(seed=1, first=0, count=5, nominal=Vehicle.paper())
    >>> d.vehicle.batch_size, bool(np.all(p.draw(1, 3, 2, Vehicle.paper()).vehicle.m == d.vehicle.m[3:]))
    (5, True)
    >>> Population(mass_spread=-0.1)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: population field 'mass_spread' must be a number >= 0, got float -0.1
    """

    mass_spread: float = 0.0
    inertia_spread: float = 0.0
    thrust_spread: float = 0.0
    bandwidth_spread: float = 0.0
    yaw_arm_spread: float = 0.0
    offset: float = 0.0
    wind_spread: float = 0.0
    distribution: str = "normal"
    environment: Any = None
    noise: Any = None
    model_error: bool = True
    aero_spread: float = 0.0
    identified: Any = None
    sensors: Any = None
    estimator: Any = None
    imu_noise_spread: float = 0.0
    gps_noise_spread: float = 0.0

    @classmethod
    def from_identification(cls, source, **fields) -> Population:
        """The vehicles a log is consistent with: each identified parameter drawn from its
        estimate and covariance (:mod:`quadcruise.montecarlo.identified`).

        Parameters
        ----------
        source : str or os.PathLike
            ``identify.json``, or the folder ``quadcruise identify --out`` wrote.
        **fields
            The population's other fields (an offset, wind, noise, a spread of a field not identified).

        Returns
        -------
        Population

        Examples
        --------
        >>> Population.from_identification("missing/identify.json")
        Traceback (most recent call last):
            ...
        quadcruise.errors.InputError: missing/identify.json: no such file (an identification is the ...
        """
        from quadcruise.montecarlo.identified import Identified

        return cls(identified=Identified.read(source), **fields)

    def __post_init__(self) -> None:
        if self.distribution not in CLIP:
            raise InputError(f"population field 'distribution' must be normal or uniform, got {self.distribution!r}")
        for name in (*ROTOR_SPREADS, *SENSOR_SPREADS, "offset", "wind_spread"):
            value = getattr(self, name)
            wrong_type = isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating))
            if wrong_type or not math.isfinite(value) or value < 0:
                raise (ArgumentTypeError if wrong_type else InputError)(
                    f"population field '{name}' must be a number >= 0, got {describe(value)}"
                )
            object.__setattr__(self, name, float(value))
            limit = 1.0 / CLIP[self.distribution]
            if (name in ROTOR_SPREADS or name in SENSOR_SPREADS) and value >= limit:
                raise InputError(
                    f"population field '{name}' = {value:g} is too large: with {self.distribution} "
                    f"draws it must be < {limit:.4f} so that every value stays positive"
                )
        from quadcruise.disturbances import Environment, SensorNoise

        if self.environment is not None:
            if not isinstance(self.environment, Environment):
                raise InputError("population field 'environment' must be an Environment or None")
            if self.environment.batch_size is not None:
                raise InputError(
                    "the population's environment must be the same for every vehicle "
                    "(per-vehicle values come from the spreads)"
                )
        if self.noise is not None:
            if not isinstance(self.noise, SensorNoise):
                raise InputError("population field 'noise' must be a SensorNoise or None")
            if np.ndim(self.noise.std_vector()) > 1:
                raise InputError("the population's sensor noise must be the same for every vehicle")
        check_sensors(self.sensors, self.estimator, self.noise, {k: getattr(self, k) for k in SENSOR_SPREADS})
        object.__setattr__(self, "model_error", bool(self.model_error))
        if self.identified is not None:
            from quadcruise.montecarlo.identified import Identified

            if isinstance(self.identified, dict):  # as to_dict wrote it (a sweep's scenario.toml)
                object.__setattr__(self, "identified", Identified.from_dict(self.identified))
            if not isinstance(self.identified, Identified):
                raise InputError("population field 'identified' must be an Identified or None")
            for spread, names in ROTOR_SPREADS.items():
                both = [n for n in names if n in self.identified.names]
                if getattr(self, spread) > 0 and both:
                    raise InputError(
                        f"population field '{spread}' spreads {', '.join(both)}, which the identification "
                        f"{self.identified.source} draws from its estimate: give one of them"
                    )

    @property
    def needs_drag(self) -> bool:
        """True if the vehicles meet wind (which acts only through drag)."""
        return self.wind_spread > 0 or (self.environment is not None and self.environment.needs_drag)

    @property
    def perturbs(self) -> bool:
        """True if its vehicles can differ from one another: a spread, a start offset, a random
        steady wind, turbulence (a random stream per vehicle) or sensor noise.

        Examples
        --------
        >>> Population().perturbs, Population(offset=0.1).perturbs
        (False, True)
        """
        if self.spreads_vehicle or self.offset > 0 or self.wind_spread > 0:
            return True
        if self.environment is not None and self.environment.turbulence is not None:
            return True
        if self.sensors is not None:  # each vehicle's readings from its own stream
            return True
        return self.noise is not None and bool(np.any(np.asarray(self.noise.std_vector()) > 0))

    def check_perturbs(self, n: int, hint: str | None = None) -> None:
        """Refuse n > 1 vehicles that could not differ: they would fly the same flight n times
        and every quantile of theirs would be the same number.

        Parameters
        ----------
        n : int
            Number of vehicles.
        hint : str, optional
            What perturbs, said after "give"; the options of ``quadcruise montecarlo`` by default.

        Raises
        ------
        InputError
            One line with the options that perturb.

        Examples
        --------
        >>> try:
        ...     Population().check_perturbs(3)
        ... except InputError as exc:
        ...     print(str(exc).split(";")[0])
        the population perturbs nothing: its 3 vehicles would fly the same flight
        """
        hint = hint or (
            "a spread (--mass-spread 0.1, --inertia-spread, --thrust-spread, --bandwidth-spread, "
            "--yaw-arm-spread, --aero-spread), a start --offset, a --wind-spread, turbulence (--turbulence moderate) "
            "or sensor --noise or --sensors"
        )
        if n > 1 and not self.perturbs:
            raise InputError(
                f"the population perturbs nothing: its {n:,} vehicles would fly the same flight; give {hint}"
            )

    def unit_draws(self, seed: int, first, count: int) -> np.ndarray:
        """The unit draws of vehicles first .. first + count - 1 (see the module).

        Parameters
        ----------
        seed : int
            The sweep's seed.
        first : int or array of int
            Index of the first vehicle; or the (count,) indices of the vehicles themselves
            (repeats allowed: a tuner flies each candidate on the same vehicles).
        count : int
            Number of vehicles.

        Returns
        -------
        ndarray, shape (count, 16)
            Unit draws [-]: standard normal truncated to [-3, 3], or uniform on
            [-sqrt 3, sqrt 3]; column :data:`SLOTS` feeds each quantity. A normal draw
            beyond 3 sigma (0.27 % of them) is replaced, in column order, by the next draws of
            the vehicle's stream that fall within: a clip would give each such vehicle the
            same value, so that a 10,000-vehicle sweep held a dozen identical copies of the
            +3 sigma vehicle.

        Examples
        --------
        >>> z = Population(mass_spread=0.1).unit_draws(1, 0, 10_000)
        >>> bool(np.abs(z).max() <= 3.0), len(np.unique(z[:, 0])) == 10_000
        (True, True)
        """
        normal = self.distribution == "normal"
        ids = int(first) + np.arange(count) if np.ndim(first) == 0 else np.ravel(first)
        if len(ids) != count:
            raise InputError(f"the population needs {count} vehicle indices, got {len(ids)}")
        # vehicle i: np.random.default_rng(np.random.SeedSequence([seed, i], spawn_key=(DRAW_KEY,))), bit for bit
        out = seeded_draws(seed, ids, DRAW_KEY, N_DRAWS, normal)
        clip = CLIP[self.distribution]
        if not normal:
            return clip * (2.0 * out - 1.0)
        beyond = np.abs(out) > clip
        for r in np.flatnonzero(beyond.any(axis=1)):  # truncated: drawn again from the same stream
            slots, spare = np.flatnonzero(beyond[r]), N_DRAWS
            while True:
                more = seeded_draws(seed, ids[r : r + 1], DRAW_KEY, 2 * N_DRAWS + spare, True)[0, N_DRAWS:]
                more = more[np.abs(more) <= clip]
                if more.size >= slots.size:
                    out[r, slots] = more[: slots.size]
                    break
                spare *= 2
        return out

    @property
    def spreads_vehicle(self) -> bool:
        """True if a spread perturbs the vehicle's parameters (not only its start, wind or sensors)."""
        return self.identified is not None or any(getattr(self, name) > 0 for name in ROTOR_SPREADS)

    def draw(
        self,
        seed: int,
        first,
        count: int,
        nominal: Vehicle | RotorVehicle,
        dt: float = 1e-3,
        *,
        batch_vehicle: bool = True,
    ) -> Draw:
        """The vehicles first .. first + count - 1: parameters, offsets and environment.

        Parameters
        ----------
        seed : int
            The sweep's seed.
        first : int or array of int
            Index of the first vehicle; or the (count,) indices of the vehicles (see
            :meth:`unit_draws`).
        count : int
            Number of vehicles.
        nominal : Vehicle or RotorVehicle
            The nominal vehicle (not batched).
        dt : float
            Control period [s] (unused: the draws do not depend on it).
        batch_vehicle : bool
            False: when no spread perturbs the vehicle, the Draw's vehicle is the (unbatched)
            nominal paper vehicle itself, for a caller that needs only its rows (an
            environment's reset); its rows equal the batch's.

        Returns
        -------
        Draw
            The batched vehicles and what was drawn for them.
        """
        plant = plants.of(nominal, "the nominal vehicle of a population")
        if plant.count(nominal) is not None:
            raise InputError("the nominal vehicle of a population must not be batched")
        plant.refuse("population", "aero_spread", self.aero_spread > 0, label="field")
        z = self.unit_draws(seed, first, count)
        drawn = self._identified_draws(seed, first, count, nominal)
        vehicles, cols = VEHICLE_DRAWS[plant.name](self, nominal, z, drawn, batch_vehicle)
        offsets = self.offset * z[:, [SLOTS["dx0"], SLOTS["dy0"], SLOTS["dz0"]]]
        cols.update(dx0=offsets[:, 0], dy0=offsets[:, 1], dz0=offsets[:, 2])
        env = self.environment
        base = (0.0, 0.0, 0.0) if env is None or env.wind is None else tuple(map(float, env.wind.velocity))
        wind = np.column_stack(
            [
                base[0] + self.wind_spread * z[:, SLOTS["wind_x"]],
                base[1] + self.wind_spread * z[:, SLOTS["wind_y"]],
                np.full(count, base[2]),
            ]
        )
        cols.update(wind_x=wind[:, 0], wind_y=wind[:, 1])
        if self.wind_spread > 0:
            from quadcruise.disturbances import ConstantWind, Environment

            env = dataclasses.replace(env or Environment(), wind=ConstantWind(velocity=wind))
        if env is not None and not env.parts:
            env = None
        sensors, estimator = self.noise, None
        if self.sensors is not None:
            spreads = (self.imu_noise_spread, self.gps_noise_spread)
            g = float(np.ravel(nominal.g)[0])
            sensors, estimator, spread_cols = drawn_sensors(self.sensors, self.estimator, *spreads, z, g)
            cols.update(spread_cols)
        else:
            cols.update(imu_noise_factor=np.ones(count), gps_noise_factor=np.ones(count))
        return Draw(
            vehicle=vehicles, offsets=offsets, environment=env, sensors=sensors, columns=cols, estimator=estimator
        )

    def _identified_draws(self, seed: int, first, count: int, nominal) -> dict[str, np.ndarray]:
        """The identified parameters drawn for vehicles first .. first + count - 1 (none: {})."""
        if self.identified is None:
            return {}
        fields = {f.name for f in dataclasses.fields(nominal)}
        foreign = [n for n in self.identified.names if n not in fields]
        if foreign:
            raise InputError(
                f"the identification {self.identified.source} draws {', '.join(foreign)}, which the nominal "
                f"{type(nominal).__name__} does not have: fly the vehicle it identified (its vehicle.toml)"
            )
        ids = int(first) + np.arange(count) if np.ndim(first) == 0 else np.ravel(first)
        values = self.identified.draw(seed, ids)
        return {name: values[:, j] for j, name in enumerate(self.identified.names)}

    def _paper_vehicles(self, nominal: Vehicle, z: np.ndarray, drawn: dict, batch_vehicle: bool) -> tuple:
        """The drawn paper vehicles, one batched Vehicle (the nominal itself where nothing spreads it
        and ``batch_vehicle`` is False), and their table columns."""
        cols: dict[str, np.ndarray] = {}
        for spread, names in SPREADS.items():
            for name in names:
                cols[name] = getattr(nominal, name) * (1.0 + getattr(self, spread) * z[:, SLOTS[name]])
        cols.update(drawn)
        vehicles = nominal
        if batch_vehicle or self.spreads_vehicle:
            vehicles = nominal.replace(**{k: cols[k] for names in SPREADS.values() for k in names})
        return vehicles, cols

    def _rotor_vehicles(
        self, nominal: RotorVehicle, z: np.ndarray, drawn: dict | None = None, batch_vehicle: bool = True
    ) -> tuple[tuple, dict]:
        """The drawn rotor-plant vehicles (one per row of unit draws ``z``; ``drawn``: identified
        fields' values) and their table columns (``batch_vehicle``: a tuple of them always)."""
        factors = {}
        for spread, names in ROTOR_SPREADS.items():
            for name in names:
                factors[name] = 1.0 + getattr(self, spread) * z[:, ROTOR_SLOTS[name]]
        vehicles = []
        for k in range(z.shape[0]):
            changes = {}
            for name, f in factors.items():
                if f[k] != 1.0:  # a field not spread keeps its very value
                    base = getattr(nominal, name)
                    changes[name] = float(base / f[k] if name.startswith("tau") else base * f[k])
            changes.update({name: float(values[k]) for name, values in (drawn or {}).items()})
            vehicles.append(_drawn(nominal, changes))
        # the table's columns: the drawn vehicles' "+" equivalents (K, d) and motor bandwidth (omega)
        cols = {name: np.array([getattr(v, name) for v in vehicles]) for name in ("m", "Jxx", "Jyy", "Jzz")}
        cols["K"] = np.array([v.n_rotors / 4.0 * v.kf * v.w_max**2 for v in vehicles])
        cols["omega"] = np.array([1.0 / max(v.tau_up, v.tau_down) for v in vehicles])
        cols["d"] = np.array([v.km / v.kf for v in vehicles])
        return tuple(vehicles), cols

    def to_dict(self) -> dict:
        """Plain values, for the result folder.

        Returns
        -------
        dict
            Field name -> value; the environment and the noise as their ``to_dict()``.
        """
        out = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        for key in ("environment", "noise", "identified", "sensors", "estimator"):
            out[key] = None if out[key] is None else out[key].to_dict()
        for key in ("identified", "sensors", "estimator", *SENSOR_SPREADS):
            if not out[key]:
                del out[key]  # a population without one: its configuration (and hash) as before
        return out


VEHICLE_DRAWS = {"paper": Population._paper_vehicles, "rotor": Population._rotor_vehicles}
"""How a population spreads each plant's vehicle, by the plant's name (:mod:`quadcruise.sim.plants`):
``draw(population, nominal, z, drawn, batch_vehicle) -> (vehicles, columns)``."""


def _drawn(nominal: RotorVehicle, changes: dict) -> RotorVehicle:
    """``nominal`` with the drawn ``changes``. A draw that cannot lift itself (n kf w_max^2 <= m g,
    which RotorVehicle refuses to make) is made anyway and flown: a heavy, weak vehicle of a
    population is a result (it sinks, or lands hard: ``lost track``, ``crashed``), not bad input.
    Every other check holds for any draw: the spreads keep each value positive, and the rotors,
    w_min and w_max are not drawn."""
    if not changes:
        return nominal
    kf, m = changes.get("kf", nominal.kf), changes.get("m", nominal.m)
    if nominal.n_rotors * kf * nominal.w_max**2 > m * nominal.g:
        return nominal.replace(**changes)
    weak = copy.copy(nominal)
    for name, value in changes.items():
        object.__setattr__(weak, name, value)
    return weak


@dataclass(frozen=True)
class Draw:
    """A chunk's drawn vehicles and what was drawn for them (:meth:`Population.draw`).

    Parameters
    ----------
    vehicle : Vehicle or tuple of RotorVehicle
        The vehicles: a batched Vehicle (one value per vehicle of each drawn parameter), or
        one RotorVehicle per vehicle for a rotor-plant nominal.
    offsets : ndarray, shape (count, 3)
        Initial position offsets [m] on x, y, z.
    environment : Environment or None
        The disturbances, with a per-vehicle steady wind [m/s] where one was drawn; None
        if there are none.
    sensors : SensorNoise, Sensors, tuple of Sensors or None
        The sensor noise and delay, or the sensor models (one per vehicle where spread).
    columns : dict of str to ndarray
        The drawn values as table columns: ``m`` [kg], ``Jxx``, ``Jyy``, ``Jzz``
        [kg m^2], ``K`` [N], ``omega`` [rad/s], ``d`` [m], ``dx0``, ``dy0``, ``dz0`` [m],
        ``wind_x``, ``wind_y`` [m/s]. For rotor-plant vehicles K = (n / 4) kf w_max^2 and
        d = km / kf (their "+" equivalent's), omega = 1 / max(tau_up, tau_down) (the motors');
        ``imu_noise_factor``, ``gps_noise_factor`` [-] (1 without a sensor spread).
    estimator : Ekf or None
        The filter the vehicles fly on.
    """

    vehicle: Vehicle
    offsets: np.ndarray
    environment: Any
    sensors: Any
    columns: dict
    estimator: Any = None

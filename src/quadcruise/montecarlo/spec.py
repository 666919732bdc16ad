"""The spec of a Monte Carlo sweep: everything that fixes its flights.

:class:`MonteCarloSpec` joins the :class:`~quadcruise.montecarlo.population.Population` with the
mission, controller, nominal vehicle, seed, flight time and step, the sampling of the log
and of the kept paths, and the failure rules. It has a :meth:`~MonteCarloSpec.hash`: equal
specs fly equal flights, so a folder of chunks is resumed only by the same spec.

Metrics are computed on a log at ``log_dt`` (10 ms by default, not every control period):
this bounds memory (a 60 s flight logs 6,001 instants instead of 60,001) at the cost of
sampling: a maximum taken over 10 ms samples, crossings interpolated between them, the
RMSE integrated by trapezoids 10 ms wide (a trapezoid straddling a jump of the reference,
as in the step mission, is 10 ms wide instead of 1 ms). How far this moves the metrics
from those of a full-rate log was measured once: see docs/performance.md.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import warnings
from dataclasses import dataclass, field
from typing import Any

from quadcruise._cache import code_digest
from quadcruise._version import __version__
from quadcruise.checks import describe
from quadcruise.control import CONTROLLERS, as_controller, controller_record
from quadcruise.errors import InputError, whole_number
from quadcruise.io.plainjson import dumps
from quadcruise.layout import CMD_SIZE, REF_SIZE, STATE_SIZE
from quadcruise.missions import Mission, mission_from_name
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.montecarlo.population import Population
from quadcruise.montecarlo.requirements import Requirement, as_requirements

__all__ = ["MonteCarloSpec"]


def _divisor_at_most(n: int, target: int) -> int:
    """The largest divisor of n that is <= target (>= 1)."""
    for k in range(max(1, min(n, target)), 0, -1):
        if n % k == 0:
            return k
    return 1


@dataclass(frozen=True)
class MonteCarloSpec:
    """Everything that fixes the flights of a sweep (not how many, nor where they run).

    Parameters
    ----------
    mission : Mission or str
        The mission, or its name for the defaults.
    controller : Controller or str
        The controller, or its name for the defaults (for a rotor-plant vehicle: the gains its
        design rules give for the vehicle the controller believes, as :func:`quadcruise.fly` does).
    population : Population
        How the vehicles differ from the nominal one; none by default.
    seed : int
        Vehicle i depends on (seed, i) only.
    duration : float, optional
        Flight time [s]; the mission's default (one lap, ...) if None.
    dt : float
        Control period [s].
    vehicle : Vehicle, RotorVehicle or str
        The nominal vehicle (Table I), or a preset's name (``"iris"``); given drag if the population meets wind. A
        :class:`~quadcruise.model.rotor_vehicle.RotorVehicle` flies the rotor-speed plant (its
        fields perturbed as :mod:`quadcruise.montecarlo.population` says; a start ``offset``
        moves its hover; no ``full_dynamics``; wind only on a vehicle with aerodynamics).
    controller_vehicle : Vehicle, RotorVehicle or str, optional
        The vehicle every controller believes it flies (its model), of the nominal's plant;
        None: the nominal ``vehicle`` (or, with the population's ``model_error`` False, each
        vehicle's own).
    max_step : float, optional
        Longest RK4 substep [s]; dt by default.
    log_dt : float
        Sampling of the log the metrics are computed on [s] (rounded to a divisor of the
        flight's periods).
    trace_dt : float
        Sampling of the kept paths [s].
    max_traces : int
        Paths kept of the first this many vehicles (a random sample: the draws are i.i.d.).
    max_failure_traces : int
        Paths kept of the first this many failed vehicles.
    settle_band : float
        A measured transient that is outside this band (fraction of the initial error) at
        the end is marked ``not_settled``: a metric, not a failure.
    max_clipped_s : float
        Clipping of rotor duties for longer than this [s] counts as "saturated".
    transient_until : float, optional
        End of the window in which the transient is measured [s].
    full_dynamics : bool
        Exact Euler-angle kinematics.
    max_track_error_m : float, optional
        A flight "lost track" if its position error after the transient
        (``steady_max_error_m``; where that is undefined because the transient never
        settled into 5 %, the error at the end, ``final_error_m``) exceeds this [m]. By
        default (None) the larger of 1 m and a quarter of the mission's extent (the longest
        side of the box holding its reference path over the flight,
        :func:`quadcruise.workflows.fly_failures.steady_bound`, the default of ``fly``'s
        ``max_steady_error``): 1 m for the built-in circle, square, step and hover. The
        value used is the field's value after construction, recorded with the spec.
    max_altitude_error_m : float, optional
        A flight is off track (counted as "lost track") too if its altitude error after the
        transient exceeds this [m]. By default (None) :func:`quadcruise.workflows.fly_failures.altitude_bound`
        (half the mission's lowest altitude: 0.5 m for the built-in missions), or
        ``max_track_error_m`` where that is given, as ``fly``'s ``max_steady_error`` bounds both.
    requirements : Requirement, sequence of Requirement, or mapping
        The user's own pass criteria, e.g. ``[Requirement("steady_max_error_m", "<=", 0.2)]``
        or ``{"steady_max_error_m": ("<=", 0.2)}``: a metric of
        :data:`~quadcruise.montecarlo.schema.METRICS`, ``<=``, ``<``, ``>=`` or ``>``, and a
        number (:class:`~quadcruise.montecarlo.requirements.Requirement`); kept as a tuple of
        Requirement. A flight that misses one "failed a requirement"; an undefined value misses it.

    Raises
    ------
    InputError
        For a field that cannot be used (unknown name, batched nominal vehicle, a
        non-positive step, a band outside (0, 1), ...).

    Examples
    --------
    >>> spec = MonteCarloSpec("hover", "nlpd", duration=2.0)
    >>> spec.periods, spec.log_every, spec.trace_every, len(spec.hash())
    (2000, 10, 10, 16)
    """

    mission: Any = "circle"
    controller: Any = "nlpd"
    population: Population = field(default_factory=Population)
    seed: int = 0
    duration: float | None = None
    dt: float = 1e-3
    vehicle: Vehicle = field(default_factory=Vehicle.paper)
    controller_vehicle: Vehicle | None = None
    max_step: float | None = None
    log_dt: float = 0.01
    trace_dt: float = 0.1
    max_traces: int = 200
    max_failure_traces: int = 50
    settle_band: float = 0.05
    max_clipped_s: float = 0.0
    transient_until: float | None = None
    full_dynamics: bool = False
    max_track_error_m: float | None = None
    requirements: tuple[Requirement, ...] = ()
    max_altitude_error_m: float | None = None

    def __post_init__(self) -> None:
        from quadcruise.sim.inputs import time_grid
        from quadcruise.workflows.fly_failures import altitude_bound, steady_bound
        from quadcruise.workflows.fly_inputs import default_duration

        if isinstance(self.mission, str):
            object.__setattr__(self, "mission", mission_from_name(self.mission))
        for name in ("vehicle", "controller_vehicle"):  # a preset's name (Vehicle.preset)
            if isinstance(getattr(self, name), str):
                object.__setattr__(self, name, Vehicle.preset(getattr(self, name)))
        named = self.controller if isinstance(self.controller, str) else None
        object.__setattr__(self, "controller", as_controller(self.controller))
        if not isinstance(self.mission, Mission):
            raise InputError(f"mission must be a name or a Mission, got {type(self.mission).__name__}")
        if not isinstance(self.population, Population):
            raise InputError("population must be a Population")
        if not isinstance(self.vehicle, (Vehicle, RotorVehicle)) or self.plant.count(self.vehicle) is not None:
            raise InputError("the nominal vehicle must be one (unbatched) Vehicle")
        self._check_plant(named)
        if self.controller_vehicle is not None:
            if self.plant.count(self.controller_vehicle) is not None:
                raise InputError("the controller's vehicle must be one (unbatched) Vehicle")
            if not self.population.model_error:
                raise InputError(
                    "a controller_vehicle (the model every controller flies with) contradicts the "
                    "population's model_error=False (each controller knows its own vehicle)"
                )
        object.__setattr__(self, "seed", whole_number(self.seed, "seed"))
        duration = default_duration(self.mission) if self.duration is None else self.duration
        time_grid(float(duration), float(self.dt))  # validates duration and dt
        object.__setattr__(self, "duration", float(duration))
        if self.population.noise is not None:
            self.population.noise.check_fits(self.duration)
        if self.population.sensors is not None:  # each sensor's rate against this dt, before any flight
            from quadcruise.estimation.stage import observation

            observation(self.population.sensors, self.population.estimator, n=1, dt=float(self.dt), seed=0)
        object.__setattr__(self, "dt", float(self.dt))
        for name in ("log_dt", "trace_dt", "settle_band"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise InputError(f"{name} must be a positive number, got {describe(value)}")
        if not 0 < self.settle_band < 1:
            raise InputError(f"settle_band must be a fraction in (0, 1), got {describe(self.settle_band)}")
        if not (math.isfinite(self.max_clipped_s) and self.max_clipped_s >= 0):
            raise InputError(f"max_clipped_s must be >= 0, got {describe(self.max_clipped_s)}")
        for name in ("max_traces", "max_failure_traces"):
            if int(getattr(self, name)) != getattr(self, name) or getattr(self, name) < 0:
                raise InputError(f"{name} must be a whole number >= 0, got {describe(getattr(self, name))}")
        object.__setattr__(self, "requirements", as_requirements(self.requirements, "MonteCarloSpec()"))
        bound = steady_bound(self.mission, self.duration) if self.max_track_error_m is None else self.max_track_error_m
        if isinstance(bound, bool) or not (isinstance(bound, (int, float)) and math.isfinite(bound) and bound > 0):
            raise InputError(f"max_track_error_m must be a positive number [m], got {describe(bound)}")
        zbound = self.max_altitude_error_m
        if zbound is None:
            zbound = altitude_bound(self.mission, self.duration) if self.max_track_error_m is None else bound
        if isinstance(zbound, bool) or not (isinstance(zbound, (int, float)) and math.isfinite(zbound) and zbound > 0):
            raise InputError(f"max_altitude_error_m must be a positive number [m], got {describe(zbound)}")
        object.__setattr__(self, "max_track_error_m", float(bound))
        object.__setattr__(self, "max_altitude_error_m", float(zbound))
        if self.population.needs_drag and self.plant.drag_for_wind:
            from quadcruise.disturbances import with_drag

            object.__setattr__(self, "vehicle", with_drag(self.vehicle, warn=True))

    def _check_plant(self, named: str | None) -> None:
        """The plant's own checks of the sweep, before any work (:class:`~quadcruise.sim.plants.Plant`);
        where the plant designs gains, a controller named gets them designed for the vehicle it
        believes (as :func:`quadcruise.fly` gives them)."""
        from quadcruise.workflows.rotor_fly import designed_controller

        plant, flown = self.plant, (self.vehicle,)
        plant.check_controller_vehicle(flown, self.controller_vehicle, where="")
        plant.refuse("MonteCarloSpec", "full_dynamics", self.full_dynamics, label="field")
        plant.refuse("population", "aero_spread", self.population.aero_spread > 0, label="field")
        plant.refuse_sensors("population field 'sensors'", self.population.sensors)
        with warnings.catch_warnings():  # fly() warns of a vehicle with little left for control
            warnings.simplefilter("ignore")
            plant.check_vehicles(flown)  # before any chunk flies: a nominal that cannot lift
        env = self.population.environment
        if self.population.wind_spread > 0 and env is None:
            from quadcruise.disturbances import ConstantWind, Environment

            env = Environment(wind=ConstantWind())
        plant.check_environment(flown, env)
        if plant.designs_gains and named in CONTROLLERS:
            bandwidth = plant.bandwidths((self.controller_vehicle or self.vehicle,))[0]
            object.__setattr__(self, "controller", designed_controller(named, bandwidth))

    # --- derived ------------------------------------------------------------------------
    @property
    def plant(self):
        """The nominal vehicle's plant (:func:`quadcruise.sim.plants.of`)."""
        from quadcruise.sim import plants

        return plants.of(self.vehicle)

    @property
    def rotor(self) -> bool:
        """True for a rotor-plant sweep (kept for callers of old; ask :attr:`plant`)."""
        return self.plant.name == "rotor"

    @property
    def model_vehicle(self) -> Vehicle | None:
        """The vehicle the controllers compute with: ``controller_vehicle``, else the nominal one,
        or None (each vehicle's own) when the population has no model error."""
        if self.controller_vehicle is not None:
            return self.controller_vehicle
        return self.vehicle if self.population.model_error else None

    @property
    def periods(self) -> int:
        """Control periods per flight."""
        return round(self.duration / self.dt)

    @property
    def log_every(self) -> int:
        """Control periods between logged instants (a divisor of the periods)."""
        return _divisor_at_most(self.periods, max(1, round(self.log_dt / self.dt)))

    @property
    def trace_every(self) -> int:
        """Logged instants between kept path samples."""
        n_log = self.periods // self.log_every
        return _divisor_at_most(n_log, max(1, round(self.trace_dt / (self.dt * self.log_every))))

    def log_bytes(self) -> int:
        """Bytes the engine's log takes per vehicle (states, commands, references).

        Returns
        -------
        int
            Logged instants times (16 + 12 + 11) float64 values of 8 bytes.
        """
        own = self.plant.log_width((self.vehicle,))  # a plant's own state logged too (rotor: 13 + n)
        return (self.periods // self.log_every + 1) * (STATE_SIZE + CMD_SIZE + REF_SIZE + own) * 8

    def to_dict(self) -> dict:
        """Plain values (for quadcruise.json and the hash).

        Returns
        -------
        dict
            Every field (mission, controller, population and vehicle as their
            ``to_dict()``, the requirements as their text, ``"rmse_m<=0.5"``), and
            ``log_every`` and ``trace_every``.
        """
        out = {
            "mission": self.mission.to_dict(),
            "controller": controller_record(self.controller),
            "population": self.population.to_dict(),
            "vehicle": self.vehicle.to_dict(),
            "controller_vehicle": None if self.controller_vehicle is None else self.controller_vehicle.to_dict(),
        }
        for f in dataclasses.fields(self):
            if f.name == "requirements":
                out[f.name] = [r.text for r in self.requirements]
            elif f.name not in out:
                out[f.name] = getattr(self, f.name)
        out["log_every"], out["trace_every"] = self.log_every, self.trace_every
        return out

    def hash(self) -> str:
        """A short hash of :meth:`to_dict`, the version and the code.

        The code is :func:`quadcruise._cache.code_digest`: equal hashes fly equal flights.

        Returns
        -------
        str
            16 hexadecimal digits (of a SHA-256).
        """
        text = dumps({"spec": self.to_dict(), "version": __version__, "code": code_digest()}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

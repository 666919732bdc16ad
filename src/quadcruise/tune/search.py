"""The search: scipy's differential evolution over the searched gains, each generation one
batched flight (:class:`~quadcruise.tune.objective.Objective`).

Differential evolution (Storn and Price, 1997; ``scipy.optimize.differential_evolution``
with ``vectorized=True`` and ``updating="deferred"``) keeps a population of candidates and
replaces each by a mutated cross with others when that is better; a whole generation is
known before any of it is flown, so a generation is one call of the batched engine. The
first generation is a Latin hypercube over the bounds with the given controller's gains in
it (when they lie within the bounds), so a tune never ends worse than where it started.
Everything random comes from ``seed``: the same call gives the same gains.

Examples
--------
>>> res = tune("step", "nlpd", targets={"rise_time_s": 1.5}, gains="position.kp",
...            bounds={"position.kp": (1.0, 10.0)}, duration=6.0, budget=3, popsize=6, seed=1)
>>> res.generations, len(res.history) == 6 * (res.generations + 1)
(3, True)
"""

from __future__ import annotations

import inspect
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.control import as_controller
from quadcruise.errors import InputError, reject_unknown, whole_number
from quadcruise.missions import Mission, as_mission
from quadcruise.model.rotor_vehicle import RotorVehicle
from quadcruise.model.vehicle import Vehicle
from quadcruise.montecarlo.population import Population
from quadcruise.montecarlo.spec import MonteCarloSpec
from quadcruise.sim import plants
from quadcruise.tune.criteria import Requirement, Target, as_minimize, as_requirements, as_targets
from quadcruise.tune.objective import Objective, check_statistic
from quadcruise.tune.result import TuneResult
from quadcruise.tune.space import Bounds, GainSpace
from quadcruise.workflows.rotor_fly import as_vehicle, flight_setup

__all__ = ["tune", "ABS_TOL", "TUNE_OPTIONS"]

ABS_TOL = 1e-3
"""The search also stops when the spread of a generation's costs is below this (scipy's
``atol``): a cost of 1e-3 is a miss of 3 % of a target's tolerance, and targets that can all be
met exactly would otherwise never stop a relative test."""

TUNE_OPTIONS = (
    "gains",
    "bounds",
    "targets",
    "require",
    "minimize",
    "population",
    "samples",
    "objective",
    "seed",
    "budget",
    "popsize",
    "tol",
    "duration",
    "dt",
    "vehicle",
    "controller_vehicle",
    "log_dt",
    "transient_until",
    "progress",
    "command",
)
"""The keywords :func:`tune` takes besides the mission and the controller."""


def tune(
    mission: Mission | str = "step",
    controller: Any = "nlpd",
    *,
    gains: str | Sequence[str] | None = None,
    bounds: Mapping[str, tuple[float, float]] | Bounds | Sequence[Bounds] | None = None,
    targets: Mapping[str, float | tuple[float, float]] | Target | Sequence[Target] = (),
    require: Mapping[str, tuple[str, float]] | Requirement | Sequence[Requirement] = (),
    minimize: str | Sequence[str] = (),
    population: Population | None = None,
    samples: int = 1,
    objective: str | float = "worst",
    seed: int = 0,
    budget: int = 100,
    popsize: int | None = None,
    tol: float = 0.01,
    duration: float | None = None,
    dt: float = 1e-3,
    vehicle: Vehicle | RotorVehicle | str | None = None,
    controller_vehicle: Vehicle | RotorVehicle | str | None = None,
    log_dt: float = 0.01,
    transient_until: float | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    command: str = "",
    **unknown: Any,
) -> TuneResult:
    """Tune a controller's gains, within bounds, towards targets on its metrics.

    Parameters
    ----------
    mission : Mission or str
        The mission flown (a name for its defaults); ``"step"``: 1 m in x at t = 1 s.
    controller : Controller or str
        The controller whose gains are searched (its other gains stay as they are).
    gains : str or sequence of str, optional
        The gains by name, ``"position.kp"`` or ``["position.wn", "position.zeta"]`` (see
        :mod:`quadcruise.tune.space`); the position PD pair by default.
    bounds : mapping, Bounds or sequence of Bounds, optional
        ``{"position.kp": (0.5, 10)}`` or ``[Bounds("position.kp", 0.5, 10)]``; a decade
        either side of each value by default.
    targets : mapping, Target or sequence of Target
        Values to reach: ``{"rise_time_s": 1, "overshoot_pct": (4, 1.5)}`` (a value, or a pair
        value, tolerance) or ``[Target("overshoot_pct", 4, 1.5)]`` (:mod:`quadcruise.tune.criteria`).
    require : mapping, Requirement or sequence of Requirement
        Bounds every candidate must keep: ``{"overshoot_pct": ("<=", 5)}`` or
        ``[Requirement("overshoot_pct", "<=", 5)]``.
    minimize : str or sequence of str
        Metrics to make small, ``"rmse_m"`` or a list.
    population : Population, optional
        How the vehicles differ from the nominal one (mass and inertia spreads, wind, an
        environment, sensor noise; see :class:`~quadcruise.montecarlo.Population`); none by
        default.
    samples : int
        Vehicles of the population each candidate flies (M): a generation is popsize x M
        vehicles in one batch.
    objective : str or float
        Over a candidate's M flights: ``"worst"`` (the largest cost), ``"median"`` or a
        quantile (0.9).
    seed : int
        Seed of the search and of the population: the same seed gives the same gains.
    budget : int
        At most this many generations after the first.
    popsize : int, optional
        Candidates per generation; 15 per searched gain by default.
    tol : float
        Relative spread of the population's costs at which the search stops (scipy's ``tol``;
        it also stops at an absolute spread of :data:`ABS_TOL`).
    duration : float, optional
        Flight time [s]; the mission's default by default.
    dt : float
        Control period [s].
    vehicle : Vehicle, RotorVehicle or str, optional
        The nominal vehicle, or a preset's name; Table I by default. A rotor-plant vehicle
        (:class:`~quadcruise.model.rotor_vehicle.RotorVehicle`) flies the rotor-speed plant,
        each generation one batch of its perturbed copies; a controller given by name starts
        from the gains designed for it (as :func:`quadcruise.fly` gives them).
    controller_vehicle : Vehicle, RotorVehicle or str, optional
        The vehicle the controller believes it flies (its model), of the nominal's plant; the
        nominal ``vehicle`` by default.
    log_dt : float
        Sampling of the log the metrics are measured on [s].
    transient_until : float, optional
        End of the window in which the transient is measured [s].
    progress : callable, optional
        Called as ``progress(generation, budget, text)`` after each generation.
    command : str
        The command line that ran this tune, recorded in the result and its scenario file.
    **unknown : Any
        Refused: an InputError names the options.

    Returns
    -------
    TuneResult
        The gains found, the metrics they reach against the targets, the history.

    Raises
    ------
    ArgumentTypeError
        An argument of the wrong type, before any flight: text targets, requirements or
        bounds (the command line's forms; Python takes the objects or mappings), ...
    InputError
        Bad input, before any flight: an unknown metric or gain, a negative target,
        bounds reversed or empty, a budget of 0, nothing to tune for, ...
    """
    reject_unknown("tune()", unknown, TUNE_OPTIONS)
    budget = whole_number(budget, "budget (generations)", 1)
    samples = whole_number(samples, "samples (vehicles per candidate)", 1)
    seed = whole_number(seed, "seed")
    w = "tune()"  # every argument checked before any flight
    statistic = check_statistic(objective, w)
    targets, requirements = as_targets(targets, w), as_requirements(require, w, "require")
    minimize = as_minimize(minimize, w)
    if not targets and not minimize:
        raise InputError("nothing to tune for: give a target or a metric to minimize")
    checks.number(w, "tol", tol, "nonneg")
    mission = as_mission(mission, w)
    checks.instance(w, "population", population, Population)
    vehicle = as_vehicle(checks.instance(w, "vehicle", vehicle, (Vehicle, RotorVehicle, str)))
    controller_vehicle = as_vehicle(
        checks.instance(w, "controller_vehicle", controller_vehicle, (Vehicle, RotorVehicle, str))
    )
    checks.number(w, "duration", duration, "pos", unit="s", optional=True)
    checks.number(w, "dt", dt, "pos", unit="s")
    checks.number(w, "log_dt", log_dt, "pos", unit="s")
    checks.number(w, "transient_until", transient_until, "pos", unit="s", optional=True)
    checks.callback(w, "progress", progress)
    checks.instance(w, "command", command, str, optional=False)
    if vehicle is not None and plants.of(vehicle).designs_gains and isinstance(controller, str):  # as fly does
        controller = flight_setup(vehicle, controller_vehicle, controller)[1]
    base = as_controller(controller, w)
    space = GainSpace.build(base, gains, bounds, where=w)
    popsize = (
        15 * len(space.gains) if popsize is None else whole_number(popsize, "popsize (candidates per generation)", 5)
    )
    population = population or Population()
    spec = MonteCarloSpec(
        mission,
        base,
        population,
        seed=seed,
        duration=duration,
        dt=dt,
        vehicle=vehicle or Vehicle.paper(),
        controller_vehicle=controller_vehicle,
        log_dt=log_dt,
        transient_until=transient_until,
    )
    from quadcruise.workflows.fly_inputs import check_run_size

    check_run_size(popsize * samples, spec.periods, spec.log_every)  # one generation is one batch: size it first
    obj = Objective(spec, space, targets, requirements, minimize, samples, statistic)
    _search(obj, budget, popsize, tol, seed, progress)
    return TuneResult.from_search(obj, budget=budget, popsize=popsize, command=command)


def _search(obj: Objective, budget: int, popsize: int, tol: float, seed: int, progress) -> np.ndarray:
    """Run differential evolution (the objective keeps every generation); the best gains."""
    from scipy.optimize import differential_evolution
    from scipy.stats import qmc

    g = len(obj.space.gains)
    rng = np.random.default_rng(seed)
    init = qmc.LatinHypercube(d=g, seed=rng).random(popsize)
    start = obj.space.start()
    if start is not None:
        init[0] = start
    t0 = time.perf_counter()

    def callback(xk, convergence=0.0):
        done = len(obj.evaluations) - 1
        ev = obj.evaluations[-1]
        best = min(float(e.cost.min()) for e in obj.evaluations)
        values = obj.space.values(xk)[0]
        gains = ", ".join(f"{n} {v:.4g}" for n, v in zip(obj.space.names, values, strict=False))
        if progress is not None:
            progress(
                done,
                budget,
                f"best cost {best:.4g} ({gains}); {ev.values.shape[0] * obj.samples} flights "
                f"in {ev.wall_s:.2f} s, {time.perf_counter() - t0:.1f} s in all",
            )
        return False

    seeding = {"rng": rng} if "rng" in inspect.signature(differential_evolution).parameters else {"seed": rng}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # scipy: "differential_evolution: the 'workers' ..."
        out = differential_evolution(
            obj,
            [(0.0, 1.0)] * g,
            maxiter=budget,
            init=init,
            tol=tol,
            atol=ABS_TOL,
            polish=False,
            updating="deferred",
            vectorized=True,
            callback=callback,
            **seeding,
        )
    return obj.space.values(out.x)[0]

"""What ``quadcruise montecarlo`` runs once its options are parsed: the population built from
them, the sweep or one case flown, the summary printed. The library does the work
(:func:`quadcruise.montecarlo.montecarlo`); the command itself, its options and its help are
in :mod:`quadcruise.cli.montecarlo`, which re-exports these."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING

import click

from quadcruise.cli.feedback import Bar
from quadcruise.errors import InputError

if TYPE_CHECKING:
    from quadcruise.montecarlo import Case, MonteCarloResult

__all__ = ["montecarlo_command", "parse_noise"]


def parse_noise(text: str | None):
    """Parse a sensor noise spec, ``position=STD,velocity=STD,angle=STD,rate=STD,delay=S``.

    Examples
    --------
    >>> parse_noise("position=0.01,delay=0.002").delay
    0.002
    >>> parse_noise("jitter=1")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: noise spec 'jitter=1': unknown key 'jitter'; keys: position, velocity, angle, ...
    """
    if text is None or str(text).strip().lower() in ("", "none"):
        return None
    from quadcruise.cli.assignments import parse_assignments
    from quadcruise.disturbances import SensorNoise

    names = {
        "position": "position_std",
        "velocity": "velocity_std",
        "angle": "angle_std",
        "rate": "rate_std",
        "delay": "delay",
    }
    return SensorNoise(**parse_assignments(text, "noise spec", keys=names, numbers=True))


def montecarlo_command(
    *,
    mission: str | None = None,
    controller: str | None = None,
    px4_params: str | None = None,
    n: int | None = None,
    seed: int | None = None,
    duration: float | None = None,
    dt: float | None = None,
    wind: str | None = None,
    wind_spread: float | None = None,
    offset: float | None = None,
    mass_spread: float | None = None,
    inertia_spread: float | None = None,
    noise: str | None = None,
    sensors_text: str | None = None,
    estimator_text: str | None = None,
    imu_noise_spread: float | None = None,
    gps_noise_spread: float | None = None,
    thrust_spread: float | None = None,
    bandwidth_spread: float | None = None,
    yaw_arm_spread: float | None = None,
    aero_spread: float | None = None,
    identification: str | None = None,
    distribution: str | None = None,
    model_error: bool | None = None,
    chunk_size: str | int = "auto",
    scheduler: str = "local",
    workers: int | None = None,
    connect_timeout: float = 10.0,
    out: str | None = None,
    force: bool = False,
    resume: bool = True,
    fmt: str = "csv",
    case: int | None = None,
    worst: int = 5,
    quiet: bool = False,
    scenario: str | None = None,
    requirements: tuple[str, ...] = (),
    max_track_error_m: float | None = None,
    vehicle: str | None = None,
    controller_vehicle: str | None = None,
    turbulence: str | None = None,
    log_every: int | None = None,
    echo: Callable[[str], None] = click.echo,
) -> MonteCarloResult | Case:
    """What ``quadcruise montecarlo`` runs: build the population, fly it (or one case), print
    the summary and the worst flights, write ``out``."""
    import numpy as np

    from quadcruise.cli.wind import parse_wind
    from quadcruise.errors import whole_number
    from quadcruise.montecarlo import montecarlo_case
    from quadcruise.montecarlo.output import case_folder, case_text, write_case
    from quadcruise.montecarlo.scenario import parse_requirements, sweep_spec
    from quadcruise.montecarlo.sweep import run_sweep

    whole_number(worst, "--worst")
    requirements = parse_requirements(requirements)  # --require texts, read before any work
    if mission is not None and str(mission).lower().endswith(".toml"):  # a scenario as the mission: as --scenario
        if scenario is not None:
            raise InputError(f"--mission {mission} and --scenario {scenario}: give the scenario once")
        mission, scenario = None, mission
    elif mission is not None and str(mission).lower().endswith(".csv"):
        from quadcruise.cli.objects import mission_from_options

        mission = mission_from_options(mission, (), smooth=False)
    if isinstance(chunk_size, str) and chunk_size != "auto":
        try:
            chunk_size = int(chunk_size)
        except ValueError:
            raise InputError(f"--chunk-size must be a whole number or auto, got {chunk_size!r}") from None
    if log_every is not None:
        whole_number(log_every, "--log-every", minimum=1)
    from quadcruise.cli.vehicle import vehicle_from_option
    from quadcruise.cli.world import environment_from_options, note
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.workflows.scenario import load_scenario

    sc = load_scenario(scenario) if scenario is not None else None
    from quadcruise.cli.onboard import onboard_options

    onboard = onboard_options(
        sensors_text,
        estimator_text,
        {k: getattr(sc, k) for k in ("sensors", "estimator") if sc is not None and getattr(sc, k) is not None},
    )  # checked before any work; given, else the scenario's
    identified = None
    if identification is not None:
        from pathlib import Path

        from quadcruise.montecarlo.identified import Identified

        identified = Identified.read(identification)
        if vehicle is None:  # the vehicle it identified
            vehicle = str(Path(identified.source).parent / "vehicle.toml")

    nominal = vehicle_from_option(vehicle, "--vehicle", sc.vehicle if sc is not None else None)
    believed = vehicle_from_option(
        controller_vehicle,
        "--controller-vehicle",
        sc.controller_vehicle if sc is not None and sc.controller_vehicle else None,
    )
    if px4_params is not None:  # --params: px4 with a file's PX4 parameters, on the vehicle it believes
        from quadcruise.cli.objects import controller_with_params

        world = {"vehicle": nominal, "controller_vehicle": believed}
        if nominal is None and sc is None:
            from quadcruise.model.vehicle import Vehicle as _PaperVehicle

            world["vehicle"] = _PaperVehicle.paper()
        controller = controller_with_params(None, controller, px4_params, (), None, world, sc)
    environment = None
    if wind is not None or turbulence is not None:
        environment = environment_from_options(wind, turbulence, sc.environment if sc is not None else None)
        environment = environment if environment is not None else parse_wind("none")  # given as still air
    with warnings.catch_warnings(record=True) as caught:  # the default drag, said before flying
        warnings.simplefilter("always")
        spec, n = sweep_spec(
            mission=mission,
            controller=controller,
            n=n,
            seed=seed,
            duration=duration,
            dt=dt,
            environment=environment,
            noise=parse_noise(noise),
            scenario=scenario,
            sensors=onboard.get("sensors"),
            estimator=onboard.get("estimator", False if estimator_text is not None else None),
            imu_noise_spread=imu_noise_spread,
            gps_noise_spread=gps_noise_spread,
            mass_spread=mass_spread,
            inertia_spread=inertia_spread,
            thrust_spread=thrust_spread,
            bandwidth_spread=bandwidth_spread,
            offset=offset,
            yaw_arm_spread=yaw_arm_spread,
            aero_spread=aero_spread,
            identified=identified,
            wind_spread=wind_spread,
            distribution=distribution,
            model_error=model_error,
            requirements=requirements,
            max_track_error_m=max_track_error_m,
            vehicle=nominal,
            controller_vehicle=believed,
            log_every=log_every,
        )
    notes = [str(w.message) for w in caught]
    if (
        nominal is not None
        and spec.controller_vehicle is None
        and spec.population.model_error
        and nominal != Vehicle.paper()
    ):
        notes.insert(
            0,
            f"the controllers are told the nominal vehicle ({vehicle}): their only model error is the "
            "spreads'; --controller-vehicle "
            + (spec.plant.default_preset or f"{vehicle.split(',')[0]},m=...")
            + " (or KEY=VALUE,...) gives them another belief",
        )
    if case is None:
        spec.population.check_perturbs(n)
    else:
        if isinstance(case, bool) or not isinstance(case, (int, np.integer)) or not 0 <= case < n:
            raise InputError(f"--case {case} is not one of the {n} flights")
        target = case_folder(out, spec, case, force=force)
        for line in notes:
            note(line)
        found = montecarlo_case(spec, case)
        echo(case_text(found, spec.seed))
        if target is not None:
            write_case(found, target, fmt=fmt, force=True)
            echo(f"wrote the flight to {target}")
        return found
    for line in notes:
        note(line)
    bar = None if quiet else Bar("flying", unit="flight")
    try:
        res = run_sweep(
            spec,
            n,
            chunk_size=chunk_size,
            scheduler=scheduler,
            workers=workers,
            out=out,
            resume=resume,
            force=force,
            fmt=fmt,
            progress=bar,
            connect_timeout=connect_timeout,
        )
    finally:
        if bar is not None:
            bar.close()
    echo(res.summary_text(worst=worst))
    info = res.info
    echo(
        f"{info.get('flown', 0):,} flights flown ({info.get('resumed', 0):,} resumed) in {info.get('wall_s', 0):.1f} s "
        f"on {info.get('scheduler')}" + (f"; wrote {out}" if out is not None else "")
    )
    return res

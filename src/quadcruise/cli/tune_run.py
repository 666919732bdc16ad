"""What ``quadcruise tune`` runs once its options are parsed: the mission, controller and
population from them (or a scenario file), the tune with its progress, the summary printed and
the folder written. The command, its options and its help are in :mod:`quadcruise.cli.tune`."""

from __future__ import annotations

import contextlib
import shlex
from collections.abc import Callable

import click

from quadcruise.cli.tune_px4 import as_px4_parameters, refuse_integer_px4_gains, write_tuned_params
from quadcruise.errors import InputError

__all__ = ["command_line", "tune_command"]


def command_line(mission: str, options: dict) -> str:
    """The command line that runs this tune again, from its options.

    Examples
    --------
    >>> command_line("step", {"targets": ("rise_time_s=1",), "seed": 1, "quiet": True})
    'quadcruise tune step --target rise_time_s=1 --seed 1'
    """
    flags = {"mission_params": "-m", "controller_params": "-c", "targets": "--target", "px4_params": "--params"}
    skip = {"out", "force", "quiet"}
    words = ["quadcruise", "tune", mission]
    for name, value in options.items():
        if name in skip or value is None or value is False or value == ():
            continue
        flag = flags.get(name, "--" + name.replace("_", "-"))
        for item in value if isinstance(value, tuple) else (value,):
            words += [flag] if item is True else [flag, str(item)]
    return " ".join(shlex.quote(w) for w in words)


DEFAULTS = {
    "controller": None,
    "samples": 1,
    "objective": "worst",
    "mass_spread": 0.0,
    "inertia_spread": 0.0,
    "wind_spread": 0.0,
    "seed": 0,
    "budget": 100,
}
"""Options left out of the recorded command line when they have these values."""


def tune_command(
    *,
    mission: str,
    mission_params: tuple = (),
    controller: str | None = None,
    controller_params: tuple = (),
    px4_params: str | None = None,
    gains: str | None = None,
    bounds: tuple = (),
    targets: tuple = (),
    require: tuple = (),
    minimize: tuple = (),
    samples: int = 1,
    objective: str = "worst",
    mass_spread: float = 0.0,
    inertia_spread: float = 0.0,
    wind: str | None = None,
    wind_spread: float = 0.0,
    noise: str | None = None,
    sensors: str | None = None,
    estimator: str | None = None,
    seed: int = 0,
    budget: int = 100,
    popsize: int | None = None,
    duration: float | None = None,
    dt: float | None = None,
    out: str | None = None,
    force: bool = False,
    quiet: bool = False,
    vehicle: str | None = None,
    controller_vehicle: str | None = None,
    turbulence: str | None = None,
    log_every: int | None = None,
    echo: Callable[..., None] = click.echo,
):
    """What ``quadcruise tune`` runs: build the tune, run it, print its progress and summary, write ``out``."""
    from quadcruise.cli.common import controller_from_options, mission_from_options
    from quadcruise.cli.montecarlo_run import parse_noise
    from quadcruise.cli.objects import controller_for_vehicle, controller_with_params
    from quadcruise.io.files import check_output_dir
    from quadcruise.montecarlo.population import Population
    from quadcruise.tune import tune

    given = {
        k: v
        for k, v in dict(
            mission_params=mission_params,
            controller=controller,
            controller_params=controller_params,
            gains=gains,
            bounds=bounds,
            targets=targets,
            require=require,
            minimize=minimize,
            samples=samples,
            objective=objective,
            mass_spread=mass_spread,
            inertia_spread=inertia_spread,
            wind=wind,
            wind_spread=wind_spread,
            noise=noise,
            sensors=sensors,
            estimator=estimator,
            seed=seed,
            budget=budget,
            popsize=popsize,
            duration=duration,
            dt=dt,
            vehicle=vehicle,
            controller_vehicle=controller_vehicle,
            turbulence=turbulence,
            log_every=log_every,
        ).items()
        if DEFAULTS.get(k, object()) != v
    }
    from quadcruise.cli.criteria import (
        parse_bounds,
        parse_gains,
        parse_minimize,
        parse_objective,
        parse_requirements,
        parse_targets,
    )
    from quadcruise.cli.world import flight_world
    from quadcruise.errors import whole_number
    from quadcruise.sim import plants

    if log_every is not None:
        whole_number(log_every, "--log-every", minimum=1)
    wanted = dict(  # the texts read into the library's objects, before any work
        targets=parse_targets(targets),
        require=parse_requirements(require),
        minimize=parse_minimize(minimize),
        objective=parse_objective(objective),
        bounds=parse_bounds(bounds),
    )
    if not wanted["targets"] and not wanted["minimize"]:
        raise InputError("nothing to tune for: give a target (--target METRIC=VALUE) or a metric to --minimize")
    if out is not None:
        check_output_dir(out, force, inputs=(mission, vehicle, controller_vehicle, wind, turbulence))
    kwargs: dict = {"duration": duration, "dt": 1e-3 if dt is None else dt}
    from quadcruise.cli.onboard import onboard_options

    sensors_text, estimator_text = sensors, estimator
    onboard = onboard_options(sensors_text, estimator_text, {})  # read before any work; the scenario's below
    sensors = parse_noise(noise)  # the white noise on the truth; the sensor models are onboard's
    sc = None
    if mission.lower().endswith(".toml"):
        from quadcruise.workflows.scenario import load_scenario

        if mission_params:
            raise InputError("-m/--mission-param does not apply to a scenario file: change its [mission] table")
        sc = load_scenario(mission)
        the_mission = sc.mission or "circle"
        the_controller = controller_from_options(controller, controller_params, None, base=sc.controller)
        kwargs.update(duration=sc.duration if duration is None else duration, dt=sc.dt if dt is None else dt)
        sensors = sensors if sensors is not None else sc.sensor_noise
        scenario_onboard = {k: getattr(sc, k) for k in ("sensors", "estimator") if getattr(sc, k) is not None}
        onboard = onboard_options(sensors_text, estimator_text, scenario_onboard)  # the options win
    else:
        the_mission = mission_from_options(mission, mission_params, False)
        the_controller = controller_from_options(
            controller or ("px4" if px4_params else None), () if px4_params else controller_params, None
        )
    world, notes = flight_world(
        vehicle=vehicle, controller_vehicle=controller_vehicle, wind=wind, turbulence=turbulence, scenario=sc
    )
    plant = plants.of(world["vehicle"])
    if px4_params:
        the_controller = controller_with_params(
            the_controller, controller, px4_params, controller_params, None, world, sc
        )
    else:
        the_controller = controller_for_vehicle(the_controller, controller, controller_params, None, world, sc)
    the_controller = as_px4_parameters(the_controller, world, bool(px4_params))
    wanted["gains"] = parse_gains(gains, the_controller)
    refuse_integer_px4_gains(wanted["gains"], the_controller)
    environment = world["environment"]
    if wind_spread > 0 and plant.drag_for_wind and not any("wind acts only through drag" in line for line in notes):
        from quadcruise.disturbances import default_drag_text, with_drag

        if world["vehicle"].drag_linear == 0 and world["vehicle"].drag_quadratic == 0:
            world["vehicle"] = with_drag(world["vehicle"])
            notes.append(default_drag_text())
    kwargs.update(vehicle=world["vehicle"], controller_vehicle=world["controller_vehicle"])
    if log_every is not None:
        kwargs["log_dt"] = log_every * kwargs["dt"]
    population = Population(
        mass_spread=mass_spread,
        inertia_spread=inertia_spread,
        wind_spread=wind_spread,
        environment=environment if environment is not None and environment.parts else None,
        noise=sensors,
        sensors=onboard.get("sensors"),
        estimator=onboard.get("estimator"),
    )
    from quadcruise.cli.feedback import Bar

    with contextlib.nullcontext() if quiet else Bar("tuning", unit="generation") as progress:
        result = tune(
            the_mission,
            the_controller,
            **wanted,
            population=population,
            samples=samples,
            seed=seed,
            budget=budget,
            popsize=popsize,
            progress=progress,
            command=command_line(mission, given),
            **kwargs,
        )
    for line in notes:  # after tune() has checked its own input: an error stays one line
        echo(f"note: {line}", err=True)
    echo(result.summary_text())
    if out is not None:
        result.write(out, force=True)
        echo(f"wrote {out}: `quadcruise fly {out}/scenario.toml` flies the tuned gains")
        write_tuned_params(result, out, command_line(mission, given), world, echo)
    return result

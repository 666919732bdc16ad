"""``quadcruise fly``: one mission flown by one controller; its metrics printed, its folder,
report and animation written on request."""

from __future__ import annotations

import sys

import click

from quadcruise.cli.common import (
    FORCE_OPTION,
    FORMAT_OPTION,
    REPORT_OPTION,
    RISE_OPTION,
    SECONDS,
    SETTLE_BAND_OPTION,
    distinct_outputs,
    friendly,
    metric_options,
    needs_out,
    writable,
    writable_with,
)
from quadcruise.cli.fly_run import fly_and_report
from quadcruise.cli.objects import PARAMS_OPTION, controller_for_vehicle, controller_with_params, flight_from_options
from quadcruise.cli.onboard import onboard_options
from quadcruise.cli.world import WORLD_OPTIONS, flight_world

__all__ = ["fly"]


@click.command("fly")
@click.argument("mission", metavar="MISSION")
@click.option("--controller", help="Controller name (default nlpd, or the scenario's).")
@click.option("--duration", type=SECONDS, help="Flight time [s] (default: one lap, or 10 s after a step).")
@click.option("--dt", type=SECONDS, help="Control period [s] (default 0.001).")
@click.option("--max-step", type=SECONDS, help="Longest RK4 substep [s] (default: dt).")
@click.option(
    "-m",
    "--mission-param",
    "mission_params",
    multiple=True,
    metavar="KEY=VALUE",
    help="Mission parameter, e.g. -m radius=3 -m period=30 (repeatable).",
)
@click.option(
    "-c",
    "--controller-param",
    "controller_params",
    multiple=True,
    metavar="KEY=VALUE",
    help="Controller parameter, e.g. -c max_tilt=0.5 (repeatable).",
)
@PARAMS_OPTION
@click.option(
    "--poles",
    "position_poles",
    metavar="P1,P2",
    help="Closed-loop poles of the x/y loops [rad/s], e.g. -0.7,-4.3 (the paper's).",
)
@click.option(
    "--out", "out", type=click.Path(file_okay=False), callback=writable, help="Folder for traces, figure and metrics."
)
@FORMAT_OPTION
@FORCE_OPTION
@click.option("--smooth", is_flag=True, help="Fly a waypoint file as a minimum-snap path instead of legs.")
@REPORT_OPTION
@click.option(
    "--animate",
    type=click.Path(dir_okay=False),
    metavar="PATH.gif",
    callback=writable,
    help="Also write an animation of the flight (.gif; .mp4 needs ffmpeg).",
)
@click.option(
    "--ulog",
    type=click.Path(dir_okay=False),
    metavar="PATH.ulg",
    callback=writable_with(".ulg"),
    help="Also write the flight as a PX4 log (ULog); a batch as PATH-0.ulg, PATH-1.ulg, ...",
)
@click.option(
    "--sensors",
    "sensors_text",
    metavar="NAME[=PRESET],...",
    help="Sensor models the vehicle carries: imu, gps, baro, mag (preset typical, or e.g. imu=bmi088); "
    "the controller still sees the truth unless --estimator is given.",
)
@click.option(
    "--estimator",
    "estimator_text",
    metavar="NAME",
    help="The estimator between the sensors and the controller: ekf (needs imu and gps), or none.",
)
@WORLD_OPTIONS
@RISE_OPTION
@SETTLE_BAND_OPTION
@friendly
def fly(
    mission,
    controller,
    duration,
    dt,
    max_step,
    mission_params,
    controller_params,
    px4_params,
    position_poles,
    out,
    fmt,
    force,
    smooth,
    report,
    animate,
    ulog,
    sensors_text,
    estimator_text,
    vehicle,
    controller_vehicle,
    wind,
    turbulence,
    log_every,
    seed,
    rise,
    settle_bands,
):
    """Fly a MISSION with a controller on the paper's vehicle (or --vehicle) and print its metrics.

    MISSION is circle, square, step, hover, sysid (doublets for `identify`), a waypoint CSV
    (columns x,y,z and optional yaw and t or speed), flown as constant-speed legs or, with
    --smooth, a minimum-snap path, or a TOML scenario file describing the whole run (options given here override it).
    With --out, also write the traces, a figure of the flight, the metrics and the
    configuration (quadcruise.json) to that folder, atomically.

    \f
    Parameters
    ----------
    mission : str
        ``MISSION``: a mission name (:func:`quadcruise.missions.mission_from_name`), the path of
        a waypoint CSV, or the path of a TOML scenario file (ending in ``.toml``).
    controller : str or None
        ``--controller``: the controller's name (:func:`quadcruise.control.controller_from_name`);
        None: the scenario's controller, else ``nlpd``. ``controller_params`` and
        ``position_poles`` change the scenario's controller when no name is given.
    duration : float or None
        ``--duration``: flight time [s]; None: the scenario's, else the mission's (one lap, or
        10 s after a step).
    dt : float or None
        ``--dt``: control period [s]; None: the scenario's, else 0.001 s.
    max_step : float or None
        ``--max-step``: longest RK4 substep [s]; None: the scenario's, else ``dt``.
    mission_params : tuple of str
        ``-m``/``--mission-param``: the mission's parameters, each ``KEY=VALUE`` (with a
        scenario, they change its mission).
    controller_params : tuple of str
        ``-c``/``--controller-param``: the controller's parameters, each ``KEY=VALUE``.
    px4_params : str or None
        ``--params``: a PX4 log or QGroundControl ``.params`` file whose PX4 parameters the px4
        controller flies (:func:`~quadcruise.cli.objects.controller_with_params`).
    position_poles : str or None
        ``--poles``: comma-separated closed-loop poles of the x/y loops [rad/s], e.g.
        ``-0.7,-4.3``; their PD gains replace the controller's position gains. None: not given.
    out : str or None
        ``--out``: folder to write the traces, the figure, the metrics and ``quadcruise.json``
        to; None: print only.
    fmt : {"csv", "parquet"}
        ``--format``: format of the traces.
    force : bool
        ``--force``: replace a non-empty ``out`` folder that quadcruise did not write.
    smooth : bool
        ``--smooth``: fly a waypoint CSV as a minimum-snap path instead of constant-speed legs.
    report : str or None
        ``--report``: path of a self-contained HTML report to write as well; None: no report.
    animate : str or None
        ``--animate``: path of an animation of the flight to write as well (``.gif``, or
        ``.mp4`` with ffmpeg); None: no animation.
    ulog : str or None
        ``--ulog``: path of a PX4 log (``.ulg``) of the flight to write as well
        (:meth:`~quadcruise.SimResult.to_ulog`); a batch of N vehicles is written as N files,
        ``PATH-0.ulg`` ... (:func:`~quadcruise.cli.fly_run.ulog_paths`). None: no log.
    sensors_text : str or None
        ``--sensors``: the sensor models, ``NAME[=PRESET],...``
        (:func:`~quadcruise.cli.onboard.parse_sensors`); None: the scenario's, else none.
    estimator_text : str or None
        ``--estimator``: ``ekf`` or ``none``; None: the scenario's, else none.
    vehicle, controller_vehicle : str or None
        ``--vehicle``, ``--controller-vehicle``: the flown vehicle and the controller's model of
        it (:func:`~quadcruise.cli.objects.vehicle_from_option`); None: the scenario's, else
        Table I and the flown vehicle.
    wind, turbulence : str or None
        ``--wind``: a :func:`~quadcruise.cli.wind.parse_wind` spec replacing the scenario's
        disturbances; ``--turbulence``: Dryden turbulence added
        (:func:`~quadcruise.cli.objects.environment_from_options`).
    log_every : int or None
        ``--log-every``: log every this many control periods; None: the scenario's, else 1.
    seed : int or None
        ``--seed``: seed of the turbulence and the sensor noise; None: the scenario's, else 0.
    rise : {"10-90", "0-100"}
        ``--rise``: the rise-time convention (% of the step).
    settle_bands : tuple of float
        ``--settle-band``: the settling bands (fractions of the step), given once or twice.
    """
    from quadcruise.errors import whole_number

    needs_out(out, force=force, format=fmt != "csv")
    distinct_outputs(out, report=report, animate=animate, ulog=ulog)
    conventions = metric_options(rise, settle_bands)
    if seed is not None:
        whole_number(seed, "--seed")
    if log_every is not None:
        whole_number(log_every, "--log-every", minimum=1)
    overrides = {
        k: v
        for k, v in (
            ("duration", duration),
            ("dt", dt),
            ("max_step", max_step),
            ("seed", seed),
            ("log_every", log_every),
        )
        if v is not None
    }
    world = {"vehicle": vehicle, "controller_vehicle": controller_vehicle, "wind": wind, "turbulence": turbulence}
    given = (
        [f"--{k.replace('_', '-')} {v}" for k, v in {**overrides, **world}.items() if v is not None]
        + [f"-m {p}" for p in mission_params]
        + [f"-c {p}" for p in controller_params]
        + ([f"--controller {controller}"] if controller else [])
        + ([f"--poles {position_poles}"] if position_poles else [])
        + ([f"--params {px4_params}"] if px4_params else [])
        + ([f"--sensors {sensors_text}"] if sensors_text else [])
        + ([f"--estimator {estimator_text}"] if estimator_text else [])
    )
    the_mission, the_controller, kwargs, scenario = flight_from_options(
        mission,
        "px4" if px4_params and controller is None else controller,
        mission_params,
        () if px4_params else controller_params,
        None if px4_params else position_poles,
        smooth,
    )
    flown, notes = flight_world(**world, scenario=scenario)
    if px4_params:
        the_controller = controller_with_params(
            the_controller, controller, px4_params, controller_params, position_poles, flown, scenario
        )
    else:
        the_controller = controller_for_vehicle(
            the_controller, controller, controller_params, position_poles, flown, scenario
        )
    kwargs = {
        **{k: v for k, v in kwargs.items() if k not in flown},
        **overrides,
        **{k: v for k, v in flown.items() if v is not None},
    }
    kwargs = onboard_options(sensors_text, estimator_text, kwargs)
    result = fly_and_report(
        the_mission,
        the_controller,
        kwargs,
        out,
        fmt,
        force,
        report,
        animate,
        given,
        scenario,
        conventions,
        notes,
        ulog,
        inputs=(mission, vehicle, controller_vehicle, wind, turbulence),
    )
    if not result.ok.all():
        sys.exit(1)  # a vehicle did not fly its mission: diverged, lost track, out of bounds

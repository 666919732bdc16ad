"""The ``quadcruise`` command: a thin layer that parses options and calls the library.

Bad input prints one line, ``error: ...``, and exits with status 2.
"""

from __future__ import annotations

import functools
import gc
import sys
import warnings

import click

from quadcruise._version import __version__
from quadcruise.errors import InputError
from quadcruise.io.files import check_output_dir

# options several commands share
FORMAT_OPTION = click.option("--format", "fmt", type=click.Choice(["csv", "parquet"]), default="csv",
                             show_default=True, help="Format of the traces.")
FORCE_OPTION = click.option("--force", is_flag=True, help="Replace a non-empty --out folder not written by quadcruise.")
REPORT_OPTION = click.option("--report", type=click.Path(dir_okay=False), metavar="PATH.html",
                             help="Also write a self-contained HTML report (tables, figures, interactive 3-D "
                                  "view, configuration).")


def _friendly(func):
    """Turn InputError into a one-line message with exit status 2; show warnings plainly."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                return func(*args, **kwargs)
            except InputError as exc:
                click.echo(f"error: {exc}", err=True)
                sys.exit(2)
            finally:
                for w in caught:
                    click.echo(f"warning: {w.message}", err=True)

    return wrapper


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="quadcruise")
def main() -> None:
    """Quadrotor cruise control: simulate, design and fly controllers, measure them."""


@main.command()
@click.argument("pwm_csv", metavar="PWM.csv")
@click.option("-o", "--out", "out", required=True, metavar="STATES.csv",
              help="Where to write the states (t,x,y,z,vx,vy,vz,phi,theta,psi,p,q,r,F1..F4).")
@click.option("--max-step", default=1e-3, show_default=True, type=float,
              help="Longest RK4 substep [s].")
@_friendly
def replay(pwm_csv: str, out: str, max_step: float) -> None:
    """Replay PWM duties open loop (columns t,u1,u2,u3,u4) and write the states.

    Each row's duties hold until the next row's time. The vehicle (the paper's Table I)
    starts at rest at the origin with each rotor at the thrust of the first row.
    """
    from quadcruise.workflows.replay import read_duty_csv, write_states_csv
    from quadcruise.workflows.replay import replay as run_replay

    schedule = read_duty_csv(pwm_csv)
    result = run_replay(schedule, max_step=max_step)
    if not result.ok[0]:
        click.echo(f"warning: the flight stopped early: {result.status_text(0)}", err=True)
    write_states_csv(result, out)
    click.echo(f"wrote {len(result.t)} states to {out} "
               f"(t = {result.t[0]:g} .. {result.t[-1]:g} s, final z = {result.final_state[0, 2]:.4f} m)")


def _assignments(items: tuple[str, ...], option: str) -> dict:
    """Parse KEY=VALUE pairs (:func:`quadcruise.fields.parse_assignments`): numbers,
    comma-separated numbers, true/false, or words."""
    from quadcruise.fields import parse_assignments

    return parse_assignments(items, option)


def _poles(text: str | None, option: str):
    if text is None:
        return None
    from quadcruise.control.design import parse_pole

    try:
        return [parse_pole(p) for p in text.split(",")]
    except ValueError:
        raise InputError(f"{option} {text!r}: expected comma-separated poles, e.g. -0.7,-4.3") from None


def _metrics_table(frame) -> str:
    """The metrics of each vehicle as aligned text (see :mod:`quadcruise.metrics.tables`)."""
    from quadcruise.metrics.tables import metrics_text

    return metrics_text(frame.drop(columns=["vehicle"]), [f"vehicle {c}" for c in frame["vehicle"]])


@main.command()
@click.argument("mission", metavar="MISSION")
@click.option("--controller", default="nlpd", show_default=True, help="Controller name.")
@click.option("--duration", type=float, help="Flight time [s] (default: one lap, or 10 s after a step).")
@click.option("--dt", type=float, help="Control period [s] (default 0.001).")
@click.option("--max-step", type=float, help="Longest RK4 substep [s] (default: dt).")
@click.option("-m", "--mission-param", "mission_params", multiple=True, metavar="KEY=VALUE",
              help="Mission parameter, e.g. -m radius=3 -m period=30 (repeatable).")
@click.option("-c", "--controller-param", "controller_params", multiple=True, metavar="KEY=VALUE",
              help="Controller parameter, e.g. -c max_tilt=0.5 (repeatable).")
@click.option("--poles", "position_poles", metavar="P1,P2",
              help="Closed-loop poles of the x/y loops [rad/s], e.g. -0.7,-4.3 (the paper's).")
@click.option("--out", "out", type=click.Path(file_okay=False), help="Folder for traces, figure and metrics.")
@FORMAT_OPTION
@FORCE_OPTION
@click.option("--smooth", is_flag=True, help="Fly a waypoint file as a minimum-snap path instead of legs.")
@REPORT_OPTION
@click.option("--animate", type=click.Path(dir_okay=False), metavar="PATH.gif",
              help="Also write an animation of the flight (.gif; .mp4 needs ffmpeg).")
@_friendly
def fly(mission, controller, duration, dt, max_step, mission_params, controller_params, position_poles,
        out, fmt, force, smooth, report, animate):
    """Fly a MISSION with a controller on the paper's vehicle and print its metrics.

    MISSION is circle, square, step, hover, a waypoint CSV (columns x,y,z and optional yaw
    and t or speed), flown as constant-speed legs or, with --smooth, a minimum-snap path, or
    a TOML scenario file describing the whole run (options given here override it).
    With --out, also write the traces, a figure of the flight, the metrics and the
    configuration (quadcruise.json) to that folder, atomically.
    """
    from quadcruise.missions import mission_from_name

    overrides = {k: v for k, v in (("duration", duration), ("dt", dt), ("max_step", max_step)) if v is not None}
    if mission.lower().endswith(".toml"):
        from quadcruise.workflows.scenario import load_scenario

        scenario = load_scenario(mission)
        the_mission, the_controller = scenario.mission or mission_from_name("circle"), scenario.controller
        if the_controller is None or controller_params or position_poles or controller != "nlpd":
            the_controller = _controller_from_options(controller, controller_params, position_poles)
        kwargs = {**scenario.fly_kwargs(), **overrides}
    else:
        the_mission = _mission(mission, mission_params, smooth)
        the_controller = _controller_from_options(controller, controller_params, position_poles)
        kwargs = overrides
    _fly_and_report(the_mission, the_controller, kwargs, out, fmt, force, report, animate)


def _controller_from_options(name: str, params: tuple[str, ...], poles_text: str | None):
    from quadcruise.control import controller_from_name
    from quadcruise.control.design import pd_from_poles

    cparams = _assignments(params, "--controller-param")
    poles = _poles(poles_text, "--poles")
    if poles is not None:
        cparams["position"] = pd_from_poles(poles)
    return controller_from_name(name, **cparams)


def _fly_and_report(mission, controller, kwargs: dict, out, fmt, force, report=None, animate=None) -> None:
    from quadcruise.workflows.fly import fly as run_fly
    from quadcruise.workflows.fly import write_flight

    if animate is not None and not animate.lower().endswith((".gif", ".mp4")):
        raise InputError(f"--animate {animate}: the animation must be a .gif (or .mp4, with ffmpeg)")
    if out is not None:
        check_output_dir(out, force)
    result = run_fly(mission, controller, **kwargs)
    metrics = result.metrics()
    click.echo(f"{controller.name} on {mission.name}: {result.t[-1]:g} s at dt = {result.meta['dt_s']:g} s")
    click.echo(_metrics_table(metrics))
    if out is not None:
        write_flight(result, out, fmt, metrics=metrics)
        click.echo(f"wrote traces, figure and metrics to {out}")
    if report is not None:
        from quadcruise.report.html import flight_report, write_html_report

        write_html_report(report, **flight_report(result, metrics=metrics))
        click.echo(f"wrote report {report}")
    if animate is not None:
        from quadcruise.plots.animate import animate_flight

        animate_flight(result, animate)
        click.echo(f"wrote animation {animate}")


@main.command()
@click.option("--out", "out", default="quadcruise-out", show_default=True, type=click.Path(file_okay=False),
              help="Folder for metrics.json, figures, traces and report.md.")
@FORMAT_OPTION
@FORCE_OPTION
@REPORT_OPTION
@click.option("--scenario", type=click.Path(dir_okay=False), metavar="FILE.toml",
              help="Reproduce with a scenario's vehicle and control period (e.g. the 1.4 kg Qball-X4).")
@_friendly
def reproduce(out, fmt, force, report, scenario):
    """Reproduce the paper: both controllers on the circle, square and step, beside its numbers.

    Writes OUT/metrics.json, one figure per paper figure, the traces and OUT/report.md,
    which explains every difference from the paper. Nothing is left half-written.
    """
    import time

    from quadcruise.workflows.reproduce import reproduce as run_reproduce
    from quadcruise.workflows.reproduce import results_table, write_reproduction

    start = time.perf_counter()
    check_output_dir(out, force)

    def flown(done, total, label):
        click.echo(f"[{done}/{total}] flew {label}", err=True)

    settings = {}
    if scenario is not None:
        from quadcruise.workflows.scenario import load_scenario

        sc = load_scenario(scenario)
        settings = {"vehicle": sc.vehicle, "dt": sc.dt}
    rep = run_reproduce(progress=flown, **settings)
    click.echo(results_table(rep))
    write_reproduction(rep, out, force=force, fmt=fmt, progress=lambda name: click.echo(f"drew {name}", err=True))
    if report is not None:
        from pathlib import Path

        from quadcruise.report.html import reproduction_report, write_html_report
        from quadcruise.workflows.reproduce import FIGURES

        figures = {cap: Path(out) / name for name, cap in FIGURES.items() if (Path(out) / name).is_file()}
        write_html_report(report, **reproduction_report(rep, figures))
        click.echo(f"wrote report {report}")
    click.echo(f"wrote {out}/report.md, metrics.json, figures and traces in {time.perf_counter() - start:.1f} s")


@main.command()
@click.argument("mission", metavar="MISSION")
@click.option("--controllers", default="nlpd,gonzalez,se3,cascade", show_default=True,
              help="Comma-separated controller names.")
@click.option("--duration", type=float, help="Flight time [s] (default: the mission's).")
@click.option("--dt", type=float, default=1e-3, show_default=True, help="Control period [s].")
@click.option("-m", "--mission-param", "mission_params", multiple=True, metavar="KEY=VALUE",
              help="Mission parameter (repeatable).")
@click.option("--out", type=click.Path(file_okay=False), help="Folder for metrics.csv and comparison.png.")
@FORCE_OPTION
@click.option("--population", type=int, metavar="N",
              help="Also fly every controller on the same Monte Carlo population of N vehicles.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the population.")
@click.option("--mass-spread", type=float, default=0.1, show_default=True, help="Relative std of the mass.")
@click.option("--wind", metavar="SPEC", help="Wind of the population, e.g. dryden:moderate@10.")
@REPORT_OPTION
@_friendly
def compare(mission, controllers, duration, dt, mission_params, out, force, population, seed, mass_spread, wind,
            report):
    """Fly MISSION (a name or a waypoint CSV) with several controllers; one table, one figure."""
    from quadcruise.workflows.compare import compare as run_compare

    if out is not None:
        check_output_dir(out, force)
    cmp_mission = _mission(mission, mission_params, smooth=False)
    cmp = run_compare(cmp_mission, controllers, duration=duration, dt=dt)
    click.echo(cmp.text())
    if population is not None:
        from quadcruise.disturbances.environment import parse_wind
        from quadcruise.montecarlo.api import Population
        from quadcruise.montecarlo.compare import compare_population

        env = parse_wind(wind) if wind else None
        pop = Population(mass_spread=mass_spread, environment=env if env is not None and env.parts else None)
        table = compare_population(cmp_mission, controllers, pop, population, seed, duration=duration, dt=dt,
                                   scheduler="none")
        click.echo(f"\nthe same {population} perturbed vehicles (seed {seed}, mass spread {mass_spread:g}"
                   + (f", wind {wind}" if wind else "") + "):")
        click.echo(table.to_string(float_format=lambda v: f"{v:.4g}"))
    if out is not None:
        cmp.write(out, force=force)
        click.echo(f"wrote metrics.csv and comparison.png to {out}")
    if report is not None:
        from quadcruise.report.html import comparison_report, write_html_report

        write_html_report(report, **comparison_report(cmp))
        click.echo(f"wrote report {report}")


@main.command()
@click.option("--controller", default="nlpd", show_default=True, help="Controller name.")
@click.option("-c", "--controller-param", "controller_params", multiple=True, metavar="KEY=VALUE",
              help="Controller parameter (repeatable).")
@click.option("--poles", "position_poles", metavar="P1,P2", help="Closed-loop poles of the x/y loops [rad/s].")
@click.option("--dt", type=float, default=1e-3, show_default=True, help="Control period [s].")
@click.option("--out", type=click.Path(file_okay=False), help="Folder for analysis.json and Bode plots.")
@FORCE_OPTION
@_friendly
def analyze(controller, controller_params, position_poles, dt, out, force):
    """Linearise the closed loop about hover: poles, damping, margins of each loop, Bode plots."""
    from pathlib import Path

    from quadcruise.io.files import MARKER, atomic_dir
    from quadcruise.io.plainjson import dumps
    from quadcruise.plots.flight import save_figure
    from quadcruise.workflows.analysis import bode, linearize, report, summary, to_json

    the_controller = _controller_from_options(controller, controller_params, position_poles)
    if out is not None:
        check_output_dir(out, force)
    lin = linearize(the_controller, dt=dt)
    rep = report(the_controller, lin=lin)
    click.echo(summary(rep))
    if out is not None:
        with atomic_dir(out) as tmp:
            tmp = Path(tmp)
            (tmp / "analysis.json").write_text(to_json(rep) + "\n")
            save_figure(bode(lin, loops=True), tmp / "bode.png")
            save_figure(bode(lin, loops=True, at="output"), tmp / "bode_output.png")
            (tmp / MARKER).write_text(dumps({"workflow": "analyze", "controller": the_controller,
                                             "dt_s": dt, "version": __version__}) + "\n")
        click.echo(f"wrote analysis.json and Bode plots to {out}")


@main.command()
@click.option("--mission", default="circle", show_default=True, help="Mission name.")
@click.option("--controller", default="nlpd", show_default=True, help="Controller name.")
@click.option("-n", "--n", "n", type=int, show_default="1000", help="Number of flights.")
@click.option("--seed", type=int, show_default="0", help="Seed of every random draw.")
@click.option("--duration", type=float, help="Flight time [s] (default: the mission's).")
@click.option("--dt", type=float, help="Control period [s] (default 0.001, or the scenario's).")
@click.option("--wind", metavar="SPEC", help="Wind: constant:WX,WY,WZ | gust:AX,AY,AZ@START+DURATION | "
              "dryden:light|moderate|severe@ALTITUDE (comma-separable).")
@click.option("--wind-spread", type=float, show_default="0",
              help="Std of a random steady horizontal wind per flight [m/s].")
@click.option("--mass-spread", type=float, show_default="0", help="Relative std of the mass.")
@click.option("--inertia-spread", type=float, show_default="0", help="Relative std of each inertia.")
@click.option("--thrust-spread", type=float, show_default="0", help="Relative std of K.")
@click.option("--bandwidth-spread", type=float, show_default="0",
              help="Relative std of the actuator bandwidth.")
@click.option("--yaw-arm-spread", type=float, show_default="0", help="Relative std of d.")
@click.option("--distribution", type=click.Choice(["normal", "uniform"]), show_default="normal")
@click.option("--offset", type=float, show_default="0", help="Std of the start position [m].")
@click.option("--noise", metavar="position=STD,velocity=STD,angle=STD,rate=STD,delay=S",
              help="Sensor noise and delay.")
@click.option("--model-error/--no-model-error", default=None, show_default="model-error",
              help="The controller flies with the nominal model, not each vehicle's own.")
@click.option("--chunk-size", default="auto", show_default=True, help="Flights per task.")
@click.option("--scheduler", default="local", show_default=True,
              help="local (a Dask cluster of processes here), none (in this process) or a Dask address.")
@click.option("--workers", type=int, help="Workers of the local cluster.")
@click.option("--connect-timeout", type=float, default=10.0, show_default=True, help="[s] for --scheduler ADDRESS.")
@click.option("--out", type=click.Path(file_okay=False), help="Folder: chunks stream here, so a rerun resumes.")
@click.option("--force", is_flag=True, help="Replace a folder holding something else.")
@click.option("--resume/--no-resume", default=True, show_default=True)
@click.option("--format", "fmt", type=click.Choice(["csv", "parquet"]), default="csv", show_default=True)
@click.option("--case", type=int, help="Fly flight I alone (replays a worst case exactly).")
@click.option("--worst", type=int, default=5, show_default=True, help="How many worst cases to list.")
@click.option("--quiet", is_flag=True, help="No progress bar.")
@click.option("--scenario", type=click.Path(dir_okay=False), metavar="FILE.toml",
              help="Mission, controller, vehicle, disturbances and a [montecarlo] table from a scenario file.")
@_friendly
def montecarlo(**options):
    """Fly a population of perturbed vehicles and report the distribution of every metric.

    Runs on Dask (a local cluster of processes by default); results stream to --out as
    chunks finish, so an interrupted sweep resumes where it stopped. Every draw comes from
    --seed, whatever the chunking or the machine.
    """
    from quadcruise.cli.montecarlo import montecarlo_command

    montecarlo_command(**options, echo=click.echo)


def _mission(text: str, params: tuple[str, ...], smooth: bool):
    """A mission from a name or a waypoint CSV, with KEY=VALUE parameters."""
    from quadcruise.missions import mission_from_name

    mparams = _assignments(params, "--mission-param")
    if text.lower().endswith(".csv"):
        mparams["table"] = text
        text = "minsnap" if smooth else "waypoints"
    return mission_from_name(text, **mparams)


def run() -> None:
    """Entry point: click's own usage errors become one line with exit status 2 too.

    The process ends here, so what it made is first moved out of the garbage collector's
    sight (``gc.freeze``): the interpreter's last collection at exit would otherwise walk
    every object that numba, pandas and matplotlib left, about 0.2 s.
    """
    try:
        code = main(standalone_mode=False)
    except click.exceptions.UsageError as exc:
        click.echo(f"error: {exc.format_message()}", err=True)
        sys.exit(2)
    except (click.exceptions.Abort, KeyboardInterrupt):
        click.echo("error: interrupted (a montecarlo sweep with --out resumes if run again)", err=True)
        sys.exit(130)
    finally:
        gc.freeze()
    sys.exit(code if isinstance(code, int) else 0)


if __name__ == "__main__":  # pragma: no cover
    run()

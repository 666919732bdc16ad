"""``quadcruise analyze``: the closed loop linearised about hover; its summary printed, its
folder written on request."""

from __future__ import annotations

import sys

import click

from quadcruise.cli.common import FORCE_OPTION, SECONDS, Bar, controller_from_options, friendly, writable
from quadcruise.cli.objects import PARAMS_OPTION
from quadcruise.io.files import check_output_dir

__all__ = ["analyze"]


@click.command("analyze")
@click.option(
    "--controller",
    default=None,
    help="Controller name [default: nlpd; px4 with --params]. px4: its rate, attitude, velocity and position "
    "loops' margins and bandwidths per axis against PX4's targets.",
)
@click.option(
    "-c",
    "--controller-param",
    "controller_params",
    multiple=True,
    metavar="KEY=VALUE",
    help="Controller parameter (repeatable).",
)
@click.option("--poles", "position_poles", metavar="P1,P2", help="Closed-loop poles of the x/y loops [rad/s].")
@click.option("--dt", type=SECONDS, default=1e-3, show_default=True, help="Control period [s].")
@click.option(
    "--vehicle",
    "vehicle_text",
    metavar="NAME|KEY=VALUE,...|FILE.toml",
    help="The vehicle (default: the paper's Table I); a rotor-plant vehicle is linearised through its "
    "equivalent '+' vehicle, with the gains fly designs for it.",
)
@click.option(
    "--out", type=click.Path(file_okay=False), callback=writable, help="Folder for analysis.json and Bode plots."
)
@PARAMS_OPTION
@FORCE_OPTION
@friendly
def analyze(controller, controller_params, position_poles, dt, vehicle_text, out, px4_params, force):
    """Linearise the closed loop about hover: poles, damping, margins of each loop, Bode plots.

    \f
    Parameters
    ----------
    controller : str or None
        ``--controller``: the controller's name (:func:`quadcruise.control.controller_from_name`);
        None: nlpd, or px4 with ``--params``. The px4 controller's loops are analysed one at a
        time as PX4's tuning reads them (:func:`quadcruise.workflows.px4margins.px4_margins`).
    controller_params : tuple of str
        ``-c``/``--controller-param``: the controller's parameters, each ``KEY=VALUE``.
    position_poles : str or None
        ``--poles``: comma-separated closed-loop poles of the x/y loops [rad/s], e.g.
        ``-0.7,-4.3``; their PD gains replace the controller's position gains. None: not given.
    dt : float
        ``--dt``: control period [s].
    vehicle_text : str or None
        ``--vehicle``: a preset, ``KEY=VALUE`` fields or a vehicle TOML file; None: Table I. A
        rotor-plant vehicle is linearised as its equivalent "+" paper vehicle
        (:func:`quadcruise.model.equivalent.paper_equivalent`: about hover, at zero airspeed, its
        thrust kf w^2 and motor lag linearise to that vehicle's), its controller given by name designed
        for it as ``fly`` designs it.
    out : str or None
        ``--out``: folder to write ``analysis.json`` and the Bode plots to; None: print only.
    px4_params : str or None
        ``--params``: a PX4 log or QGroundControl ``.params`` file whose parameters the px4
        controller analysed has (:func:`~quadcruise.cli.objects.controller_with_params`).
    force : bool
        ``--force``: replace a non-empty ``out`` folder that quadcruise did not write.
    """
    if controller == "px4" or px4_params is not None:
        _analyze_px4(controller, controller_params, position_poles, dt, vehicle_text, out, px4_params, force)
        return
    controller = controller or "nlpd"
    linearising = Bar("linearising about hover")
    linearising(0, 3)  # python-control takes a few seconds to load
    from quadcruise.cli.objects import controller_for_vehicle
    from quadcruise.cli.vehicle import vehicle_from_option
    from quadcruise.model.equivalent import paper_equivalent
    from quadcruise.workflows.analysis import linearize

    vehicle = vehicle_from_option(vehicle_text, "--vehicle")
    the_controller = controller_from_options(controller, controller_params, position_poles)
    the_controller = controller_for_vehicle(
        the_controller, controller, controller_params, position_poles, {"vehicle": vehicle}, None
    )
    if vehicle is not None:  # None: linearize's default, Table I
        vehicle = paper_equivalent(vehicle)  # a rotor-plant vehicle's "+" equivalent, a paper one as it is
    if out is not None:
        check_output_dir(out, force, inputs=[vehicle_text])
    lin = linearize(the_controller, vehicle, dt=dt, progress=linearising)
    click.echo(str(lin.summary(progress=Bar("margins", unit="loop"))))
    if out is not None:
        lin.write(out, force=force, progress=Bar("Bode plots"))
        click.echo(f"wrote analysis.json and Bode plots to {out}")
    if not lin.stable:
        sys.exit(1)  # the closed loop about hover is unstable: it could never have flown


def _analyze_px4(controller, controller_params, position_poles, dt, vehicle_text, out, px4_params, force):
    """``analyze --controller px4`` (or ``--params``): the px4 loops' margins per axis."""
    from quadcruise.cli.objects import controller_for_vehicle, controller_with_params
    from quadcruise.cli.vehicle import vehicle_from_option
    from quadcruise.errors import InputError

    if dt > 0.05:
        raise InputError(f"--dt {dt:g}: the px4 controller's rate loop runs at the control period, at most 0.05 s")
    if position_poles is not None and px4_params is None:
        raise InputError("--poles: the px4 controller takes its position gains from PX4's MPC_* parameters")
    vehicle = vehicle_from_option(vehicle_text, "--vehicle")
    world = {"vehicle": vehicle}
    if px4_params is not None:
        the_controller = controller_with_params(None, controller, px4_params, controller_params, position_poles, world)
    else:
        the_controller = controller_from_options("px4", controller_params, None)
        the_controller = controller_for_vehicle(the_controller, "px4", controller_params, None, world, None)
    if out is not None:
        check_output_dir(out, force, inputs=[vehicle_text, px4_params])
    from quadcruise.workflows.px4margins import px4_margins

    result = px4_margins(the_controller, vehicle, dt=dt)
    summary = result.summary()
    click.echo(str(summary))
    if out is not None:
        result.write(out, force=force, progress=Bar("Bode plots", unit="loop"))
        click.echo(f"wrote analysis.json and bode.png to {out}")
    if not all(e["stable"] for axes in summary["loops"].values() for e in axes.values()):
        sys.exit(1)  # a loop is unstable about hover: it could never have flown

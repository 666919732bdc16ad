"""``quadcruise analyze``: the closed loop linearised about hover; its summary printed, its
folder written on request."""

from __future__ import annotations

import click

from quadcruise.cli.common import FORCE_OPTION, SECONDS, Bar, controller_from_options, friendly, writable
from quadcruise.io.files import check_output_dir

__all__ = ["analyze"]


@click.command("analyze")
@click.option("--controller", default="nlpd", show_default=True, help="Controller name.")
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
    "--out", type=click.Path(file_okay=False), callback=writable, help="Folder for analysis.json and Bode plots."
)
@FORCE_OPTION
@friendly
def analyze(controller, controller_params, position_poles, dt, out, force):
    """Linearise the closed loop about hover: poles, damping, margins of each loop, Bode plots.

    \f
    Parameters
    ----------
    controller : str
        ``--controller``: the controller's name (:func:`quadcruise.control.controller_from_name`).
    controller_params : tuple of str
        ``-c``/``--controller-param``: the controller's parameters, each ``KEY=VALUE``.
    position_poles : str or None
        ``--poles``: comma-separated closed-loop poles of the x/y loops [rad/s], e.g.
        ``-0.7,-4.3``; their PD gains replace the controller's position gains. None: not given.
    dt : float
        ``--dt``: control period [s].
    out : str or None
        ``--out``: folder to write ``analysis.json`` and the Bode plots to; None: print only.
    force : bool
        ``--force``: replace a non-empty ``out`` folder that quadcruise did not write.
    """
    linearising = Bar("linearising about hover")
    linearising(0, 3)  # python-control takes a few seconds to load
    from quadcruise.workflows.analysis import linearize

    the_controller = controller_from_options(controller, controller_params, position_poles)
    if out is not None:
        check_output_dir(out, force)
    lin = linearize(the_controller, dt=dt, progress=linearising)
    click.echo(str(lin.summary(progress=Bar("margins", unit="loop"))))
    if out is not None:
        lin.write(out, force=force, progress=Bar("Bode plots"))
        click.echo(f"wrote analysis.json and Bode plots to {out}")

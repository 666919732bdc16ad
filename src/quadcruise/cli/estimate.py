"""``quadcruise estimate``: our EKF on a PX4 log's own sensors, compared with the log's EKF2
estimate (a folder with ``estimate.json`` and ``estimate.png``)."""

from __future__ import annotations

import math
import shlex

import click

from quadcruise.cli.common import FORCE_OPTION, friendly, writable

__all__ = ["estimate"]


@click.command("estimate")
@click.argument("log", metavar="LOG.ulg", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--declination",
    type=float,
    default=None,
    metavar="DEG",
    help="Magnetic declination east of north [deg]; default: the log's EKF2_MAG_DECL, else 0.",
)
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(file_okay=False),
    callback=writable,
    help="Folder for estimate.json (RMS differences from EKF2, the configuration) and estimate.png.",
)
@FORCE_OPTION
@friendly
def estimate(log: str, declination: float | None, out: str, force: bool) -> None:
    """Run quadcruise's EKF on LOG's sensor_combined, GPS, barometer and magnetometer, and
    compare it with what PX4's EKF2 estimated (vehicle_attitude, vehicle_local_position).

    Prints the RMS differences (roll, pitch, yaw in degrees; altitude and horizontal position
    in metres) and writes them, with the configuration, to OUT/estimate.json, and a figure
    of both estimates to OUT/estimate.png.

    \f
    Parameters
    ----------
    log : str
        ``LOG``: the PX4 log (``.ulg``).
    declination : float or None
        ``--declination``: [deg].
    out : str
        ``--out``: the output folder.
    force : bool
        ``--force``: replace a folder quadcruise did not write.
    """
    from quadcruise.errors import InputError
    from quadcruise.io.files import check_output_dir
    from quadcruise.workflows.estimate import estimate_log

    if declination is not None and not math.isfinite(declination):
        raise InputError(f"--declination must be a finite number of degrees, got {declination}")
    check_output_dir(out, force)
    words = ["quadcruise", "estimate", log, "--out", out]
    words += ["--declination", f"{declination:g}"] if declination is not None else []
    result = estimate_log(log, declination=None if declination is None else math.radians(declination),
                          command=shlex.join(words))  # fmt: skip
    click.echo(f"{log}: quadcruise EKF against the log's EKF2, from t = {result.config['start_s']:.2f} s")
    click.echo(result.table())
    result.write(out, force=force)
    click.echo(f"wrote {out}/estimate.json, {out}/estimate.png")

"""``quadcruise px4-check``: a PX4 log's own signals through the PX4 loops, compared with what
PX4 logged (a folder with ``check.json``)."""

from __future__ import annotations

import shlex

import click

from quadcruise.cli.common import FORCE_OPTION, friendly, writable

__all__ = ["px4_check"]


@click.command("px4-check")
@click.argument("log", metavar="LOG.ulg")
@click.option(
    "--params",
    "params",
    default=None,
    metavar="LOG.ulg|FILE.params",
    help="Parameters to run the loops with (a PX4 log's or a QGroundControl file's); default: LOG's own.",
)
@click.option(
    "--out",
    "out",
    required=True,
    type=click.Path(file_okay=False),
    callback=writable,
    help="Folder for check.json (R2 and RMSE per loop and axis, the parameters, what limits the fit).",
)
@FORCE_OPTION
@friendly
def px4_check(log: str, params: str | None, out: str, force: bool) -> None:
    """Feed LOG's attitude, rates and positions through PX4's loops (release v1.15, written from
    PX4's source) with LOG's parameters, and compare what they give with what PX4 logged.

    Prints R2 and RMSE per loop and axis, airborne samples only, and writes them to
    OUT/check.json. Parameters the loops do not use are counted here and listed there.

    \f
    Parameters
    ----------
    log : str
        ``LOG``: the PX4 log (``.ulg``).
    params : str or None
        ``--params``: a ``.ulg`` or ``.params`` file whose parameters to use instead.
    out : str
        ``--out``: the output folder.
    force : bool
        ``--force``: replace a folder quadcruise did not write.
    """
    from quadcruise.io.files import check_output_dir
    from quadcruise.io.px4params import read_params
    from quadcruise.workflows.px4check import px4_check as run_check

    chosen = read_params(params) if params is not None else None
    check_output_dir(out, force, inputs=[log, params])
    words = ["quadcruise", "px4-check", log, "--out", out] + (["--params", params] if params else [])
    result = run_check(log, chosen, command=shlex.join(words))
    click.echo(
        f"{result.log}: PX4 {result.px4_version}; loops of PX4 v1.15 with the parameters of {result.params.source}"
    )
    click.echo(result.table())
    unused = result.params.unused
    if 0 < len(unused) <= 12:
        click.echo(f"not used by the loops: {', '.join(unused)} (of {result.params.source})")
    elif unused:
        click.echo(
            f"{len(unused)} parameters of {result.params.source} are not used by the loops (listed in {out}/check.json)"
        )
    result.write(out, force=force)
    click.echo(f"wrote {out}/check.json")

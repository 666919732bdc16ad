"""``quadcruise vehicles``: the vehicle presets, their plant and their sources."""

from __future__ import annotations

import click

from quadcruise.cli.common import friendly

__all__ = ["vehicles"]


@click.command("vehicles")
@friendly
def vehicles() -> None:
    """List the vehicle presets: name, plant, mass, rotors and where the numbers come from.

    Give a name to --vehicle, or copy its file (listed under it) and change any field.

    \f
    Notes
    -----
    The presets are TOML files in ``quadcruise/model/preset_files`` (docs/vehicles.md).
    """
    from quadcruise.model.vehicle_files import preset_table

    rows = preset_table()
    width = max(len(r["name"]) for r in rows)
    for r in rows:
        click.echo(f"{r['name']:<{width}}  {r['plant']:<5}  {r['m']:>7.4g} kg  {r['rotors']} rotors  {r['source']}")
        click.echo(f"{'':<{width}}  file: {r['file']}")

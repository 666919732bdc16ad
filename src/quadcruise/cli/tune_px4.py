"""``tune --controller px4``: the px4 controller in PX4's parameter form for the search, and the
``tuned.params`` written from its result."""

from __future__ import annotations

import click

from quadcruise.errors import InputError

__all__ = ["as_px4_parameters", "refuse_integer_px4_gains", "write_tuned_params"]


def write_tuned_params(result, out, command: str, world: dict, echo=click.echo) -> None:
    """``DIR/tuned.params`` of a tuned px4 controller in PX4's parameter form (what
    ``fly --params`` reads back), or a note saying why there is none.

    Parameters
    ----------
    result : TuneResult
        The tune's result.
    out : str or Path
        The tuned folder, already written.
    command : str
        The command line, recorded in the file's comment.
    world : dict
        :func:`quadcruise.cli.world.flight_world`'s.
    echo : callable
        Where the lines go (``click.echo``'s signature).
    """
    if _px4_form(result.controller):
        from pathlib import Path

        from quadcruise.io.px4params import write_params

        searched = [g.removeprefix("params.") for g in result.gains]
        note = (
            f"{command}\n"
            f"tuned: {', '.join(searched)}; the other lines are what the tune flew, not tuned "
            "(the --params file's, or the design for the simulated vehicle: check those before loading)"
        )
        path = write_params(Path(out) / "tuned.params", result.controller.params, note=note)
        echo(f"wrote {path}: `quadcruise fly MISSION --params {path}` (with the same vehicle) flies the tuned gains")
    elif getattr(result.controller, "name", None) == "px4":  # no tuned.params: said, with why
        echo(f"note: no {out}/tuned.params: {_why_no_params(result.controller, world)}", err=True)


def refuse_integer_px4_gains(names, controller) -> None:
    """A px4 parameter PX4 declares INT32 (``MC_AIRMODE``, ``IMU_INTEG_RATE``, ...) is a choice,
    not a gain a continuous search can set: refused before the search, naming it."""
    if getattr(controller, "name", None) != "px4" or not names:
        return
    from quadcruise.io.px4defaults import INT32, PX4_PARAMETERS

    for name in names:
        spec = PX4_PARAMETERS.get(name.removeprefix("params.")) if name.startswith("params.") else None
        if spec is not None and spec.kind == INT32:
            raise InputError(
                f"--gains {name}: PX4 declares it an integer (INT32), which the search cannot set; "
                f"tune with each value instead (a --params FILE setting it, e.g. "
                f"{name.removeprefix('params.')} {spec.default:g})"
            )


def _why_no_params(controller, world: dict) -> str:
    """Why a tuned px4 controller has no PX4 parameter form (the paper plant's design)."""
    from quadcruise.model.equivalent import paper_equivalent

    believed = world.get("controller_vehicle") or world.get("vehicle")
    reason = "its gains are designed for the vehicle (rate_bandwidth, hover_from_vehicle)"
    try:
        controller.resolved(paper_equivalent(believed))
    except InputError as exc:  # the design is outside PX4's ranges
        reason += f" and PX4's parameters cannot hold them ({str(exc).removeprefix('argument: ')})"
    return reason + "; tune a rotor vehicle (--vehicle iris) or PX4's own parameters (--params FILE) for one"


def _px4_form(controller) -> bool:
    """A px4 controller flying PX4's parameters as they are (what ``--params`` reads back)."""
    return getattr(controller, "name", None) == "px4" and not (
        controller.hover_from_vehicle or controller.rate_bandwidth > 0.0
    )


def as_px4_parameters(controller, world: dict, given: bool):
    """A px4 controller on a rotor-plant vehicle (or from ``--params``) in PX4's parameter form: its
    vehicle-dependent design written as PX4 parameters and the vehicle's rotors, exactly what
    ``fly --params tuned.params`` builds, so the tuned file flies the tuned flight.

    Parameters
    ----------
    controller : Controller
        The controller to tune.
    world : dict
        :func:`quadcruise.cli.world.flight_world`'s.
    given : bool
        ``--params`` was given.

    Returns
    -------
    Controller
        ``controller`` itself unless it is px4 on a rotor-plant vehicle or from ``--params``.

    Raises
    ------
    InputError
        A design value outside PX4's range (PX4 could not fly it).
    """
    from quadcruise.model.equivalent import paper_equivalent
    from quadcruise.sim import plants

    believed = world.get("controller_vehicle") or world.get("vehicle")
    designs = believed is not None and plants.of(believed).designs_gains  # designed for the vehicle believed
    if getattr(controller, "name", None) != "px4" or not (given or designs):
        return controller
    if _px4_form(controller) and (given or controller.rotors):
        return controller
    from quadcruise.control.px4 import Px4

    plain = controller.resolved(paper_equivalent(believed))  # a paper vehicle is its own equivalent
    return Px4.from_params(plain.params, vehicle=believed, position_rate=controller.position_rate)

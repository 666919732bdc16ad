"""What :func:`quadcruise.identify` fits from, for the base vehicle's plant
(:mod:`quadcruise.sim.plants`): :data:`BASES`, one entry per plant.

The paper plant's fit (:mod:`quadcruise.sysid.equations`) serves both plants. A paper base
vehicle is its own start: the log's rotors are the paper's "+" of its arm ``l`` where the log
has no ``CA_ROTOR*``, the commands are thrusts, the joint covariance of the result is kept.
A rotor-plant base with rotor speeds in the log is identified on its own plant
(:func:`~quadcruise.sysid.rotor_identify.identify_rotor`); without them, from the commands
alone (:mod:`quadcruise.sysid.commands_alone`): the fit starts from its "+" equivalent with one
rotor's full thrust as K, its rotors where the log has none, the commands as relative thrust
whose square root (the speed) lags, and the result turned into the rotor plant's.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.io.flightlog import FlightLog
from quadcruise.sysid.logprep import WINDOW_S, command_meaning


@dataclass(frozen=True)
class Basis:
    """The start of a fit of the paper plant's equations, for a base vehicle of a plant.

    Parameters
    ----------
    vehicle : Vehicle
        The paper vehicle the fit starts from (its g, omega, l, and the values reported for what
        the log cannot identify).
    geometry : callable
        ``geometry(flight) -> (n, 3) array``: the rotors (x, y, direction) where the log has none.
    commands : callable
        ``commands(flight) -> FlightLog``: the commands as the fit reads them.
    lag_of : str
        What lags the command: ``"thrust"`` (the paper plant) or ``"speed"``.
    covariance : bool
        The result keeps the joint covariance of its parameters (a Monte Carlo population draws from it).
    finish : callable
        ``finish(result) -> IdentifyResult``: the paper plant's result as the base's plant reports it.
    """

    vehicle: Any
    geometry: Callable[[FlightLog], np.ndarray]
    commands: Callable[[FlightLog], FlightLog]
    lag_of: str
    covariance: bool
    finish: Callable[[Any], Any]


def paper_basis(flight: FlightLog, base, mass, holdout, kind, report) -> tuple[Any, Basis]:
    """A paper base vehicle: ``(None, its basis)``."""

    def plus(flight: FlightLog) -> np.ndarray:
        if flight.n_rotors != 4:
            raise InputError(
                f"{flight.source}: {flight.n_rotors} rotor commands and no CA_ROTOR* geometry: "
                "the base vehicle has the paper's four '+' rotors"
            )
        arm = float(base.l)
        return np.array([[-arm, 0.0, 1.0], [0.0, arm, -1.0], [arm, 0.0, 1.0], [0.0, -arm, -1.0]])

    return None, Basis(base, plus, lambda f: f, "thrust", True, lambda result: result)


def rotor_basis(flight: FlightLog, base, mass, holdout, kind, report) -> tuple[Any, Basis | None]:
    """A rotor-plant base vehicle: ``(its result, None)`` from a log with rotor speeds fast enough,
    else ``(None, the basis of the commands alone)``."""
    from quadcruise.model.equivalent import paper_equivalent
    from quadcruise.sysid.commands_alone import as_rotor_result
    from quadcruise.sysid.rotor_identify import MIN_SPEED_SAMPLES, identify_rotor

    speed_hz = float(flight.rates_hz.get("esc_status", flight.rates_hz.get("csv", 0.0)))
    if kind == "rad/s" or (flight.speeds is not None and speed_hz >= MIN_SPEED_SAMPLES / WINDOW_S):
        return identify_rotor(flight, base, mass, holdout, kind, report), None

    def hubs(flight: FlightLog) -> np.ndarray:
        rotors = np.array([[x, y, s] for x, y, _, s in base.rotors], dtype=float)
        if len(rotors) != flight.n_rotors:
            raise InputError(
                f"{flight.source}: {flight.n_rotors} rotor commands and no CA_ROTOR* geometry: the base "
                f"vehicle has {len(rotors)} rotors"
            )
        return rotors

    def relative(flight: FlightLog) -> FlightLog:  # relative thrust, whose square root (the speed) lags
        meaning, f_log = command_meaning(flight)
        u_rel = flight.u if meaning == "thrust" else f_log * flight.u**2 + (1.0 - f_log) * flight.u
        return dataclasses.replace(flight, u=u_rel, commands=flight.commands + "; relative thrust (rotor plant)")

    equivalent = paper_equivalent(base).replace(K=float(base.kf * base.w_max**2))  # one rotor's full thrust
    return None, Basis(equivalent, hubs, relative, "speed", False, lambda result: as_rotor_result(result, base))


BASES: dict[str, Callable[..., tuple[Any, Basis | None]]] = {"paper": paper_basis, "rotor": rotor_basis}
"""Each plant's start of an identification, by the plant's name:
``basis(flight, base, mass, holdout, kind, report) -> (result or None, Basis or None)``."""

__all__ = ["BASES", "Basis", "paper_basis", "rotor_basis"]

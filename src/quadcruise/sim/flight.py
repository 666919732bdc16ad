"""One array-level ``simulate`` for both plants: :func:`quadcruise.simulate`.

The plant is read from the arrays as the :class:`~quadcruise.sim.stepper.Stepper` reads it
(:func:`quadcruise.sim.plants.of_arrays`): with ``alloc`` (the rotor plant's allocation rows)
the rotor-speed plant flies (:func:`~quadcruise.sim.rotor_batch.fly_rotor_vehicles`: ``x0`` rotor
states, ``vp`` rotor rows, ``vp_ctrl`` the controller's equivalent paper row), without it the
paper plant (:func:`quadcruise.sim.engine.simulate`, unchanged: its flights bit for bit). The
plant checks its arrays and refuses what is not its own in one line naming the argument. This
module sits above the plant modules, which themselves fly the paper plant through the engine.
"""

from __future__ import annotations

from typing import Any

from quadcruise.sim import plants
from quadcruise.sim.result import SimResult


def simulate(
    t_grid,
    x0,
    vp,
    controller,
    gains,
    mission,
    mp,
    *,
    alloc=None,
    psi0=None,
    touchdown_speed=None,
    rotor_names=None,
    **options: Any,
) -> SimResult:
    """Fly N vehicles of either plant over the control instants ``t_grid``.

    Parameters
    ----------
    t_grid, x0, vp, controller, gains, mission, mp : array_like or compiled function
        As :func:`quadcruise.sim.engine.simulate` takes them (the paper plant); with ``alloc``,
        ``x0`` the rotor states (13 + n columns) and ``vp`` the rotor rows
        (:meth:`~quadcruise.model.rotor_vehicle.RotorVehicle.row`), as
        :func:`~quadcruise.sim.rotor_batch.fly_rotor_vehicles` takes them.
    alloc : (4 n + 1,) or (N, 4 n + 1) array, optional
        The rotor plant's allocation rows (the controller vehicle's duty-to-thrust matrix, then
        its kf); given, the rotor plant flies.
    psi0, touchdown_speed, rotor_names : optional
        The rotor plant's own (:func:`~quadcruise.sim.rotor_batch.fly_rotor_vehicles`);
        refused on the paper plant.
    **options : Any
        The engine's keywords (``memory``, ``vp_ctrl``, ``disturbance``, ..., ``log_every``,
        ``limits``, ``meta``, ``track``; ``full_dynamics`` on the paper plant only).

    Returns
    -------
    SimResult
        The logged flight; on the rotor plant with ``rotor_states`` beside the paper layout.

    Raises
    ------
    InputError
        An option the plant does not take, or an array that does not fit it (one line naming it).

    Examples
    --------
    >>> import numpy as np, quadcruise as qc
    >>> from quadcruise.sim.engine import simulate as paper_simulate
    >>> from quadcruise.control import NLPD
    >>> from quadcruise.missions import Hover
    >>> t, c, m, v = qc.time_grid(0.01, 1e-3), NLPD(), Hover(), qc.Vehicle.paper()
    >>> args = (t, np.zeros(16), v.rows(1), c.function, c.gains(), m.function, m.params())
    >>> mem = c.memory()  # nlpd's integrators: a controller's memory must be given
    >>> bool((qc.simulate(*args, memory=mem).states == paper_simulate(*args, memory=mem).states).all())
    True
    >>> qc.simulate(*args, psi0=1.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: simulate() argument psi0: the rotor plant's (give alloc, ...)
    """
    plant = plants.of_arrays(alloc)
    own = {"alloc": alloc, "psi0": psi0, "touchdown_speed": touchdown_speed, "rotor_names": rotor_names}
    own = {k: v for k, v in own.items() if v is not None}
    for option, value in options.items():  # e.g. full_dynamics=True on the rotor plant
        plant.refuse("simulate()", option, value is not None and value is not False)
    for option in own:  # the rotor plant's own, given to the paper plant
        plant.refuse("simulate()", option, True)
    args, options = (t_grid, x0, vp, controller, gains, mission, mp), {**options, **own}
    plant.check_arrays("simulate()", args, options)
    return plant.fly(args, options)


__all__ = ["simulate"]

"""What the engine is handed: the time grid, the divergence bounds, the batch arrays checked and
laid out as the kernel reads them, and the kernel's ``carry`` rows.

Everything here runs in Python before the flight: a wrong argument is one :class:`InputError`
line naming it, never a numba typing error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from quadcruise import checks
from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.layout import STATE_SIZE
from quadcruise.sim.rng import vehicle_states


@dataclass(frozen=True)
class Limits:
    """Bounds beyond which a flight counts as diverged (and stops).

    Parameters
    ----------
    max_position : float
        |x|, |y| or |z| above this [m] ends the flight.
    max_speed : float
        any velocity component above this [m/s].
    max_rate : float
        any body rate above this [rad/s].
    max_tilt : float
        |roll| or |pitch| above this [rad]; 90 degrees by default: beyond it the vehicle is
        on its side or upside down, its thrust pulls it towards the ground, and no mission
        is being flown (the paper's model has no singularity there: it is the flight that
        has failed, whatever the mission). (The full plant, ``full_dynamics=True``, stops
        anyway at |pitch| > :data:`quadcruise.model.plant.EULER_PITCH_LIMIT`, 85 degrees,
        with the status ``PITCH_SINGULAR``.)
    """

    max_position: float = 1.0e4
    max_speed: float = 1.0e3
    max_rate: float = 1.0e3
    max_tilt: float = math.pi / 2.0

    def __post_init__(self) -> None:
        for name in ("max_position", "max_speed", "max_rate", "max_tilt"):
            object.__setattr__(self, name, checks.number("Limits()", name, getattr(self, name), "pos", infinite=True))

    def array(self) -> np.ndarray:
        """The four bounds as the kernel reads them.

        Returns
        -------
        numpy.ndarray
            (4,) max_position [m], max_speed [m/s], max_rate [rad/s], max_tilt [rad].
        """
        return np.array([self.max_position, self.max_speed, self.max_rate, self.max_tilt])


TRIG_WIDTH = 6  # the carried sines and cosines of phi, theta, psi (the RK4 workspace row TRIG in use)


MEMORY_GUARD = 256
"""Width of the NaN memory row a controller or a disturbance gets when its memory is not given
(``memory=None``): wider than any built-in law's (px4: 133), so that one which reads memory it was
not handed reads NaN (its flight then stops with a bad command) instead of past the row's end,
which would give numbers that change from run to run. Pass ``memory=controller.memory()``."""


def carry_width(sensor_delay: int) -> int:
    """Width of the kernel's ``carry`` rows: the 6 carried sines and cosines of the angles,
    then the sensor-delay ring buffer of ``sensor_delay + 1`` states.

    Parameters
    ----------
    sensor_delay : int
        The sensor delay [control periods].

    Returns
    -------
    int

    Examples
    --------
    >>> carry_width(0), carry_width(2)
    (22, 54)
    """
    return TRIG_WIDTH + (int(sensor_delay) + 1) * STATE_SIZE


def fresh_carry(x0: np.ndarray, sensor_delay: int) -> np.ndarray:
    """The ``carry`` rows of vehicles about to start from the states ``x0``: every slot of the
    ring buffer holds x0 (the controller sees the initial state until the delay has passed).

    Parameters
    ----------
    x0 : numpy.ndarray
        (N, 16) initial states.
    sensor_delay : int
        The sensor delay [control periods].

    Returns
    -------
    numpy.ndarray
        (N, :func:`carry_width`) rows; the sines and cosines are zero: a vehicle whose
        ``clock`` RK4 count is 0 computes them afresh.
    """
    n = x0.shape[0]
    out = np.zeros((n, carry_width(sensor_delay)))
    out[:, TRIG_WIDTH:] = np.tile(x0, (1, int(sensor_delay) + 1))
    return out


MAX_STEPS = 1e9
"""Most control periods one flight may have (a day at 1 kHz is 8.6e7): beyond it the time grid
alone would need 8 GB."""


def time_grid(duration: float, dt: float, t0: float = 0.0) -> np.ndarray:
    """Uniform control instants t0, t0 + dt, ..., t0 + duration.

    ``duration`` must be a whole number of periods (to 1e-9 relative) so the grid ends
    exactly at t0 + duration.

    Parameters
    ----------
    duration : float
        Flight time [s], > 0.
    dt : float
        Control period [s], in (0, duration].
    t0 : float
        First instant [s].

    Returns
    -------
    numpy.ndarray
        The instants [s], duration / dt + 1 of them.

    Examples
    --------
    >>> time_grid(0.003, 0.001).tolist()
    [0.0, 0.001, 0.002, 0.003]
    """
    if not (math.isfinite(duration) and duration > 0):
        raise InputError(f"duration must be a positive number of seconds, got {describe(duration)}")
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a positive number of seconds, got {describe(dt)}")
    if dt > duration:
        raise InputError(f"dt ({dt:g} s) is larger than the duration ({duration:g} s)")
    if duration / dt > MAX_STEPS:
        raise InputError(
            f"{duration:g} s at dt = {dt:g} s is {duration / dt:.3g} control periods, more than "
            f"{MAX_STEPS:.0e}: shorten the duration or lengthen dt"
        )
    n = round(duration / dt)
    if abs(n * dt - duration) > 1e-9 * max(1.0, duration):
        raise InputError(f"duration ({duration:g} s) is not a whole number of dt ({dt:g} s) periods")
    return t0 + dt * np.arange(n + 1, dtype=float)


def _batch(name: str, a, n: int, width: int | None) -> np.ndarray:
    """Broadcast a vector or (N, w) array to a C-contiguous (n, w) float64 array."""
    arr = np.asarray(a, dtype=float)
    if arr.ndim == 1:
        arr = np.broadcast_to(arr, (n, arr.shape[0]))
    if arr.ndim != 2 or arr.shape[0] != n or (width is not None and arr.shape[1] != width):
        want = f"({n}, {width})" if width is not None else f"({n}, w)"
        raise InputError(f"{name} has shape {np.shape(a)}, expected {want} or one row")
    return np.array(arr, dtype=float, order="C")  # a writable copy, never a broadcast view


def batch_inputs(
    t_grid,
    x0,
    vp,
    gains,
    mp,
    *,
    memory=None,
    vp_ctrl=None,
    disturbance=None,
    disturbance_params=None,
    disturbance_memory=None,
    seed: int = 0,
    first_vehicle=0,
    sensor_std=None,
    sensor_delay: int = 0,
    max_step: float = 1e-3,
    log_every: int = 1,
) -> dict:
    """The kernel's batch arrays, checked and made C-contiguous writable copies: what
    :func:`simulate` and :class:`quadcruise.sim.stepper.Stepper` hand to the kernel.

    Parameters
    ----------
    t_grid, x0, vp, gains, mp, memory, vp_ctrl, disturbance, disturbance_params, disturbance_memory : array or None
        As in :func:`simulate` (``disturbance`` only says whether there is one).
    seed, first_vehicle, sensor_std, sensor_delay, max_step, log_every : optional
        As in :func:`simulate`.

    Returns
    -------
    dict
        The arrays by name (``t_grid``, ``x0``, ``vp``, ``gains``, ``mp``, ``memory``, ``vp_ctrl``,
        ``disturbance_params``, ``disturbance_memory``, ``sensor_std``, ``rng``), the number of
        vehicles ``n``, ``disturbed`` and ``drawn`` (whether anything draws random numbers).

    Raises
    ------
    InputError
        One line naming the argument that is wrong.
    """
    t_grid = np.ascontiguousarray(t_grid, dtype=float)
    if t_grid.ndim != 1 or t_grid.shape[0] < 2:
        raise InputError("the time grid needs at least two instants")
    if not np.all(np.isfinite(t_grid)) or np.any(np.diff(t_grid) <= 0):
        raise InputError("the time grid must be finite and strictly increasing")
    if not (math.isfinite(max_step) and max_step > 0):
        raise InputError(f"max_step must be a positive number of seconds, got {describe(max_step)}")
    if int(log_every) != log_every or log_every < 1:
        raise InputError(f"log_every must be a positive integer, got {describe(log_every)}")
    vp = np.ascontiguousarray(vp, dtype=float)
    n = vp.shape[0]
    x0 = _batch("initial state", x0, n, STATE_SIZE)
    if not np.all(np.isfinite(x0)):
        raise InputError("the initial state must be finite")
    gains = _batch("controller gains", gains, n, None)
    mp = _batch("mission parameters", mp, n, None)
    # memory not given: a row of NaN (MEMORY_GUARD wide), so that a compiled law that reads memory it
    # was not handed computes NaN and stops with a bad command instead of reading past an empty row
    mem = _batch("controller memory", np.full(MEMORY_GUARD, np.nan) if memory is None else memory, n, None)
    vp_ctrl = vp if vp_ctrl is None else _batch("controller parameters", vp_ctrl, n, vp.shape[1])
    dp = _batch("disturbance parameters", np.zeros(0) if disturbance_params is None else disturbance_params, n, None)
    dmem = _batch(
        "disturbance memory",
        np.full(MEMORY_GUARD, np.nan) if disturbance_memory is None else disturbance_memory,
        n,
        None,
    )
    std = _batch("sensor noise", np.zeros(STATE_SIZE) if sensor_std is None else sensor_std, n, STATE_SIZE)
    if not np.all(np.isfinite(std)) or np.any(std < 0):
        raise InputError("sensor noise standard deviations must be finite and >= 0")
    if int(sensor_delay) != sensor_delay or sensor_delay < 0:
        raise InputError(f"sensor delay must be a whole number of periods >= 0, got {describe(sensor_delay)}")
    # the random streams, when anything draws from them (SeedSequence: ~25 us a vehicle)
    disturbed = disturbance is not None
    drawn = disturbed or bool(np.any(std))
    rng = vehicle_states(seed, n, first_vehicle) if drawn else np.zeros((n, 1), dtype=np.uint64)
    return {
        "t_grid": t_grid,
        "x0": x0,
        "vp": vp,
        "n": n,
        "gains": gains,
        "mp": mp,
        "memory": mem,
        "vp_ctrl": vp_ctrl,
        "disturbance_params": dp,
        "disturbance_memory": dmem,
        "sensor_std": std,
        "rng": rng,
        "disturbed": disturbed,
        "drawn": drawn,
    }


__all__ = [
    "Limits",
    "MAX_STEPS",
    "TRIG_WIDTH",
    "batch_inputs",
    "carry_width",
    "fresh_carry",
    "time_grid",
]

"""Wind that the vehicle meets through its drag: a steady wind and a 1 - cosine gust, and the
default drag that lets wind act on a vehicle without any.

- Gust: w = (A/2)(1 - cos(2 pi (t - start)/duration)) for start <= t <= start + duration, else
  0: MIL-F-8785C's 1 - cosine rise (A/2)(1 - cos(pi x/d_m)) with the gust length d_m covered in
  duration/2 (peak A at start + duration/2), then mirrored back to 0 (the full 1 - cosine gust).

The wind acts only through the vehicle's drag -(c1 + c2 |v - w|)(v - w) (the paper's vehicle
has none: :func:`with_drag`). The compiled part is in :mod:`quadcruise.disturbances.environment`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.disturbances.part import Part
from quadcruise.disturbances.part import batch_field as _f
from quadcruise.model.vehicle import Vehicle

#: Drag estimates for a Qball-X4-sized vehicle (assumptions, not measurements): quadratic
#: 0.5 rho Cd A with rho = 1.225 kg/m^3, Cd ~ 1 (bluff frame and cage), A ~ 0.1 m^2 frontal
#: area -> 0.06 N s^2/m^2; linear rotor drag (the induced drag of the rotors, linear in the
#: air-relative velocity: Martin and Salaun, ICRA 2010) ~ 0.3 N s/m, i.e. c1/m ~ 0.09 1/s;
#: an order-of-magnitude guess, not measured on the Qball-X4.
DEFAULT_DRAG = {"drag_linear": 0.3, "drag_quadratic": 0.5 * 1.225 * 1.0 * 0.1}


@dataclass(frozen=True)
class ConstantWind(Part):
    """A steady wind (earth frame).

    Parameters
    ----------
    velocity : sequence of 3 (float or array), or (N, 3) array
        Wind velocity (x, y, z), earth frame, z up [m/s]; each component a number or one
        value per vehicle.

    Examples
    --------
    >>> ConstantWind(velocity=(3.0, 0.0, 0.0)).to_dict()
    {'model': 'constant', 'velocity': [3.0, 0.0, 0.0]}
    """

    velocity: Any = _f((0.0, 0.0, 0.0), "m/s", "wind velocity (x, y, z)", "vec")
    name = "constant"


@dataclass(frozen=True)
class Gust(Part):
    """A full "1 - cosine" gust: (A/2)(1 - cos(2 pi (t - start)/duration)) over the duration.

    Parameters
    ----------
    amplitude : sequence of 3 (float or array), or (N, 3) array
        Peak wind A (x, y, z), earth frame [m/s], reached at start + duration / 2.
    start : float or array
        Time the gust begins [s], >= 0.
    duration : float or array
        Time from start until the wind is back to 0 [s], > 0.

    Examples
    --------
    >>> Gust(amplitude=(2.0, 0.0, 0.0), start=5.0, duration=2.0).start
    5.0
    """

    amplitude: Any = _f((1.0, 0.0, 0.0), "m/s", "gust peak (x, y, z)", "vec")
    start: Any = _f(1.0, "s", "gust start", "nonneg")
    duration: Any = _f(1.0, "s", "gust duration", "pos")
    name = "gust"


def with_drag(vehicle: Vehicle, *, warn: bool = False) -> Vehicle:
    """The vehicle with :data:`DEFAULT_DRAG` where both its drag coefficients are zero.

    Wind acts on a vehicle only through its drag, and the paper's vehicle has none. Calling
    this is asking for the default drag, so it says nothing; a workflow that gives the drag
    on its own (a scenario or a sweep with wind on a vehicle without drag) passes
    ``warn=True``, and the warning says what the vehicles fly with.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle, batched or not.
    warn : bool
        Warn (UserWarning) when a vehicle is given the default drag.

    Returns
    -------
    Vehicle
        The same vehicle if every one of its vehicles has some drag; else a copy with
        ``drag_linear`` [N s/m] and ``drag_quadratic`` [N s^2/m^2] of :data:`DEFAULT_DRAG`
        for the vehicles that had none.

    Examples
    --------
    >>> from quadcruise.model.vehicle import Vehicle
    >>> with_drag(Vehicle.paper()).drag_linear
    0.3
    >>> with_drag(Vehicle.paper().replace(drag_linear=0.1)).drag_quadratic
    0.0
    """
    c1, c2 = np.asarray(vehicle.drag_linear), np.asarray(vehicle.drag_quadratic)
    bare = (c1 == 0) & (c2 == 0)
    if not np.any(bare):
        return vehicle
    if warn:
        warnings.warn(default_drag_text(int(np.count_nonzero(bare)), int(bare.size)), stacklevel=2)
    new = {k: np.where(bare, v, c) for (k, v), c in zip(DEFAULT_DRAG.items(), (c1, c2), strict=False)}
    return vehicle.replace(**{k: float(v) if v.ndim == 0 else v for k, v in new.items()})


def default_drag_text(count: int = 1, total: int = 1) -> str:
    """What :func:`with_drag` does to a vehicle without drag, in one line.

    Parameters
    ----------
    count, total : int
        How many vehicles had no drag, of how many.

    Returns
    -------
    str

    Examples
    --------
    >>> print(default_drag_text())
    the vehicle has no drag, and wind acts only through drag: it flies with DEFAULT_DRAG, drag_linear 0.3 N s/m \
and drag_quadratic 0.06125 N s^2/m^2 (estimates; give the vehicle's own drag_linear and drag_quadratic to choose)
    """
    which = "the vehicle has no drag" if total == 1 else f"{count:,} of {total:,} vehicles have no drag"
    return (
        f"{which}, and wind acts only through drag: {'it flies' if count == 1 else 'they fly'} with "
        f"DEFAULT_DRAG, drag_linear {DEFAULT_DRAG['drag_linear']:g} N s/m and drag_quadratic "
        f"{DEFAULT_DRAG['drag_quadratic']:.4g} N s^2/m^2 (estimates; give the vehicle's own drag_linear and "
        "drag_quadratic to choose)"
    )

"""Missions by name: the kinds a name, a scenario file or the command line can ask for."""

from __future__ import annotations

from typing import Any

from quadcruise import checks
from quadcruise.errors import InputError
from quadcruise.missions.base import Mission, check_names
from quadcruise.missions.minsnap import MinimumSnap
from quadcruise.missions.shapes import Circle, Hover, Square, Step
from quadcruise.missions.sysid import Sysid
from quadcruise.missions.waypoints import Waypoints
from quadcruise.model.vehicle import shared_default

__all__ = ["MISSIONS", "as_mission", "mission_from_dict", "mission_from_name"]

MISSIONS = {cls.name: cls for cls in (Hover, Step, Circle, Square, Waypoints, MinimumSnap, Sysid)}
"""Mission kind name -> class."""


def mission_from_name(name: str, **kw: Any) -> Mission:
    """Build a mission by kind name and fields.

    Parameters
    ----------
    name : str
        A key of :data:`MISSIONS`: 'hover', 'step', 'circle', 'square', 'waypoints',
        'minsnap' or 'sysid' (case and surrounding blanks ignored).
    **kw : Any
        Fields of that kind, in their units (e.g. ``radius`` [m], ``period`` [s]); the
        waypoint kinds need ``table`` (a :class:`~quadcruise.missions.WaypointTable`, a CSV
        path or a dict).

    Returns
    -------
    Mission
        The mission; without fields, the kind's shared default instance
        (:func:`quadcruise.model.vehicle.shared_default`).

    Raises
    ------
    InputError
        An unknown kind or field, a bad value, or a waypoint kind without ``table``.

    Examples
    --------
    >>> mission_from_name("circle", radius=3.0).speed == 2 * 3.1415926535897931 * 3 / 20
    True
    >>> mission_from_name(" Hover ") is mission_from_name("hover")
    True
    """
    cls = MISSIONS.get(str(name).strip().lower())
    if cls is None:
        raise InputError(f"unknown mission {name!r}; valid missions: {', '.join(MISSIONS)}")
    check_names(cls, kw)
    if cls in (Waypoints, MinimumSnap) and kw.get("table") is None:
        raise InputError(
            f"the {cls.name} mission flies a waypoint table: give its CSV file as the mission "
            f"(quadcruise fly path.csv{' --smooth' if cls is MinimumSnap else ''}) or table=PATH"
        )
    return cls(**kw) if kw else shared_default(cls)


def mission_from_dict(d: dict) -> Mission:
    """Inverse of :meth:`Mission.to_dict`.

    Parameters
    ----------
    d : dict
        ``{'kind': name, field: value, ...}``; it is not modified.

    Returns
    -------
    Mission
        As :func:`mission_from_name` builds it.

    Examples
    --------
    >>> from quadcruise.missions import Square
    >>> mission_from_dict(Square(side=2.0).to_dict()) == Square(side=2.0)
    True
    """
    d = dict(d)
    return mission_from_name(d.pop("kind", ""), **d)


def as_mission(value: Any, where: str = "fly()", name: str = "mission") -> Mission:
    """A mission from a name or a Mission object: the API's one check of a mission argument.

    Parameters
    ----------
    value : str or Mission
        A kind name (see :func:`mission_from_name`, its defaults) or a mission object.
    where, name : str
        The function and the argument, for the message.

    Returns
    -------
    Mission

    Raises
    ------
    ArgumentTypeError
        Anything else, a mission class included (the message says to make one).
    InputError
        An unknown name.

    Examples
    --------
    >>> from quadcruise.missions import Circle
    >>> as_mission("circle") == Circle()
    True
    >>> as_mission(Circle)
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: fly() argument mission must be a mission name (hover, step, circle, ...
    """
    if isinstance(value, str):
        return mission_from_name(value)
    return checks.instance(
        where, name, value, Mission, optional=False, want=f"a mission name ({', '.join(MISSIONS)}) or a Mission"
    )

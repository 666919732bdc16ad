"""Missions by name: the kinds a name, a scenario file or the command line can ask for."""

from __future__ import annotations

from typing import Any

from quadcruise.errors import InputError
from quadcruise.missions.base import Mission, check_names
from quadcruise.missions.shapes import Circle, Hover, Square, Step
from quadcruise.missions.waypoints import MinimumSnap, Waypoints
from quadcruise.model.vehicle import shared_default

__all__ = ["MISSIONS", "mission_from_dict", "mission_from_name"]

MISSIONS = {cls.name: cls for cls in (Hover, Step, Circle, Square, Waypoints, MinimumSnap)}
"""Mission kind name -> class."""


def mission_from_name(name: str, **kw: Any) -> Mission:
    """Build a mission by kind name ('hover', 'step', 'circle', 'square') and fields.

    >>> mission_from_name("circle", radius=3.0).speed == 2 * 3.1415926535897931 * 3 / 20
    True
    """
    cls = MISSIONS.get(str(name).strip().lower())
    if cls is None:
        raise InputError(f"unknown mission {name!r}; valid missions: {', '.join(MISSIONS)}")
    check_names(cls, kw)
    if cls in (Waypoints, MinimumSnap) and kw.get("table") is None:
        raise InputError(f"the {cls.name} mission flies a waypoint table: give its CSV file as the mission "
                         f"(quadcruise fly path.csv{' --smooth' if cls is MinimumSnap else ''}) or table=PATH")
    return cls(**kw) if kw else shared_default(cls)


def mission_from_dict(d: dict) -> Mission:
    """Inverse of :meth:`Mission.to_dict`."""
    d = dict(d)
    return mission_from_name(d.pop("kind", ""), **d)

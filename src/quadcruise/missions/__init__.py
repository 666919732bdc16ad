"""Missions: what the vehicle is asked to fly (hover, step, circle, square, waypoint legs,
minimum snap, the ``sysid`` excitation), each a compiled reference function of time and a frozen parameter object."""

from quadcruise.missions.base import Mission, stack_params
from quadcruise.missions.minsnap import MinimumSnap
from quadcruise.missions.registry import MISSIONS, as_mission, mission_from_dict, mission_from_name
from quadcruise.missions.shapes import Circle, Hover, Square, Step, circle_ref, hover_ref, square_ref, step_ref
from quadcruise.missions.sysid import Sysid, sysid_ref
from quadcruise.missions.waypoints import Waypoints, WaypointTable, read_waypoints_csv

__all__ = [
    "MISSIONS",
    "Circle",
    "as_mission",
    "Hover",
    "MinimumSnap",
    "Mission",
    "Square",
    "Step",
    "WaypointTable",
    "Waypoints",
    "circle_ref",
    "hover_ref",
    "mission_from_dict",
    "mission_from_name",
    "read_waypoints_csv",
    "square_ref",
    "stack_params",
    "step_ref",
    "Sysid",
    "sysid_ref",
]

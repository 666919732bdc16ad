"""The engine: fixed-step RK4 over N vehicles in one compiled kernel, its exit statuses and its
results. Controllers, missions and disturbances reach it as compiled functions, so it imports
none of them."""

from quadcruise.sim.flight import simulate
from quadcruise.sim.inputs import Limits, time_grid
from quadcruise.sim.result import SimResult

__all__ = ["Limits", "SimResult", "simulate", "time_grid"]

"""quadcruise: quadrotor cruise control, from the paper's decoupling + nonlinear PD design
to batched simulation, metrics and robustness studies.

Data flows one way: parameters -> model -> controllers -> engine -> results -> metrics ->
plots, report, CLI.
"""

from __future__ import annotations

from quadcruise._cache import drop_stale_cache as _drop_stale_cache
from quadcruise._version import __version__

_drop_stale_cache()                      # before anything compiles: see quadcruise._cache

from quadcruise.errors import InputError
from quadcruise.model.vehicle import Vehicle
from quadcruise.sim.engine import Limits, simulate, time_grid
from quadcruise.sim.result import SimResult
from quadcruise.sim.status import STATUS_REASONS, ExitStatus
from quadcruise.workflows.compare import Comparison, compare
from quadcruise.workflows.fly import fly
from quadcruise.workflows.replay import DutySchedule, read_duty_csv, replay, write_states_csv

__all__ = [
    "Comparison", "DutySchedule", "ExitStatus", "InputError", "Limits", "STATUS_REASONS", "SimResult", "Vehicle", "__version__",
    "compare", "fly", "read_duty_csv", "replay", "simulate", "time_grid", "write_states_csv",
]


def __getattr__(name: str):
    """``qc.tune``: the tuning package (:mod:`quadcruise.tune`; its entry point ``qc.tune.tune``),
    imported on first use so that ``import quadcruise`` does not load scipy's optimiser."""
    if name == "tune":
        import importlib

        return importlib.import_module("quadcruise.tune")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

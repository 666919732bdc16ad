"""quadcruise: quadrotor cruise control, from the paper's decoupling + nonlinear PD design
to batched simulation, metrics and robustness studies.

Data flows one way: parameters -> model -> controllers -> engine -> results -> metrics ->
plots, report, CLI.
"""

from __future__ import annotations

from importlib import metadata as _metadata

try:
    __version__ = _metadata.version("quadcruise")
except _metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0+unknown"

from ._cache import drop_stale_cache as _drop_stale_cache  # noqa: E402

_drop_stale_cache()                      # before anything compiles: see quadcruise._cache

from .engine import Limits, simulate, time_grid  # noqa: E402
from .errors import InputError  # noqa: E402
from .flight import fly  # noqa: E402
from .params import Vehicle  # noqa: E402
from .replay import DutySchedule, read_duty_csv, replay, write_states_csv  # noqa: E402
from .result import SimResult  # noqa: E402

__all__ = [
    "DutySchedule", "InputError", "Limits", "SimResult", "Vehicle", "__version__",
    "fly", "read_duty_csv", "replay", "simulate", "time_grid", "write_states_csv",
]

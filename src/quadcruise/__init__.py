"""quadcruise: quadrotor cruise control, from the paper's decoupling + nonlinear PD design
to batched simulation, metrics and robustness studies.

Data flows one way: parameters -> model -> controllers -> engine -> results -> metrics ->
plots, report, CLI.

The names below are imported on first use (``qc.fly``, ``from quadcruise import fly``):
``import quadcruise`` alone loads neither numba nor the engine, whose compiled code numba
loads from its cache or, the first time, compiles. So the command line can say that it is
compiling before it does (:mod:`quadcruise.cli.feedback`), and ``quadcruise --help`` is quick.
"""

from __future__ import annotations

import os as _os
import sys as _sys


def _quit_on_interrupt(signum, frame):  # pragma: no cover - runs in a command's first instants
    _sys.stderr.write("error: interrupted\n")
    _sys.stderr.flush()
    _os._exit(130)  # 128 + SIGINT, as a command's own Ctrl-C (quadcruise.cli.faults)


def _command_starting() -> bool:
    """Whether this process is the ``quadcruise`` command: its script, or ``python -m quadcruise``."""
    module = _sys.modules.get("__main__")
    main = getattr(module, "__file__", None) or ""
    if getattr(module, "__name__", "") == "__main__" and _os.path.basename(main).lower() in (
        "quadcruise",
        "quadcruise-script.py",
    ):
        return True  # not a worker process it spawns (multiprocessing names its copy __mp_main__)
    argv = list(getattr(_sys, "orig_argv", ()))
    return "-m" in argv and argv[argv.index("-m") + 1 : argv.index("-m") + 2] == ["quadcruise"]


if _command_starting():
    # Ctrl-C while the command loads (numba, pandas, matplotlib: a few tenths of a second) is one
    # line and status 130, not a traceback of imports; cli.main.run puts Python's handler back
    import signal as _signal

    _signal.signal(_signal.SIGINT, _quit_on_interrupt)

import importlib  # noqa: E402 - after Ctrl-C is answered
from typing import TYPE_CHECKING  # noqa: E402

from quadcruise._cache import check_before_compiled_code as _check_before_compiled_code  # noqa: E402
from quadcruise._version import __version__  # noqa: E402
from quadcruise.errors import InputError  # noqa: E402

_check_before_compiled_code()  # numba's stale cache dropped when compiled code is first imported

if TYPE_CHECKING:  # what the names are, for readers and type checkers
    from quadcruise.model.vehicle import Vehicle
    from quadcruise.sim.flight import simulate
    from quadcruise.sim.inputs import Limits, time_grid
    from quadcruise.sim.result import SimResult
    from quadcruise.sim.status import STATUS_REASONS, ExitStatus
    from quadcruise.sysid.api import identify
    from quadcruise.sysid.result import IdentifyResult
    from quadcruise.workflows.commands import CommandSchedule, read_commands
    from quadcruise.workflows.compare import Comparison, compare
    from quadcruise.workflows.fly import fly
    from quadcruise.workflows.replay import (
        DutySchedule,
        SpeedSchedule,
        read_duty_csv,
        read_speed_csv,
        replay,
        replay_rotors,
        write_rotor_states_csv,
        write_states_csv,
    )

_LAZY = {
    "quadcruise.model.vehicle": ("Vehicle",),
    "quadcruise.sim.flight": ("simulate",),
    "quadcruise.sim.inputs": ("Limits", "time_grid"),
    "quadcruise.sim.result": ("SimResult",),
    "quadcruise.sim.status": ("STATUS_REASONS", "ExitStatus"),
    "quadcruise.sysid.api": ("identify",),
    "quadcruise.sysid.result": ("IdentifyResult",),
    "quadcruise.workflows.compare": ("Comparison", "compare"),
    "quadcruise.workflows.fly": ("fly",),
    "quadcruise.workflows.commands": ("CommandSchedule", "read_commands"),
    "quadcruise.workflows.replay": (  # replay and write_states_csv; the others deprecated aliases
        "DutySchedule",
        "SpeedSchedule",
        "read_duty_csv",
        "read_speed_csv",
        "replay",
        "replay_rotors",
        "write_rotor_states_csv",
        "write_states_csv",
    ),
}
_HOME = {name: module for module, names in _LAZY.items() for name in names}

__all__ = [
    "CommandSchedule",
    "Comparison",
    "DutySchedule",
    "ExitStatus",
    "IdentifyResult",
    "InputError",
    "Limits",
    "STATUS_REASONS",
    "SimResult",
    "SpeedSchedule",
    "Vehicle",
    "__version__",
    "compare",
    "fly",
    "identify",
    "read_commands",
    "read_duty_csv",
    "read_speed_csv",
    "replay",
    "replay_rotors",
    "simulate",
    "time_grid",
    "write_rotor_states_csv",
    "write_states_csv",
]


def __getattr__(name: str):
    """A re-exported name, imported from its module on first use and kept.

    Parameters
    ----------
    name : str
        One of ``__all__``.

    Returns
    -------
    object
        The function, class or constant of that name.

    Raises
    ------
    AttributeError
        For a name the package does not export.
    """
    if name == "tune":  # the tuning package: qc.tune.tune(...)
        value = importlib.import_module("quadcruise.tune")
        globals()[name] = value
        return value
    module = _HOME.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names, the lazily imported ones included.

    Returns
    -------
    list of str
    """
    return sorted(set(globals()) | set(__all__) | {"tune"})

"""The controllers known by name: each declared once, by :func:`register_controller`, and then
flown by that name in ``fly``, ``compare``, ``tune``, ``montecarlo``, the command line and the
Gymnasium environments.

A declaration holds the name, the class (or ``"module:Class"``, imported on first use), the
design of its gains for a rotor-plant vehicle (a function of the motor bandwidth w [rad/s]
giving the fields to replace), whether the gym scores it as a baseline policy, and whether
``compare`` flies it by default. The built-in ones are declared at the end of this module;
a user's own, anywhere before it is flown (docs/extending.md), or by a package's entry point
in the group ``quadcruise.controllers`` (loaded on the first look-up by name).

Examples
--------
>>> controller_names()[:4]
('nlpd', 'gonzalez', 'se3', 'cascade')
>>> declared("se3").rotor_design(80.0)["attitude"].kp      # (0.6 x 80 rad/s)^2
2304.0
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any, NamedTuple

from quadcruise.errors import InputError

__all__ = [
    "ControllerEntry",
    "ENTRY_POINT_GROUP",
    "baseline_names",
    "compared_names",
    "controller_names",
    "declared",
    "register_controller",
    "rotor_gains",
    "unregister_controller",
]

ENTRY_POINT_GROUP = "quadcruise.controllers"
"""The entry-point group whose modules are imported on the first look-up by name: an installed
package declares its controllers there (``[project.entry-points."quadcruise.controllers"]``,
``mine = "mypackage.controllers"``), and its module calls :func:`register_controller`."""

Design = Callable[[float], Mapping[str, Any]]


class ControllerEntry(NamedTuple):
    """One declared controller.

    Parameters
    ----------
    name : str
        The name it is flown by.
    cls : type or str
        Its class, or ``"module:Class"`` imported on first use; called without arguments it
        gives the controller with its default gains.
    rotor_design : callable or None
        ``design(w)`` for a motor bandwidth w [rad/s]: a mapping of field name to value that
        replaces the default's (``dataclasses.replace``) for a rotor-plant vehicle; None: the
        controller flies no rotor-plant vehicle by name.
    baseline : bool
        Scored by :func:`quadcruise.gym.evaluate.baselines` by default.
    compared : bool
        Flown by :func:`quadcruise.compare` and ``quadcruise compare`` by default.
    """

    name: str
    cls: Any
    rotor_design: Design | None = None
    baseline: bool = False
    compared: bool = False

    def load(self) -> type:
        """The class (imported on first use).

        Returns
        -------
        type
        """
        cls = self.cls
        if isinstance(cls, str):
            module, _, attr = cls.partition(":")
            cls = getattr(importlib.import_module(module), attr)
        _check_name(self.name, cls)
        return cls


_ENTRIES: dict[str, ControllerEntry] = {}
_PLUGINS_LOADED = [False]


def register_controller(
    name: str,
    cls: Any,
    *,
    rotor_design: Design | None = None,
    baseline: bool = False,
    compared: bool = False,
    replace: bool = False,
) -> ControllerEntry:
    """Declare a controller: from then on it flies by ``name`` everywhere a name is taken.

    Parameters
    ----------
    name : str
        The name (letters, digits, ``_`` and ``-``).
    cls : type or str
        The controller's class (``cls()`` is the controller with its default gains; its
        dataclass fields are the parameters a scenario's ``[controller]`` table sets), or
        ``"module:Class"``.
    rotor_design : callable, optional
        ``design(w)`` -> {field: value} for a motor bandwidth w [rad/s]; without it the name
        is refused on a rotor-plant vehicle (a controller object is still flown as given).
    baseline : bool
        A default baseline policy of :func:`quadcruise.gym.evaluate.baselines`.
    compared : bool
        One of the controllers :func:`quadcruise.compare` flies by default.
    replace : bool
        Allow a name already declared to be declared again.

    Returns
    -------
    ControllerEntry

    Raises
    ------
    InputError
        A bad name, a name already declared (without ``replace``), a ``cls`` that is neither
        a class nor ``"module:Class"``, or a ``rotor_design`` that is not callable.

    Examples
    --------
    >>> register_controller("nlpd", "quadcruise.control.position:NLPD")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: controller 'nlpd' is already declared (register_controller(..., replace=True) ...
    """
    if not isinstance(name, str) or not name or not name.replace("_", "").replace("-", "").isalnum():
        raise InputError(f"register_controller: the name must be letters, digits, '_' or '-', got {name!r}")
    if name in _ENTRIES and not replace:
        raise InputError(
            f"controller {name!r} is already declared (register_controller(..., replace=True) declares it again)"
        )
    if not (isinstance(cls, type) or (isinstance(cls, str) and ":" in cls)):
        raise InputError(f"register_controller {name!r}: cls must be a class or 'module:Class', got {cls!r}")
    if rotor_design is not None and not callable(rotor_design):
        raise InputError(f"register_controller {name!r}: rotor_design must be callable(w) or None")
    if isinstance(cls, type):
        _check_name(name, cls)
    entry = ControllerEntry(name, cls, rotor_design, bool(baseline), bool(compared))
    _ENTRIES[name] = entry
    return entry


def unregister_controller(name: str) -> ControllerEntry:
    """Take back a declaration (a test's, a notebook's).

    Parameters
    ----------
    name : str
        A declared controller.

    Returns
    -------
    ControllerEntry
        What was declared (``register_controller(**entry._asdict())`` declares it again).

    Raises
    ------
    InputError
        A name not declared.
    """
    declared(name)
    return _ENTRIES.pop(name)


def _check_name(name: str, cls: type) -> None:
    """A controller records its class's ``name``: it must be the name it is declared by (a
    subclass that kept its parent's would be flown, designed and reported as the parent)."""
    if getattr(cls, "name", None) != name:
        raise InputError(
            f"register_controller {name!r}: {cls.__name__}.name is {getattr(cls, 'name', None)!r}; "
            f"give the class `name = {name!r}` (the name its flights record)"
        )


def _load_plugins() -> None:
    if _PLUGINS_LOADED[0]:
        return
    _PLUGINS_LOADED[0] = True
    from importlib.metadata import entry_points

    for point in entry_points(group=ENTRY_POINT_GROUP):
        try:
            point.load()
        except Exception as exc:  # noqa: BLE001 - an installed package's fault, said in one line
            raise InputError(
                f"the {ENTRY_POINT_GROUP} entry point {point.name!r} ({point.value}) failed to load: "
                f"{type(exc).__name__}: {exc}"
            ) from exc


def controller_names() -> tuple[str, ...]:
    """Every declared controller's name, in the order declared.

    Returns
    -------
    tuple of str
    """
    _load_plugins()
    return tuple(_ENTRIES)


def declared(name: str) -> ControllerEntry:
    """The declaration of ``name``.

    Parameters
    ----------
    name : str

    Returns
    -------
    ControllerEntry

    Raises
    ------
    InputError
        A name not declared (the message lists those that are).
    """
    _load_plugins()
    if name not in _ENTRIES:
        raise InputError(f"unknown controller {name!r}; choose one of {', '.join(_ENTRIES)}")
    return _ENTRIES[name]


def baseline_names() -> tuple[str, ...]:
    """The controllers the gym scores as baseline policies by default.

    Returns
    -------
    tuple of str
    """
    return tuple(n for n in controller_names() if _ENTRIES[n].baseline)


def compared_names() -> tuple[str, ...]:
    """The controllers ``compare`` flies by default.

    Returns
    -------
    tuple of str
    """
    return tuple(n for n in controller_names() if _ENTRIES[n].compared)


def rotor_gains(name: str, bandwidth: float) -> dict[str, Any]:
    """The fields of controller ``name`` designed for a rotor-plant vehicle's motor bandwidth.

    Parameters
    ----------
    name : str
        A declared controller.
    bandwidth : float
        The motor bandwidth w [rad/s] (1 / tau_up of the vehicle's paper equivalent).

    Returns
    -------
    dict
        Field name -> value, to replace in the default controller.

    Raises
    ------
    InputError
        An unknown name, or a controller declared without ``rotor_design``.
    """
    entry = declared(name)
    if entry.rotor_design is None:
        raise InputError(
            f"controller {name!r} has no design for a rotor-plant vehicle (register_controller(..., "
            "rotor_design=...)); fly it as an object with the gains you want, or on a paper Vehicle"
        )
    return dict(entry.rotor_design(bandwidth))


# --- the built-in controllers --------------------------------------------------------------
def _pid_design(w: float) -> dict[str, Any]:
    from quadcruise.control.design import attitude_pid_design

    return {"attitude": attitude_pid_design(w), "yaw": attitude_pid_design(w)}


def _se3_design(w: float) -> dict[str, Any]:
    from quadcruise.control.se3 import se3_attitude_design

    return {"attitude": se3_attitude_design(w)}


def _cascade_design(w: float) -> dict[str, Any]:
    from quadcruise.control.cascade import rate_pid_design

    return {"rate": rate_pid_design(w), "yaw_rate": rate_pid_design(w, yaw=True)}


def _px4_design(w: float) -> dict[str, Any]:
    """PX4's defaults on a rotor-plant vehicle: the rate gains designed for its lag, the hover
    thrust from its weight (``MPC_THR_MIN`` at most half of it), its thrust per command u^2
    (speed u w_max) and PX4's thrust model matched to it (``THR_MDL_FAC`` = 1)
    (:mod:`quadcruise.control.px4`)."""
    from quadcruise.io.px4params import Px4Parameters

    params = Px4Parameters.defaults().with_values(THR_MDL_FAC=1.0)
    return {"params": params, "rate_bandwidth": w, "hover_from_vehicle": True, "thrust_curve": 1.0}


for _name, _cls, _design in (
    ("nlpd", "quadcruise.control.position:NLPD", _pid_design),
    ("gonzalez", "quadcruise.control.baselines:Gonzalez", _pid_design),
    ("se3", "quadcruise.control.se3:SE3", _se3_design),
    ("cascade", "quadcruise.control.cascade:Cascade", _cascade_design),
):
    register_controller(_name, _cls, rotor_design=_design, baseline=True, compared=True)
register_controller("px4", "quadcruise.control.px4:Px4", rotor_design=_px4_design)

"""Controllers: compiled functions with the engine's controller signature, and their design.

Built-in controllers by name (see :func:`controller_from_name`):

- ``nlpd``: the paper's inverse-model nonlinear PD over decoupled attitude PID.
- ``gonzalez``: a reconstruction of the paper's baseline [5]: saturated (tanh) PD with the
  small-angle attitude mapping over the same attitude PID (see :mod:`.baselines`).
- ``se3``: geometric tracking control on SE(3) (Lee, Leok, McClamroch 2010), as RotorPy
  flies it, with the paper's position poles (see :mod:`.se3`).
- ``cascade``: a PX4-style multicopter cascade, P position, PID velocity, P attitude, PID
  body rate, with PX4's default gains and rate gains designed for the rotor lag (see
  :mod:`.cascade`).

The ``nlpd`` module (:mod:`.position`) is imported with this package, and so compiled (or
loaded from numba's cache) with it; each other controller module is imported only when its
controller is first asked for, so flying ``nlpd`` never pays for the others.

Each is declared once in :mod:`.registry` (name, class, design for a rotor-plant vehicle,
gym baseline, compared by default); a user's own controller is declared the same way, with
:func:`register_controller`, and then flies by name everywhere (docs/extending.md).
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Mapping
from typing import Any

import numpy as np

from quadcruise import checks
from quadcruise.control import registry
from quadcruise.control.base import Controller
from quadcruise.control.position import NLPD
from quadcruise.control.registry import register_controller
from quadcruise.errors import InputError
from quadcruise.model.vehicle import shared_default
from quadcruise.protocols import ControllerLike


class _Registry(Mapping):
    """Controller name -> class, as declared in :mod:`quadcruise.control.registry` (each module
    imported on first use)."""

    def __getitem__(self, name: str) -> type[Controller]:
        if name not in self:
            raise KeyError(name)
        return registry.declared(name).load()

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in registry.controller_names()

    def __iter__(self):
        return iter(registry.controller_names())

    def __len__(self) -> int:
        return len(registry.controller_names())


CONTROLLERS: Mapping[str, type[Controller]] = _Registry()


def controller_from_name(name: str, **params: Any) -> Controller:
    """A built-in controller by name, with optional parameters.

    Parameters
    ----------
    name : str
        A key of :data:`CONTROLLERS`: 'nlpd', 'gonzalez', 'se3', 'cascade', 'px4', or one declared by
        :func:`~quadcruise.control.registry.register_controller`.
    **params : Any
        Parameters of that controller (its dataclass fields), in their units: gain sets
        such as ``position`` (a :class:`~quadcruise.control.design.PDGains`, kp [1/s^2],
        kd [1/s]), limits such as ``max_tilt`` [rad], switches such as ``accel_feedforward``.

    Returns
    -------
    Controller
        The controller; without parameters, the class's shared default instance
        (:func:`quadcruise.model.vehicle.shared_default`).

    Raises
    ------
    InputError
        An unknown name or parameter, or a bad value.

    Examples
    --------
    >>> controller_from_name("nlpd", max_tilt=0.5).max_tilt
    0.5
    >>> controller_from_name("pid")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: unknown controller 'pid'; choose one of nlpd, gonzalez, se3, cascade, px4
    """
    if name not in CONTROLLERS:
        raise InputError(f"unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}")
    cls = CONTROLLERS[name]
    known = [f.name for f in dataclasses.fields(cls)]
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise InputError(f"{name} has no parameter {unknown[0]!r}; its parameters: {', '.join(known)}")
    return cls(**params) if params else shared_default(cls)


def as_controller(obj: Any, where: str = "fly()") -> ControllerLike:
    """A controller from a name or any object that offers what the engine needs.

    Parameters
    ----------
    obj : str or ControllerLike
        A built-in controller's name (see :data:`CONTROLLERS`), or an object with ``name``,
        ``function`` (compiled with :data:`quadcruise.layout.CONTROLLER_SIG`), ``gains()`` and
        ``memory()`` (see :class:`quadcruise.protocols.ControllerLike`); it need not subclass
        :class:`Controller`. Its ``function`` must be compiled with ``CONTROLLER_SIG``.
    where : str
        The function that was given it, for the message.

    Returns
    -------
    ControllerLike

    Raises
    ------
    ArgumentTypeError
        Anything else: a class, an object that lacks one of the four, or whose ``function``
        is not compiled with ``CONTROLLER_SIG`` (the message shows how to compile it).
    InputError
        An unknown name.

    Examples
    --------
    >>> as_controller("nlpd").name
    'nlpd'
    >>> as_controller(3.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.ArgumentTypeError: fly() argument controller must be a name (nlpd, gonzalez, se3, ...
    """
    if isinstance(obj, str):
        return controller_from_name(obj)
    if inspect.isclass(obj) or not isinstance(obj, ControllerLike) or not callable(getattr(obj, "function", None)):
        checks.fail(
            where,
            "controller",
            obj,
            f"a name ({', '.join(CONTROLLERS)}) or an object with name, function, "
            "gains() and memory() (quadcruise.protocols.ControllerLike)",
        )
    if not compiled_for_engine(obj.function):
        checks.fail(
            where,
            "controller",
            obj,
            "an object whose function is compiled with CONTROLLER_SIG",
            hint=f"its function {getattr(obj.function, '__name__', '?')!r} is {_compiled_how(obj.function)}: "
            "compile it with `from numba import njit; from quadcruise.layout import CONTROLLER_SIG` "
            "and `@njit(CONTROLLER_SIG, cache=True)` above its def",
        )
    return obj


def compiled_for_engine(function: Any) -> bool:
    """Whether ``function`` is a numba-compiled function the engine can call: a dispatcher
    holding a compiled :data:`~quadcruise.layout.CONTROLLER_SIG`, or one that compiles for it
    (an ``@njit`` without a signature, compiled here), or a compiled function type.

    Parameters
    ----------
    function : Any
        A controller's ``function``.

    Returns
    -------
    bool

    Examples
    --------
    >>> from quadcruise.control import NLPD
    >>> compiled_for_engine(NLPD().function), compiled_for_engine(print)
    (True, False)
    """
    from quadcruise.layout import CONTROLLER_SIG

    signatures = getattr(function, "signatures", None)
    if signatures is not None and hasattr(function, "py_func"):
        if tuple(CONTROLLER_SIG.args) in [tuple(sig) for sig in signatures]:
            return True
        try:  # an @njit without a signature compiles on first use: do it now
            function.compile(CONTROLLER_SIG)
        except Exception:  # noqa: BLE001 - numba's typing errors: it cannot take the signature
            return False
        return True
    return hasattr(function, "_numba_type_") or hasattr(function, "address")  # a cfunc or a wrapped pointer


def _compiled_how(function: Any) -> str:
    if hasattr(function, "py_func"):
        return (
            "compiled by numba without CONTROLLER_SIG (its signatures: "
            f"{', '.join(str(s) for s in function.signatures) or 'none yet'})"
        )
    plain = inspect.isfunction(function) or inspect.ismethod(function)
    return "a plain Python function" if plain else f"a {type(function).__name__}"


def controller_record(controller: ControllerLike) -> dict:
    """What a result records of a controller: its ``to_dict()`` if it has one, else its name,
    gains and memory size.

    Parameters
    ----------
    controller : ControllerLike

    Returns
    -------
    dict
        Plain values (JSON-ready).
    """
    to_dict = getattr(controller, "to_dict", None)
    if callable(to_dict):
        return to_dict()
    return {
        "name": str(controller.name),
        "gains": [float(g) for g in np.asarray(controller.gains()).ravel()],
        "memory_size": int(np.asarray(controller.memory()).size),
    }


def __getattr__(name: str):
    """``from quadcruise.control import Gonzalez`` etc. without importing them eagerly."""
    for key in registry.controller_names():
        cls = registry.declared(key).cls
        if (cls.rpartition(":")[2] if isinstance(cls, str) else cls.__name__) == name:
            return CONTROLLERS[key]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "CONTROLLERS",
    "NLPD",
    "Gonzalez",
    "SE3",
    "Cascade",
    "Controller",
    "ControllerLike",
    "as_controller",
    "compiled_for_engine",
    "controller_from_name",
    "controller_record",
    "register_controller",
]

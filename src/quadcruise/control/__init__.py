"""Controllers: compiled functions with the engine's controller signature, and their design.

Built-in controllers by name (see :func:`controller_from_name`):

- ``nlpd``: the paper's inverse-model nonlinear PD over decoupled attitude PID.
- ``gonzalez``: a reconstruction of the paper's baseline [5]: saturated (tanh) PD with the
  small-angle attitude mapping over the same attitude PID (see :mod:`.baselines`).
- ``se3``: geometric tracking control on SE(3) (Lee, Leok, McClamroch 2010), as RotorPy
  flies it, with the paper's position poles (see :mod:`.modern`).
- ``cascade``: a PX4-style multicopter cascade, P position, PID velocity, P attitude, PID
  body rate, with PX4's default gains and rate gains designed for the rotor lag (see
  :mod:`.modern` and :mod:`.px4`).

Each controller module is imported, and so compiled (or loaded from numba's cache), only
when its controller is first asked for, so flying one controller never pays for the others.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from typing import Any

from quadcruise.control.base import Controller
from quadcruise.control.position import NLPD
from quadcruise.errors import InputError
from quadcruise.model.vehicle import shared_default


class _Registry(Mapping):
    """Controller name -> class, importing each module on first use."""

    _where = {"nlpd": ("quadcruise.control.position", "NLPD"), "gonzalez": ("quadcruise.control.baselines", "Gonzalez"),
              "se3": ("quadcruise.control.se3", "SE3"), "cascade": ("quadcruise.control.cascade", "Cascade")}

    def __getitem__(self, name: str) -> type[Controller]:
        module, attr = self._where[name]
        return getattr(importlib.import_module(module), attr)

    def __iter__(self):
        return iter(self._where)

    def __len__(self) -> int:
        return len(self._where)


CONTROLLERS: Mapping[str, type[Controller]] = _Registry()


def controller_from_name(name: str, **params: Any) -> Controller:
    """A built-in controller by name, with optional parameters."""
    if name not in CONTROLLERS:
        raise InputError(f"unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}")
    return CONTROLLERS[name](**params) if params else shared_default(CONTROLLERS[name])


def __getattr__(name: str):
    """``from quadcruise.control import Gonzalez`` etc. without importing them eagerly."""
    for key, (_, attr) in _Registry._where.items():
        if attr == name:
            return CONTROLLERS[key]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["CONTROLLERS", "NLPD", "Gonzalez", "SE3", "Cascade", "Controller", "controller_from_name"]

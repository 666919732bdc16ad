"""Controllers: compiled functions with the engine's controller signature, and their design.

Built-in controllers by name (see :func:`controller_from_name`):

- ``nlpd``: the paper's inverse-model nonlinear PD over decoupled attitude PID.
- ``gonzalez``: a reconstruction of the paper's baseline [5]: saturated (tanh) PD with the
  small-angle attitude mapping over the same attitude PID (see :mod:`.baselines`).
"""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from .base import Controller
from .baselines import Gonzalez
from .position import NLPD

CONTROLLERS: dict[str, type[Controller]] = {NLPD.name: NLPD, Gonzalez.name: Gonzalez}


def controller_from_name(name: str, **params: Any) -> Controller:
    """A built-in controller by name, with optional parameters."""
    try:
        cls = CONTROLLERS[name]
    except KeyError:
        raise InputError(f"unknown controller {name!r}; choose one of {', '.join(CONTROLLERS)}") from None
    return cls(**params)


__all__ = ["CONTROLLERS", "NLPD", "Gonzalez", "Controller", "controller_from_name"]

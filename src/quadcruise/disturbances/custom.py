"""A user's own disturbance: any compiled function with ``DISTURBANCE_SIG``, its parameter row and
its initial memory, handed to :func:`quadcruise.fly` as ``environment=`` like an Environment."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.fields import Check, Validated, unit_field

__all__ = ["CustomDisturbance"]


def _numbers(value: Any) -> bool:
    """Whether ``value`` is a number, a row or (N, P) rows of numbers, not empty."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        return False
    return a.dtype.kind in "iuf" and a.ndim <= 2 and a.size > 0


_COMPILED = Check("compiled", "a numba-compiled function with DISTURBANCE_SIG", lambda f: hasattr(f, "py_func"))
_ROWS = Check("rows", "numbers: one row for every vehicle or (N, P) rows, not empty", _numbers)


@dataclass(frozen=True)
class CustomDisturbance(Validated):
    """A compiled disturbance of the user's.

    Parameters
    ----------
    function : numba dispatcher
        Compiled with :data:`quadcruise.layout.DISTURBANCE_SIG`: ``f(t, dt, x, dp, dmem, rng, ext)``.
    params : array_like
        Its parameter row ``dp`` (one row for every vehicle, or (N, P) rows).
    memory : array_like
        Its initial state ``dmem`` (one row for every vehicle, or (N, M) rows); at least one entry.

    Examples
    --------
    >>> from numba import njit
    >>> import quadcruise as qc
    >>> from quadcruise.layout import DISTURBANCE_SIG, EXT_E1, EXT_FX, EXT_SIZE
    >>> @njit(DISTURBANCE_SIG)
    ... def push(t, dt, x, dp, dmem, rng, ext):
    ...     for j in range(EXT_SIZE):
    ...         ext[j] = 1.0 if j >= EXT_E1 else 0.0
    ...     ext[EXT_FX] = dp[0]                      # a steady push in x [N]
    >>> res = qc.fly("hover", duration=2.0, environment=CustomDisturbance(push, params=[1.0]))
    >>> bool(res.states[0, -1, 0] > 0.0)
    True
    >>> CustomDisturbance(print)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: custom disturbance field 'function' (the compiled disturbance, -) must be a ...
    """

    function: Any = unit_field(unit="-", doc="the compiled disturbance", check=_COMPILED)
    params: Any = unit_field((0.0,), "-", "its parameter row dp", _ROWS)
    memory: Any = unit_field((0.0,), "-", "its initial state dmem", _ROWS)
    name = "custom disturbance"

    @property
    def parts(self) -> dict:
        """Always present (an Environment's empty parts mean still air)."""
        return {"custom": self}

    def kwargs(self, n: int | None = None) -> dict:
        """``disturbance``, ``disturbance_params`` and ``disturbance_memory`` for :func:`quadcruise.simulate`.

        Parameters
        ----------
        n : int, optional
            Number of vehicles (unused: the engine hands one row to every vehicle).

        Returns
        -------
        dict
        """
        dp = np.ascontiguousarray(np.atleast_1d(np.asarray(self.params, dtype=float)))
        dm = np.ascontiguousarray(np.atleast_1d(np.asarray(self.memory, dtype=float)))
        return {"disturbance": self.function, "disturbance_params": dp, "disturbance_memory": dm}

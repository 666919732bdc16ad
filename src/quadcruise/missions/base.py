"""What every mission kind shares: validation of its fields (:mod:`quadcruise.fields`), its
parameter vector ``mp``, its reference at given times, and the stacking of a batch's rows.

A kind sets ``name``, ``columns`` (names of the mp entries), ``function`` (the compiled
reference with ``MISSION_SIG``, as a staticmethod) and ``_row()`` (the mp entries in order).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numba import njit, types

from quadcruise.errors import InputError
from quadcruise.fields import Validated
from quadcruise.layout import REF_SIZE, MissionType

__all__ = ["Mission", "check_names", "stack_params"]


@njit(types.void(MissionType, types.float64[::1], types.float64[::1], types.float64[:, ::1]), cache=True)
def _evaluate(fn, ts, mp, out):
    for i in range(ts.shape[0]):
        fn(ts[i], mp, out[i])


@dataclass(frozen=True)
class Mission(Validated):
    """Shared code of every mission kind: validation (its fields come from
    :func:`quadcruise.fields.unit_field`, checked by :func:`quadcruise.fields.validate`),
    ``units``, ``params``, ``reference``, ``to_dict``.

    A subclass sets ``name``, ``columns`` (names of the mp entries), ``function`` (the
    compiled reference, as a staticmethod) and ``_row()`` (the mp entries in order).

    Examples
    --------
    >>> from quadcruise.missions import Step
    >>> Step.units()["time"], Step(axis="yaw").axis
    ('s', 'yaw')
    >>> Step(axis="w")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: step field 'axis' (stepped axis, -) must be one of x, y, z, yaw, got 'w'
    """

    name: ClassVar[str] = ""
    columns: ClassVar[tuple] = ()

    def _row(self) -> tuple:
        raise NotImplementedError

    @property
    def duration(self) -> float:
        """The default flight time [s]: 5 s here; one lap, the step and 10 s after it, or
        the last waypoint and a settling time in the kinds that know better."""
        return 5.0

    def params(self) -> np.ndarray:
        """The mission's parameter vector mp, laid out as ``columns``.

        Returns
        -------
        numpy.ndarray
            1-D float64, C-contiguous: the entries of ``_row()`` in order, in the units of
            the fields they come from.
        """
        return np.ascontiguousarray(self._row(), dtype=np.float64)

    def reference(self, t: Any) -> np.ndarray:
        """The reference at given times, from the compiled function.

        Parameters
        ----------
        t : float or array_like
            Time or 1-D array of times [s], all finite.

        Returns
        -------
        numpy.ndarray
            Shape (len(t), REF_SIZE) (one row for a scalar ``t``): position [m], velocity
            [m/s], acceleration [m/s^2], yaw [rad] and yaw rate [rad/s], in the columns of
            :mod:`quadcruise.layout` (``REF_X`` ... ``REF_PSI_DOT``).

        Raises
        ------
        InputError
            ``t`` is not a scalar or 1-D array of finite numbers.
        """
        ts = np.array(np.atleast_1d(t), dtype=np.float64)  # a writable C-ordered copy
        if ts.ndim != 1 or not np.all(np.isfinite(ts)):
            raise InputError("mission reference times must be a 1-D array of finite numbers")
        out = np.empty((ts.shape[0], REF_SIZE))
        _evaluate(self.function, ts, self.params(), out)
        return out

    def replace(self, **changes: Any) -> Mission:
        """A copy with some fields changed (validated again).

        Parameters
        ----------
        **changes : Any
            Field name -> new value, in the field's unit.

        Returns
        -------
        Mission
            A new mission of the same kind.

        Raises
        ------
        InputError
            A name that is not a field of this kind, or a bad value.
        """
        check_names(type(self), changes)
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict:
        """The mission as plain values, for result bundles (read back by
        :func:`quadcruise.missions.mission_from_dict`).

        Returns
        -------
        dict
            ``{'kind': name, field: value, ...}``, tuple fields as lists.
        """
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {"kind": self.name, **{k: list(v) if isinstance(v, tuple) else v for k, v in values.items()}}


def check_names(cls: type, kw: dict) -> None:
    """Refuse keys that are not fields of a mission kind.

    Parameters
    ----------
    cls : type
        A mission class (a subclass of :class:`Mission`).
    kw : dict
        Field name -> value; only the keys are checked.

    Raises
    ------
    InputError
        Naming every key of ``kw`` that is not a field of ``cls``.

    Examples
    --------
    >>> from quadcruise.missions import Circle
    >>> check_names(Circle, {"radius": 1.0})
    >>> check_names(Circle, {"radiu": 1.0})
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: unknown circle field(s): radiu
    """
    unknown = set(kw) - {f.name for f in dataclasses.fields(cls)}
    if unknown:
        raise InputError(f"unknown {cls.name} field(s): {', '.join(sorted(unknown))}")


def stack_params(missions: Mission | Sequence[Mission], n: int | None = None) -> np.ndarray:
    """The (N, M) mp array of a batch: one row per mission, all of the same kind.

    A single mission (or a list of one) is broadcast to ``n`` rows when ``n`` is given.
    Rows of different lengths (waypoint tables of different sizes) are padded with zeros.

    Parameters
    ----------
    missions : Mission or sequence of Mission
        One mission, or one per vehicle, all of one kind.
    n : int, optional
        Number of vehicles N: a single mission is repeated to N rows; a list of several must
        have N entries. None: one row per mission given.

    Returns
    -------
    numpy.ndarray
        Shape (N, M), float64, C-contiguous; M is the longest mission's ``params()``.

    Raises
    ------
    InputError
        An empty list or one holding something other than missions, missions of different
        kinds, or a list whose length is neither 1 nor ``n``.

    Examples
    --------
    >>> from quadcruise.missions import Circle, Hover
    >>> stack_params([Circle(radius=1.0), Circle(radius=2.0)])[:, 0]
    array([1., 2.])
    >>> stack_params(Hover(), n=3).shape
    (3, 4)
    """
    missions = [missions] if isinstance(missions, Mission) else list(missions)
    if not missions or not all(isinstance(m, Mission) for m in missions):
        raise InputError("stack_params needs a non-empty list of missions")
    kinds = sorted({type(m).name for m in missions})
    if len(kinds) > 1:
        raise InputError(f"a batch flies one mission kind, got {', '.join(kinds)}")
    params = [m.params() for m in missions]
    width = max(p.shape[0] for p in params)  # tables of waypoints differ in length:
    rows = np.zeros((len(params), width))  # pad; each function reads its own count
    for i, p in enumerate(params):
        rows[i, : p.shape[0]] = p
    if n is not None:
        if len(missions) == 1:
            rows = np.repeat(rows, n, axis=0)
        elif len(missions) != n:
            raise InputError(f"{len(missions)} missions given but {n} vehicles were asked for")
    return np.ascontiguousarray(rows)

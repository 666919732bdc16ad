"""What a rotor-plant replay returns: the logged states of N vehicles (quaternion attitude,
rotor speeds), their exit status, and the configuration that produced them.

The attitude is logged as the quaternion; :meth:`RotorResult.euler` gives the ZYX Euler angles
(roll phi, pitch theta, yaw psi, as the paper's plant uses them) beside it, computed by
``scipy.spatial.transform.Rotation``: for reading only, since they are singular at
pitch +-90 degrees where the quaternion is not.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from quadcruise.errors import InputError
from quadcruise.sim.status import ExitStatus

EULER_NAMES = ("phi", "theta", "psi")
"""Columns of :meth:`RotorResult.euler`: roll, pitch, yaw [rad], ZYX convention."""


@dataclass(frozen=True, eq=False)
class RotorResult:
    """Logged open-loop flight of N rotor-plant vehicles.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Logged instants [s].
    states : ndarray, shape (N, L, 13 + n)
        State at each instant (:mod:`quadcruise.model.rotor_plant`; NaN after a vehicle stopped).
    final_state : ndarray, shape (N, 13 + n)
        State when each vehicle finished or stopped.
    status : ndarray of int, shape (N,)
        Exit status code, 0 = finished (:class:`~quadcruise.ExitStatus`).
    t_stop : ndarray, shape (N,)
        Time each vehicle finished or stopped [s].
    names : tuple of str
        The state's column names.
    meta : dict
        The configuration and version that produced the result.
    """

    t: np.ndarray
    states: np.ndarray
    final_state: np.ndarray
    status: np.ndarray
    t_stop: np.ndarray
    names: tuple = ()
    meta: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        """Number of vehicles, N."""
        return self.states.shape[0]

    @property
    def ok(self) -> np.ndarray:
        """(N,) True where the vehicle flew the whole schedule within every bound."""
        return self.status == 0

    def status_text(self, i: int = 0) -> str:
        """Why vehicle i stopped, and when.

        Parameters
        ----------
        i : int
            The vehicle's index.

        Returns
        -------
        str
        """
        status = ExitStatus(int(self.status[i]))
        return status.reason if status.ok else f"{status.reason} at t = {self.t_stop[i]:g} s"

    def state(self, name: str) -> np.ndarray:
        """One state column for every vehicle and instant.

        Parameters
        ----------
        name : str
            A column name (``z``, ``qw``, ``w3``, ...).

        Returns
        -------
        numpy.ndarray
            Shape (N, L), SI units.

        Raises
        ------
        InputError
            A name that is not a column.
        """
        if name not in self.names:
            raise InputError(f"no state column {name!r}; columns: {', '.join(self.names)}")
        return self.states[:, :, self.names.index(name)]

    def euler(self, i: int = 0) -> np.ndarray:
        """Vehicle i's attitude as ZYX Euler angles (roll, pitch, yaw).

        Parameters
        ----------
        i : int
            The vehicle's index.

        Returns
        -------
        numpy.ndarray
            Shape (L, 3): phi, theta, psi [rad]; NaN where the state is.
        """
        q = self.states[i, :, 6:10]
        out = np.full((q.shape[0], 3), np.nan)
        good = np.all(np.isfinite(q), axis=1)
        if good.any():
            out[good] = Rotation.from_quat(q[good], scalar_first=True).as_euler("ZYX")[:, ::-1]
        return out

    def to_pandas(self, vehicle: int | None = None):
        """The log, long-form: one row per vehicle and logged instant (as :meth:`SimResult.to_pandas`).

        An open-loop replay flies no reference, so it has no per-flight metrics.

        Parameters
        ----------
        vehicle : int, optional
            One vehicle's index; default: every vehicle.

        Returns
        -------
        pandas.DataFrame
            Columns ``vehicle``, ``t`` [s], the state's names, ``phi``, ``theta``, ``psi``
            (:meth:`euler`), SI units.
        """
        import pandas as pd

        if vehicle is not None and not 0 <= vehicle < self.n:
            raise InputError(f"vehicle {vehicle} is not in this flight of {self.n} vehicles")
        picks = range(self.n) if vehicle is None else [vehicle]
        rows = np.concatenate([np.column_stack([self.states[i], self.euler(i)]) for i in picks])
        frame = pd.DataFrame(rows, columns=list(self.names) + list(EULER_NAMES))
        frame.insert(0, "t", np.tile(self.t, len(picks)))
        frame.insert(0, "vehicle", np.repeat(np.asarray(list(picks)), len(self.t)))
        return frame

"""The minimum-snap path through a waypoint table (Mellinger and Kumar 2011): 7th-order
segments whose snap integral is least (:func:`minimum_snap_coefficients`, a banded system in
the velocity, acceleration and jerk at each knot), flown by :class:`MinimumSnap`. The table and
the straight legs: :mod:`quadcruise.missions.waypoints`. The parameter layout and the
continuity: docs/missions.md.

Examples
--------
>>> from quadcruise.missions.waypoints import WaypointTable
>>> table = WaypointTable([[0, 0, 1], [2, 0, 1], [2, 1, 1]], speed=[0, 0.5, 0.25])
>>> smooth = MinimumSnap(table)
>>> smooth.reference([0.0, 4.0, 8.0])[:, :3].round(12) + 0.0
array([[0., 0., 1.],
       [2., 0., 1.],
       [2., 1., 1.]])
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Any, ClassVar

import numpy as np
from numba import njit

from quadcruise.layout import REF_AX, REF_PSI, REF_PSI_DOT, REF_SIZE, REF_VX, REF_X
from quadcruise.missions.waypoints import WaypointMission, last_start

__all__ = ["MinimumSnap", "minimum_snap_coefficients"]

_ORDER = 7  # polynomial degree of the minimum-snap segments
_NC = _ORDER + 1

# offsets into the packed parameter vector (mp) that the compiled reference reads
# MinimumSnap: [m, x, y, z, yaw at the end, t at the end, (t_i, T_i, 4 x 8 coefficients) per segment]
MS_M, MS_END, MS_T_END, MS_SEGMENTS = 0, 1, 5, 6  # segments, end point (x, y, z, yaw), end time, first segment
MS_STRIDE = 2 + 4 * _NC  # entries per segment: ...
SEG_T0, SEG_DUR, SEG_COEF = 0, 1, 2  # ... start, duration, coefficients of s^0..s^7 per axis


# --- the compiled reference -----------------------------------------------------------------
@njit(cache=True, error_model="numpy")
def minsnap_ref(t, mp, ref):
    """Minimum-snap reference: the polynomial segments of :func:`minimum_snap_coefficients`.

    Before t = 0, the first point; after the end, the last point, at rest.

    Parameters
    ----------
    t : float
        Time [s].
    mp : numpy.ndarray
        [m, the end's x, y, z [m], yaw [rad], t [s], then per segment t_i, T_i [s] and the 8
        coefficients of s^0..s^7, s = (t - t_i) / T_i, for each of x, y, z, yaw].
    ref : numpy.ndarray
        Output: the reference at ``t`` (``REF_SIZE`` entries, overwritten).
    """
    for i in range(REF_SIZE):
        ref[i] = 0.0
    if t >= mp[MS_T_END]:
        for j in range(3):
            ref[REF_X + j] = mp[MS_END + j]
        ref[REF_PSI] = mp[MS_END + 3]
        return
    off = MS_SEGMENTS + MS_STRIDE * last_start(t, mp, MS_SEGMENTS + SEG_T0, MS_STRIDE, int(mp[MS_M]))
    dur = mp[off + SEG_DUR]
    s = max(t - mp[off + SEG_T0], 0.0) / dur  # before t = 0: the first point, at rest
    for j in range(4):  # Horner for p, p' and p'' / 2 (in s)
        c = off + SEG_COEF + _NC * j  # x, y, z, yaw: coefficients of s^0..s^7
        p, dp, ddp = mp[c + _ORDER], 0.0, 0.0
        for k in range(_ORDER - 1, -1, -1):
            ddp = ddp * s + dp
            dp = dp * s + p
            p = p * s + mp[c + k]
        if j < 3:
            ref[REF_X + j] = p
            ref[REF_VX + j] = dp / dur
            ref[REF_AX + j] = 2.0 * ddp / (dur * dur)
        else:
            ref[REF_PSI] = p
            ref[REF_PSI_DOT] = dp / dur


# --- minimum snap: the KKT system ------------------------------------------------------------
def _derivative_row(r: int, s: float) -> np.ndarray:
    """d^r/ds^r of (1, s, ..., s^7) at s."""
    return np.array([math.perm(k, r) * s ** max(k - r, 0) for k in range(_NC)], dtype=float)


def _hermite_matrices() -> tuple[np.ndarray, np.ndarray]:
    """(Minv, K), computed exactly in rationals and rounded once: Minv turns the value and the
    first three s-derivatives at s = 0 and at s = 1 (in that order) into the coefficients of
    s^0..s^7; K = Minv^T H Minv is a segment's snap cost in those end values. (K annihilates
    every cubic: rounded in floating point term by term, it would lose seven digits.)"""
    rows = np.array([_derivative_row(r, s) for s in (0.0, 1.0) for r in range(4)])
    exact = np.vectorize(lambda x: Fraction(x).limit_denominator(10_000), otypes=[object])
    minv = exact(np.linalg.inv(rows))  # small rationals (halves, sixths, ...)
    if not np.all(exact(rows) @ minv == np.eye(_NC, dtype=int)):
        raise ArithmeticError("the Hermite inverse is not a matrix of small rationals")
    k = np.arange(_NC)
    fall = np.array([math.perm(int(i), 4) for i in k], dtype=object)
    hess = np.array(
        [
            [Fraction(int(fall[i] * fall[j]), int(i + j - 7)) if i >= 4 and j >= 4 else Fraction(0) for j in k]
            for i in k
        ],
        dtype=object,
    )
    return minv.astype(float), (minv.T @ hess @ minv).astype(float)


def minimum_snap_coefficients(values: Any, times: Any, stops: Any = None) -> np.ndarray:
    """Minimum-snap 7th-order segments through ``values`` at ``times``.

    Each segment is the 7th-order Hermite polynomial of the value and the first three time
    derivatives (velocity, acceleration, jerk) at its two knots; those derivatives are the
    unknowns at every knot that is not a stop (zero at a stop). The cost
    ``sum_i int |d^4p/dt^4|^2 dt`` is a quadratic in them whose Hessian is block tridiagonal
    (3 x 3 blocks: a knot is coupled to its neighbours only), a banded symmetric positive
    definite system solved by Cholesky (``scipy.linalg.solveh_banded``) in time and memory
    linear in the number of knots (10^6 knots in seconds). It is the same QP as the
    equality-constrained KKT system over all 8 coefficients per segment, and gives its
    solution to rounding (``tests/unit/test_waypoints.py`` solves both).

    Parameters
    ----------
    values : array_like, shape (n,) or (n, A)
        Knot values, in the unit of the axis (e.g. [m], [rad]); A axes are solved together.
    times : array_like, shape (n,)
        Strictly increasing knot times [s], n >= 2.
    stops : array_like of bool, shape (n,), optional
        True where the path comes to rest (zero velocity, acceleration and jerk). The two
        ends always do.

    Returns
    -------
    numpy.ndarray
        Shape (m, 8, A), m = n - 1: the coefficients of s^0..s^7 of each segment, in the
        unit of the values, s = (t - times[i]) / (times[i+1] - times[i]).

    Examples
    --------
    >>> c = minimum_snap_coefficients([0.0, 1.0], [0.0, 2.0])   # rest to rest: 35s^4 - 84s^5 ...
    >>> c[0, :, 0].round(9) + 0.0
    array([  0.,   0.,   0.,   0.,  35., -84.,  70., -20.])
    """
    import scipy.linalg  # here, not at the top: importing quadcruise stays free of scipy

    w = np.asarray(values, dtype=float).reshape(len(times), -1)
    dur = np.diff(np.asarray(times, dtype=float))
    n, m, axes = w.shape[0], w.shape[0] - 1, w.shape[1]
    fixed = np.zeros(n, bool) if stops is None else np.asarray(stops, bool).copy()
    fixed[[0, -1]] = True
    minv, k_s = _hermite_matrices()  # a segment's cost y^T K y, y: value and s-derivatives at both ends
    # with time derivatives instead (y_a = T^r_a times them) a segment of duration T costs
    # T^-7 sum K[a, b] T^(r_a + r_b) y_a y_b; entry (a, b) over all segments as one vector:
    order, log_t = np.array([0, 1, 2, 3, 0, 1, 2, 3]), np.log(dur)

    def q(a: int, b: int) -> np.ndarray:
        return k_s[a, b] * np.exp((order[a] + order[b] - 7) * log_t)

    size = 3 * n  # unknowns: velocity, acceleration, jerk at each knot
    band = np.zeros((6, size))  # upper band storage: band[5 + row - col, col]
    rhs = np.zeros((size, axes))
    start = 3 * np.arange(m)  # a segment's first unknown at its start knot; + 3 at its end
    for ra in range(3):
        for rb in range(3):
            if rb >= ra:  # start-start and end-end blocks (upper triangle)
                band[5 - (rb - ra), start + rb] += q(1 + ra, 1 + rb)
                band[5 - (rb - ra), start + 3 + rb] += q(5 + ra, 5 + rb)
            band[5 - (3 + rb - ra), start + 3 + rb] += q(1 + ra, 5 + rb)  # start-end block
        for local, row in ((1 + ra, start + ra), (5 + ra, start + 3 + ra)):  # the values' pull
            rhs[row] -= q(local, 0)[:, None] * w[:-1] + q(local, 4)[:, None] * w[1:]
    fixed = np.repeat(fixed, 3)  # a stop's derivatives are 0: an identity row
    for o in range(1, 6):
        band[5 - o, o:][fixed[o:] | fixed[:-o]] = 0.0
    band[5, fixed] = 1.0
    rhs[fixed] = 0.0
    scale = 1.0 / np.sqrt(band[5])  # unit diagonal, whatever the spread of durations
    for o in range(6):
        band[5 - o, o:] *= scale[o:] * scale[: size - o]
    deriv = scipy.linalg.solveh_banded(band, rhs * scale[:, None], check_finite=False) * scale[:, None]
    d = deriv.reshape(n, 3, axes)
    powers = (dur[:, None] ** np.arange(1, 4))[:, :, None]  # a time derivative times T^r: the s-derivative
    y = np.empty((m, 8, axes))
    y[:, 0], y[:, 4] = w[:-1], w[1:]
    y[:, 1:4], y[:, 5:8] = d[:-1] * powers, d[1:] * powers
    return np.einsum("kj,ija->ika", minv, y)


# --- the mission kind ----------------------------------------------------------------------
@dataclass(frozen=True)
class MinimumSnap(WaypointMission):
    """The minimum-snap path through the points (Mellinger & Kumar 2011), yaw included.

    At rest at both ends and wherever the table dwells (two equal points in a row);
    C6 elsewhere. mp = [m, x, y, z, yaw, t at the end, (t_i, T_i, 32 coefficients) per segment].

    Parameters
    ----------
    table : WaypointTable, str, os.PathLike or dict
        The points and their timing; a path is read by
        :func:`~quadcruise.missions.waypoints.read_waypoints_csv`, a dict by
        :meth:`~quadcruise.missions.waypoints.WaypointTable.from_dict`.
    speed : float
        Leg speed where the table gives no timing [m/s], > 0.

    Examples
    --------
    >>> from quadcruise.missions.waypoints import WaypointTable
    >>> ms = MinimumSnap(WaypointTable([[0, 0, 1], [1, 1, 1], [2, 0, 1]], t=[0, 3, 6]))
    >>> ms.params().shape, ms.reference(3.0)[0, :2] .round(12) + 0.0
    ((74,), array([1., 1.]))
    """

    name: ClassVar[str] = "minsnap"
    columns: ClassVar[tuple] = (
        "m",
        "x_end",
        "y_end",
        "z_end",
        "yaw_end",
        "t_end",
        "t[i]",
        "T[i]",
        "x[i, 0..7]",
        "y[i, 0..7]",
        "z[i, 0..7]",
        "yaw[i, 0..7]",
    )
    function = staticmethod(minsnap_ref)

    @cached_property
    def coefficients(self) -> np.ndarray:
        """(m, 8, 4) coefficients of s^0..s^7 per segment, for x, y, z, yaw."""
        pts = self.table.points
        still = np.all(pts[1:] == pts[:-1], axis=1)  # dwells: rest at both ends
        stops = np.zeros(len(pts), bool)
        stops[:-1] |= still
        stops[1:] |= still
        coef = minimum_snap_coefficients(np.column_stack([pts, self.table.yaws()]), self.times, stops)
        coef.setflags(write=False)
        return coef

    def _row(self) -> np.ndarray:  # an array, not a tuple: 10^6 points stay quick
        tk, end = self.times, np.append(self.table.points[-1], self.table.yaws()[-1])
        segs = np.column_stack([tk[:-1], np.diff(tk), self.coefficients.transpose(0, 2, 1).reshape(len(tk) - 1, -1)])
        return np.concatenate([[len(tk) - 1], end, [tk[-1]], segs.ravel()])

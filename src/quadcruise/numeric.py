"""Scalar helpers shared by every layer: :func:`wrap_angle` and :func:`clamp`, the one copy of each.

Both are compiled with ``inline="always"``, so a compiled controller that calls them pays no
call (and no reference counting); from Python they are ordinary functions of floats. A leaf
module: it imports nothing of the package.

Examples
--------
>>> import math
>>> wrap_angle(3 * math.pi / 2) == -math.pi / 2
True
>>> clamp(5.0, -1.0, 1.0)
(1.0, True)
"""

from __future__ import annotations

import math

from numba import njit

__all__ = ["TWO_PI", "clamp", "wrap_angle"]

TWO_PI = 2.0 * math.pi


@njit(cache=True, inline="always", error_model="numpy")
def wrap_angle(a):
    """The angle ``a`` [rad] wrapped into [-pi, pi): a - 2 pi floor((a + pi) / (2 pi)).

    Parameters
    ----------
    a : float
        Any angle [rad].

    Returns
    -------
    float
        The same direction in [-pi, pi) (pi itself maps to -pi; rounding may leave a
        result a few ulp beyond either end for large ``a``). NaN gives NaN and +-inf
        itself; beyond |a| ~ 1e18 (where floor's integer overflows) the result is meaningless.

    Examples
    --------
    >>> import math
    >>> wrap_angle(math.pi), wrap_angle(-math.pi), round(wrap_angle(0.5 + 4 * math.pi), 12)
    (-3.141592653589793, -3.141592653589793, 0.5)
    >>> math.isnan(wrap_angle(float("nan"))), wrap_angle(float("inf"))
    (True, inf)
    """
    return a - TWO_PI * math.floor((a + math.pi) / TWO_PI)


@njit(cache=True, inline="always", error_model="numpy")
def clamp(value, low, high):
    """``value`` held within [low, high], and whether it had to be moved.

    Parameters
    ----------
    value : float
        The number to limit.
    low, high : float
        The bounds, ``low <= high`` (a symmetric limit is ``clamp(v, -bound, bound)``).

    Returns
    -------
    (float, bool)
        The limited value and True if it was outside [low, high]. NaN is returned as it
        is, with False (no comparison holds for it).

    Examples
    --------
    >>> clamp(0.5, 0.0, 1.0), clamp(-2.0, -1.0, 1.0)
    ((0.5, False), (-1.0, True))
    >>> clamp(float("nan"), 0.0, 1.0)
    (nan, False)
    """
    if value < low:
        return low, True
    if value > high:
        return high, True
    return value, False

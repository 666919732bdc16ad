"""Open-loop control: replay a schedule of PWM duties, ignoring the state.

The schedule is packed into the controller's parameter vector as
``[n, t_0 .. t_{n-1}, u1_0, u2_0, u3_0, u4_0, u1_1, ...]``; its memory holds the index
of the current row, so a lookup costs O(1) per control period.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadcruise.layout import CMD_FLAGS


@njit(cache=True)  # compiled (as CONTROLLER_SIG) on first use, not at import
def duty_schedule(t, dt, x, ref, vp, gains, mem, cmd):
    """Hold the duties of the last schedule row whose time is <= t (the first row before it).

    Examples
    --------
    >>> import numpy as np
    >>> gains = pack_schedule([0.0, 1.0], [[0.1, 0.2, 0.3, 0.4], [0.5, 0.6, 0.7, 0.8]])
    >>> mem, cmd, v = np.zeros(1), np.zeros(12), np.zeros(16)
    >>> duty_schedule(1.5, 1e-3, v, v[:11], v, gains, mem, cmd)
    >>> cmd[:4].tolist(), float(mem[0])
    ([0.5, 0.6, 0.7, 0.8], 1.0)
    """
    n = int(gains[0])
    row = int(mem[0])
    tol = 1e-12 * (1.0 + abs(t))
    while row + 1 < n and gains[1 + row + 1] <= t + tol:
        row += 1
    mem[0] = row
    base = 1 + n + 4 * row
    for j in range(4):
        cmd[j] = gains[base + j]
    for j in range(4, CMD_FLAGS):  # no generalized inputs or setpoints: open loop
        cmd[j] = np.nan


def pack_schedule(t: np.ndarray, duties: np.ndarray) -> np.ndarray:
    """The gains vector of :func:`duty_schedule`:
    ``[n, t_0 .. t_{n-1}, u1_0 .. u4_0, u1_1, ...]``.

    Examples
    --------
    >>> pack_schedule([0.0, 2.0], [[0.1, 0.1, 0.1, 0.1], [0.2, 0.2, 0.2, 0.2]]).tolist()
    [2.0, 0.0, 2.0, 0.1, 0.1, 0.1, 0.1, 0.2, 0.2, 0.2, 0.2]
    """
    t = np.asarray(t, dtype=float)
    duties = np.asarray(duties, dtype=float)
    return np.concatenate(([float(t.shape[0])], t, duties.reshape(-1)))

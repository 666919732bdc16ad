"""A known flight for checking estimators: a climbing, tilting circle given in closed form, with
its exact body rates and specific force (ENU world, FLU body).

Position ``p = (A cos wt, A sin wt, h + B sin 2wt)``; attitude ``R = Rz(psi) Ry(theta) Rx(phi)``
with ``phi = a sin(1.3 w t)``, ``theta = a cos(0.9 w t)``, ``psi = w t + pi/2 + 0.3 sin(0.5 w t)``;
body rates from the Euler rates, ``(phi' - psi' s_theta, theta' c_phi + psi' s_phi c_theta,
-theta' s_phi + psi' c_phi c_theta)``; specific force ``R^T (p'' + (0, 0, g))``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def tilted_circle(
    t: np.ndarray, radius: float = 10.0, omega: float = 0.3, height: float = 5.0, climb: float = 1.0,
    tilt: float = 0.2, gravity: float = 9.80665,
) -> dict:  # fmt: skip
    """The closed-form flight at the instants ``t``.

    Parameters
    ----------
    t : numpy.ndarray
        (L,) times [s].
    radius : float
        A, the circle's radius [m].
    omega : float
        w, its angular rate [rad/s].
    height : float
        h, mean altitude [m].
    climb : float
        B, amplitude of the altitude's oscillation [m].
    tilt : float
        a, amplitude of roll and pitch [rad].
    gravity : float
        g [m/s^2].

    Returns
    -------
    dict
        ``position``, ``velocity`` [m, m/s] (L, 3) ENU; ``quaternion`` (L, 4) w first, FLU to
        ENU; ``euler`` (L, 3) roll, pitch, yaw [rad]; ``rates`` [rad/s] and ``specific_force``
        [m/s^2] (L, 3) FLU.

    Examples
    --------
    >>> import numpy as np
    >>> f = tilted_circle(np.array([0.0]))
    >>> f["position"].round(3).tolist()
    [[10.0, 0.0, 5.0]]
    """
    t = np.asarray(t, float)
    A, w, B, a = radius, omega, climb, tilt
    c, s, c2, s2 = np.cos(w * t), np.sin(w * t), np.cos(2 * w * t), np.sin(2 * w * t)
    pos = np.column_stack([A * c, A * s, height + B * s2])
    vel = np.column_stack([-A * w * s, A * w * c, 2 * B * w * c2])
    acc = np.column_stack([-A * w * w * c, -A * w * w * s, -4 * B * w * w * s2])
    phi, dphi = a * np.sin(1.3 * w * t), 1.3 * w * a * np.cos(1.3 * w * t)
    th, dth = a * np.cos(0.9 * w * t), -0.9 * w * a * np.sin(0.9 * w * t)
    psi = w * t + np.pi / 2 + 0.3 * np.sin(0.5 * w * t)
    dpsi = w + 0.15 * w * np.cos(0.5 * w * t)
    rates = np.column_stack(
        [
            dphi - dpsi * np.sin(th),
            dth * np.cos(phi) + dpsi * np.sin(phi) * np.cos(th),
            -dth * np.sin(phi) + dpsi * np.cos(phi) * np.cos(th),
        ]
    )
    rot = Rotation.from_euler("ZYX", np.column_stack([psi, th, phi]))
    force = rot.inv().apply(acc + [0.0, 0.0, gravity])
    q = rot.as_quat()[:, [3, 0, 1, 2]]
    return {
        "position": pos,
        "velocity": vel,
        "quaternion": q,
        "euler": np.column_stack([phi, th, psi]),
        "rates": rates,
        "specific_force": force,
    }

"""An independent, plain-numpy statement of the paper's model for cross-checks.

Written from the equations, not from quadcruise's compiled code, so that agreement
between the two is evidence about both.
"""

import numpy as np


def rhs(x, u, m=3.499, Jxx=0.03, Jyy=0.03, Jzz=0.04, l=0.2, K=120.0, w=15.0, d=4 / 120, g=9.81):
    phi, th, psi = x[6:9]
    p, q, r = x[9:12]
    F = x[12:16]
    U1 = F.sum()
    U2 = F[1] - F[3]
    U3 = F[0] - F[2]
    U4 = d * (F[0] + F[2] - F[1] - F[3])
    acc = np.array(
        [
            (np.sin(phi) * np.sin(psi) + np.cos(phi) * np.sin(th) * np.cos(psi)) * U1 / m,
            (-np.sin(phi) * np.cos(psi) + np.cos(phi) * np.sin(th) * np.sin(psi)) * U1 / m,
            np.cos(phi) * np.cos(th) * U1 / m - g,
        ]
    )
    # Euler's equations for a rigid body (the k1..k6 form)
    pdot = ((Jyy - Jzz) * q * r + l * U2) / Jxx
    qdot = ((Jzz - Jxx) * p * r + l * U3) / Jyy
    rdot = ((Jxx - Jyy) * p * q + U4) / Jzz
    return np.concatenate([x[3:6], acc, [p, q, r], [pdot, qdot, rdot], w * (K * np.asarray(u) - F)])


def still_air_ext():
    """The plant's external-input vector with no disturbance: healthy rotors, no wind."""
    from quadcruise.layout import EXT_E1, EXT_SIZE

    ext = np.zeros(EXT_SIZE)
    ext[EXT_E1 : EXT_E1 + 4] = 1.0
    return ext


def euler_to_matrix(phi, theta, psi):
    """R = Rz(psi) Ry(theta) Rx(phi): body to earth (so R e3 is the thrust direction of eqs 5-7)."""
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    rz = np.array([[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[ct, 0.0, st], [0.0, 1.0, 0.0], [-st, 0.0, ct]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cf, -sf], [0.0, sf, cf]])
    return rz @ ry @ rx


def rotation_rhs(y, u, m=3.499, Jxx=0.03, Jyy=0.03, Jzz=0.04, l=0.2, K=120.0, w=15.0, d=4 / 120, g=9.81):
    """The rigid body with its attitude as a rotation matrix, free of any Euler-angle singularity.

    y = position (3), velocity (3), R row by row (9), body rates (3), rotor thrusts (4):
    v' = R e3 U1/m - g e3, R' = R [omega]x, J omega' = tau - omega x J omega.
    """
    R = y[6:15].reshape(3, 3)
    omega = y[15:18]
    F = y[18:22]
    U1, U2, U3 = F.sum(), F[1] - F[3], F[0] - F[2]
    U4 = d * (F[0] + F[2] - F[1] - F[3])
    J = np.array([Jxx, Jyy, Jzz])
    tau = np.array([l * U2, l * U3, U4])
    p, q, r = omega
    hat = np.array([[0.0, -r, q], [r, 0.0, -p], [-q, p, 0.0]])
    acc = R[:, 2] * U1 / m - np.array([0.0, 0.0, g])
    omega_dot = (tau - np.cross(omega, J * omega)) / J
    return np.concatenate([y[3:6], acc, (R @ hat).ravel(), omega_dot, w * (K * np.asarray(u) - F)])

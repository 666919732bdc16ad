"""The ``px4`` controller's loops linearised about hover, one axis at a time, as PX4's tuning
reads them: :func:`px4_margins` (``quadcruise analyze --controller px4``).

Each loop is the discrete system that quadcruise flies (:mod:`quadcruise.control.px4kernel`),
written from its pieces rather than differentiated, about hover on the vehicle's paper
equivalent:

- **plant** of one rotational axis: the normalised torque ``u`` (held over the control period
  ``T``) through the rotors' first-order lag ``omega_m`` (the vehicle's ``omega``) to a torque
  ``k_tau u`` [N m] on the inertia ``J``: ``tau' = omega_m (k_tau u - tau)``, ``J w' = tau``,
  ``angle' = w``; horizontally ``v' = g angle`` (a tilt ``a / g`` per acceleration setpoint, as
  ``bodyzToAttitude`` gives at hover). ``k_tau`` is the allocation's torque per unit normalised
  torque at hover (PX4's normalised mix, the thrust model ``THR_MDL_FAC`` and the vehicle's
  thrust curve, differentiated at the hover thrust). Sampled exactly (zero-order hold, ``expm``);
- **rate loop** at ``T`` (PX4's runs at the gyro rate): the rate through ``LowPassFilter2p`` at
  ``IMU_GYRO_CUTOFF``, D on the differenced raw rate through the ``AlphaFilter`` at
  ``IMU_DGYRO_CUTOFF``, ``u = K P e + i - K D w' + FF w_sp``, ``i += K I e T`` (the
  integral's factor is 1 at zero error);
- **attitude loop** at ``IMU_INTEG_RATE`` (the rate setpoint held in between): ``w_sp = P e``
  (tilt and yaw alike for a small error: ``MC_YAW_WEIGHT`` scales the yaw gain back);
- **velocity loop** at ``position_rate``: ``a_sp = P e_v + i - D v'``, ``v'`` the velocity
  differenced at that rate and low-passed at ``MPC_VELD_LP``; horizontally the tilt setpoint
  ``a_sp / g``, vertically the collective thrust ``MPC_THR_HOVER a_sp / g`` through the rotors' lag;
- **position loop** at ``position_rate``: ``v_sp = P e_p``.

A slower loop sees the faster ones closed over its own period (the exact lifting of the
periodic system: the product of the fast steps, the slower output held). Each loop is broken
at its controller's output (the rate loop at the normalised torque, the attitude loop at the
rate setpoint, the velocity loop at the acceleration setpoint, the position loop at the
velocity setpoint), the loops inside it closed and the ones outside open, as PX4's autotune and
tuning guide take them one at a time.

Targets (:data:`TARGETS`): PX4 v1.15 states no margins. Its autotune
(``src/modules/mc_autotune_attitude_control/``) designs the rate loop for a closed-loop rise
time of ``MC_AT_RISE_TIME`` (0.14 s, roll and pitch) and 0.2 s (yaw, hard-coded) with damping
0.7, and sets the attitude gain by ``K_att K_rate rad(60) = 1`` within [2, 6.5]; the manual
guide asks for no oscillation ("twitches") and no numbers. The margins are held to the
classical floors quadcruise uses for every controller (:mod:`quadcruise.metrics.margins`): a
phase margin of 30 deg and 6 dB of gain margin each way.

>>> m = px4_margins("px4", "iris")
>>> m.summary()["loops"]["rate"]["roll"]["meets_margins"]
True
"""

from __future__ import annotations

import math
from collections.abc import Callable

import control
import numpy as np
import scipy.linalg

from quadcruise import checks
from quadcruise import layout as L
from quadcruise.errors import InputError
from quadcruise.workflows.px4margins_result import AXES, LOOP_ORDER, TARGETS, LoopModel, Px4Margins

__all__ = ["AXES", "TARGETS", "Px4Margins", "LoopModel", "px4_margins", "rotor_gains", "zoh"]

_G = 9.80665  # PX4's CONSTANTS_ONE_G [m/s^2]


def zoh(Ac: np.ndarray, Bc: np.ndarray, T: float) -> tuple[np.ndarray, np.ndarray]:
    """A continuous system sampled with its input held over ``T``: ``expm([[A, B], [0, 0]] T)``.

    Parameters
    ----------
    Ac, Bc : numpy.ndarray
        x' = Ac x + Bc u.
    T : float
        Sample period [s].

    Returns
    -------
    Ad, Bd : numpy.ndarray
        x[k+1] = Ad x[k] + Bd u[k].

    Examples
    --------
    >>> Ad, Bd = zoh(np.array([[0.0]]), np.array([[1.0]]), 0.5)   # an integrator
    >>> float(Ad[0, 0]), float(Bd[0, 0])
    (1.0, 0.5)
    """
    n, m = Bc.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = Ac, Bc
    E = scipy.linalg.expm(M * T)
    return E[:n, :n], E[:n, n:]


def _thrust_slope(vp, gains, n):
    """The hover command ``s_h`` of each rotor (its thrust ``m g / n``) and ``dF/ds`` there [N].

    ``F = T ((1 - c) u + c u^2)`` (c the vehicle's thrust curve, T a rotor's full thrust), ``u``
    the command PX4's thrust model gives for ``s``: ``s = (1 - f) u + f u^2`` (f ``THR_MDL_FAC``)."""
    from quadcruise.control.px4kernel import X_THR_MDL_FAC, X_THRUST_CURVE

    full = 4.0 * vp[L.P_K] / n
    c, f = gains[X_THRUST_CURVE], gains[X_THR_MDL_FAC]
    share = vp[L.P_M] * vp[L.P_G] / (n * full)
    u = share if c <= 0.0 else (-(1.0 - c) + math.sqrt((1.0 - c) ** 2 + 4.0 * c * share)) / (2.0 * c)
    s = (1.0 - f) * u + f * u * u
    return s, full * ((1.0 - c) + 2.0 * c * u) / ((1.0 - f) + 2.0 * f * u)


def rotor_gains(controller, vehicle) -> dict:
    """What the allocation and the rotors make of a unit of PX4's normalised commands at hover.

    Parameters
    ----------
    controller : Px4
        The controller (its ``CA_ROTOR*`` mix or the vehicle's layout, its thrust model).
    vehicle : Vehicle
        The paper vehicle flown (a rotor vehicle's paper equivalent).

    Returns
    -------
    dict
        ``torque`` [N m], FRD roll, pitch, yaw per unit normalised torque; ``accel`` [m/s^2 per
        m/s^2]: the vertical acceleration per unit of the velocity loop's vertical acceleration
        setpoint (1 when ``MPC_THR_HOVER`` is the vehicle's hover thrust and the thrust is linear
        in the command); ``hover_command`` the rotors' command at hover [-].

    Examples
    --------
    >>> from quadcruise.control.px4 import Px4
    >>> import quadcruise as qc
    >>> r = rotor_gains(Px4(), qc.Vehicle.paper())
    >>> round(r["accel"], 6), round(9.81 / 9.80665, 6)   # the vehicle's g over PX4's CONSTANTS_ONE_G
    (1.000342, 1.000342)
    """
    from quadcruise.control.px4kernel import X_GEOM, X_MIX, X_N_ROTORS
    from quadcruise.control.px4loops import G_THR_HOVER

    vp = np.asarray(vehicle.rows()[0], float)
    gains = controller.gains()
    n = int(gains[X_N_ROTORS])
    s_h, slope = _thrust_slope(vp, gains, n)
    arms, signs = (vp[L.P_L], vp[L.P_L], vp[L.P_D]), (1.0, -1.0, -1.0)  # FRD axes from the FLU layout
    torque = [
        signs[a] * arms[a] * sum(gains[X_GEOM + 3 * i + a] * gains[X_MIX + 6 * i + a] * slope for i in range(n))
        for a in range(3)
    ]
    # collective thrust c: each rotor's command -mix[i, 5] * (-c); the vertical acceleration per unit of it
    per_collective = -sum(gains[X_MIX + 6 * i + 5] for i in range(n)) * slope / vp[L.P_M]
    hover = controller.loop_gains(vehicle)[G_THR_HOVER]
    return {
        "torque": [float(t) for t in torque],
        "accel": float(per_collective * hover / _G),
        "hover_command": float(s_h),
    }


def _rate_controller(g, a, T, gyro_hz, dgyro_hz):
    """One rate axis's controller over one period as matrices: state c = (lpf d0, d1, accel, last
    rate, integral), inputs (rate, rate setpoint): c+ = Ac c + Bw w + Br r, u = Cc c + Dw w + Dr r."""
    from quadcruise.control.px4filters import alpha_of, lpf2p_coefficients
    from quadcruise.control.px4loops import G_RATE_D, G_RATE_FF, G_RATE_I, G_RATE_P

    b0, b1, b2, a1, a2 = lpf2p_coefficients(1.0 / T, gyro_hz)
    al = alpha_of(1.0 / T, dgyro_hz)
    P, I, D, FF = g[G_RATE_P + a], g[G_RATE_I + a], g[G_RATE_D + a], g[G_RATE_FF + a]
    # filtered rate y = b0 w + (b1 - b0 a1) d0 + (b2 - b0 a2) d1; derivative acc = (1 - al) acc_ + al/T (w - w_)
    cy, dy = np.array([b1 - b0 * a1, b2 - b0 * a2, 0.0, 0.0, 0.0]), b0
    cacc, dacc = np.array([0.0, 0.0, 1.0 - al, -al / T, 0.0]), al / T
    Ac = np.zeros((5, 5))
    Ac[0, :2] = (-a1, -a2)
    Ac[1, 0] = 1.0
    Ac[2] = cacc
    Ac[4] = -I * T * cy
    Ac[4, 4] += 1.0
    Bw = np.array([1.0, 0.0, dacc, 1.0, -I * T * dy])
    Br = np.array([0.0, 0.0, 0.0, 0.0, I * T])
    Cc = -P * cy - D * cacc + np.array([0.0, 0.0, 0.0, 0.0, 1.0])
    return Ac, Bw, Br, Cc, -P * dy - D * dacc, P + FF


def _axis_plant(inertia, k_tau, omega_m, T, horizontal):
    """One rotational axis over T: states (tau, w, angle[, v, p]), input the normalised torque."""
    n = 5 if horizontal else 3
    A, B = np.zeros((n, n)), np.zeros((n, 1))
    A[0, 0], B[0, 0] = -omega_m, omega_m * k_tau
    A[1, 0], A[2, 1] = 1.0 / inertia, 1.0
    if horizontal:
        A[3, 2], A[4, 3] = _G, 1.0
    return zoh(A, B, T)


class _Fast:
    """One rotational axis's rate loop at T as the state z = (plant, rate controller, held rate
    setpoint): ``step(attitude)`` the map of one period, the attitude loop run first or not."""

    def __init__(self, plant, ctrl, att_p):
        (self.Ad, self.Bd), (self.Ac, self.Bw, self.Br, self.Cc, self.Dw, self.Dr) = plant, ctrl
        self.np, self.P = self.Ad.shape[0], att_p
        self.n = self.np + 6
        self.rate, self.angle = 1, 2  # plant rows

    def step(self, attitude: bool, feedback: bool = True):
        """(F, G): z+ = F z + G w; w the attitude setpoint (attitude and feedback), the rate
        setpoint injected (attitude, no feedback) or nothing (G zero)."""
        n, m = self.n, self.np
        S = np.eye(n)  # the attitude loop first: r = P (w - angle), or r = w
        G0 = np.zeros(n)
        if attitude:
            S[n - 1, n - 1] = 0.0
            if feedback:
                S[n - 1, self.angle] = -self.P
                G0[n - 1] = self.P
            else:
                G0[n - 1] = 1.0
        R = np.zeros((m + 5, n))  # then the rate loop with r = z[-1]
        ew = np.zeros(m)
        ew[self.rate] = 1.0
        u = np.concatenate([self.Dw * ew, self.Cc, [self.Dr]])
        R[:m] = self.Ad[:, :m] @ np.eye(m, n) + self.Bd @ u[None, :]
        R[m:] = np.hstack([np.outer(self.Bw, ew), self.Ac, self.Br[:, None]])
        F = np.vstack([R, np.eye(n)[n - 1 :]])
        return F @ S, F @ G0


def _lift(steps):
    """The product of a period's steps [(F, G), ...] (the first applied first), its input held."""
    F, G = steps[0]
    for Fk, Gk in steps[1:]:
        F, G = Fk @ F, Fk @ G + Gk
    return F, G


def _ss(A, B, C, dt):
    return control.ss(A, np.asarray(B, float).reshape(-1, 1), np.asarray(C, float).reshape(1, -1), 0.0, dt)


def _vel_controller(P, I, D, alpha, Tp):
    """The velocity PID at Tp, state (integral, derivative, last velocity), inputs (v, v_sp): the
    matrices of c+ = Ac c + Bv v + Bs s and a_sp = Cc c + Dv v + Ds s."""
    Ac = np.array([[1.0, 0.0, 0.0], [0.0, 1.0 - alpha, -alpha / Tp], [0.0, 0.0, 0.0]])
    Bv, Bs = np.array([-I * Tp, alpha / Tp, 1.0]), np.array([I * Tp, 0.0, 0.0])
    Cc = np.array([1.0, -D * (1.0 - alpha), D * alpha / Tp])
    return Ac, Bv, Bs, Cc, -P - D * alpha / Tp, P


def _outer(inner_A, inner_B, c_v, c_p, gains, Tp):
    """The velocity and position loops around an inner system (held a_sp -> state at Tp), as
    (L_velocity, T_velocity, L_position, T_position); c_v, c_p read v and p from the inner state."""
    P, I, D, alpha, Kp = gains
    Ac, Bv, Bs, Cc, Dv, Ds = _vel_controller(P, I, D, alpha, Tp)
    n = inner_A.shape[0]
    b = inner_B.reshape(-1, 1)
    # velocity loop broken at a_sp (v_sp = 0): y = -a_sp
    A = np.block([[inner_A, np.zeros((n, 3))], [np.outer(Bv, c_v), Ac]])
    L_vel = _ss(A, np.r_[b.ravel(), np.zeros(3)], -np.r_[Dv * c_v, Cc], Tp)
    # the velocity loop closed: a_sp = Cc c + Dv v + Ds s; input s = v_sp
    Acl = np.block([[inner_A + b @ (Dv * c_v)[None, :], b @ Cc[None, :]], [np.outer(Bv, c_v), Ac]])
    Bcl = np.r_[b.ravel() * Ds, Bs]
    T_vel = _ss(Acl, Bcl, np.r_[c_v, np.zeros(3)], Tp)
    cp = np.r_[c_p, np.zeros(3)]
    L_pos = _ss(Acl, Bcl, Kp * cp, Tp)
    T_pos = _ss(Acl - Kp * np.outer(Bcl, cp), Kp * Bcl, cp, Tp)
    return L_vel, T_vel, L_pos, T_pos


def px4_margins(
    controller="px4",
    vehicle=None,
    *,
    dt: float = 1e-3,
    progress: Callable[[int, int], None] | None = None,
) -> Px4Margins:
    """The px4 controller's rate, attitude, velocity and position loops about hover, per axis:
    margins, crossover, closed-loop bandwidth and PX4's targets (the module's model).

    Parameters
    ----------
    controller : Px4 or str
        ``"px4"`` (the controller a name gives, designed for the vehicle as ``fly`` designs
        it) or a :class:`~quadcruise.control.px4.Px4` (e.g. ``Px4.from_params("x500.params",
        vehicle=...)``).
    vehicle : Vehicle, RotorVehicle or str, optional
        The vehicle (a preset name, a paper vehicle or a rotor-plant one, linearised through its
        paper equivalent); the paper's Table I by default.
    dt : float
        The control period [s]: the rate loop's (PX4's gyro rate).
    progress : callable, optional
        ``progress(done, total)`` after each of the four loops.

    Returns
    -------
    Px4Margins

    Raises
    ------
    InputError
        Another controller, a bad vehicle or period.

    Examples
    --------
    >>> m = px4_margins("px4", "iris")
    >>> sorted(m.loops)[:2]
    [('attitude', 'pitch'), ('attitude', 'roll')]
    """
    from quadcruise.control.px4 import Px4
    from quadcruise.control.px4loops import G_ATT_P, G_POS_P, G_VEL_D, G_VEL_I, G_VEL_P
    from quadcruise.model.equivalent import paper_equivalent
    from quadcruise.model.rotor_vehicle import RotorVehicle
    from quadcruise.model.vehicle import Vehicle

    w = "px4_margins()"
    dt = checks.number(w, "dt", dt, "pos", unit="s")
    checks.callback(w, "progress", progress)
    if not math.isfinite(dt) or dt > 0.05:
        raise InputError(f"{w}: dt = {dt:g} s is not a control period of PX4's rate loop (at most 0.05 s)")
    given = vehicle
    if isinstance(vehicle, str):
        from quadcruise.workflows.scenario_vehicle import vehicle_preset

        vehicle = vehicle_preset(vehicle)
    if vehicle is None:
        vehicle = Vehicle.paper()
    if not isinstance(vehicle, (Vehicle, RotorVehicle)):
        checks.fail(w, "vehicle", given, "a Vehicle, a RotorVehicle or a preset name")
    if isinstance(controller, str):
        if controller != "px4":
            raise InputError(f"{w}: controller {controller!r} is not px4 (analyse it with linearize)")
        from quadcruise.workflows.rotor_fly import flight_setup

        controller = flight_setup(vehicle, None, "px4")[1]  # designed for the vehicle where its plant designs gains
        if isinstance(controller, str):
            controller = Px4()
    if not isinstance(controller, Px4):
        checks.fail(w, "controller", controller, "the px4 controller (a Px4 or 'px4')")
    paper = paper_equivalent(vehicle)
    vp = np.asarray(paper.rows()[0], float)
    g = controller.loop_gains(paper)
    p = controller.params
    rg = rotor_gains(controller, paper)
    n_att = max(1, round(1.0 / (p["IMU_INTEG_RATE"] * dt)))
    n_pos = max(1, round(1.0 / (controller.position_rate * dt)))  # the attitude loop restarts with each
    Ta, Tp = n_att * dt, n_pos * dt
    inertia = (vp[L.P_JXX], vp[L.P_JYY], vp[L.P_JZZ])
    models: dict = {}
    total = len(LOOP_ORDER)
    done = 0
    # rate and attitude loops, per axis; the horizontal loops built on roll (y) and pitch (x). Over a
    # position period the attitude loop runs at its steps 0, n_att, 2 n_att, ... (exact when n_att divides n_pos)
    inner = {}
    for a, axis in enumerate(("roll", "pitch", "yaw")):
        horizontal = axis != "yaw"
        plant = _axis_plant(inertia[a], rg["torque"][a], vp[L.P_OMEGA], dt, horizontal)
        ctrl = _rate_controller(g, a, dt, p["IMU_GYRO_CUTOFF"], p["IMU_DGYRO_CUTOFF"])
        fast = _Fast(plant, ctrl, g[G_ATT_P + a])
        n, m = fast.n, fast.np
        # rate loop broken at the normalised torque, the attitude loop open (r = 0)
        Ad, Bd = plant
        Ac, Bw, Br, Cc, Dw, Dr = ctrl
        ew = np.eye(m)[fast.rate]
        A = np.block([[Ad, np.zeros((m, 5))], [np.outer(Bw, ew), Ac]])
        L_rate = _ss(A, np.r_[Bd.ravel(), np.zeros(5)], -np.r_[Dw * ew, Cc], dt)
        Fr, Gr = fast.step(True, feedback=False)  # r held as a state: the closed rate loop
        T_rate = _ss(Fr, Gr, np.eye(n)[fast.rate], dt)
        # attitude loop at Ta: broken at the rate setpoint, and closed
        Fo, Go = _lift([fast.step(True, feedback=False)] + [fast.step(False)] * (n_att - 1))
        L_att = _ss(Fo, Go, g[G_ATT_P + a] * np.eye(n)[fast.angle], Ta)
        Fa, Ga = _lift([fast.step(True)] + [fast.step(False)] * (n_att - 1))
        T_att = _ss(Fa, Ga, np.eye(n)[fast.angle], Ta)
        models[("rate", axis)] = LoopModel(L_rate, T_rate, dt, "normalised torque", "rad/s")
        models[("attitude", axis)] = LoopModel(L_att, T_att, Ta, "rate setpoint [rad/s]", "rad")
        if horizontal:
            inner[axis] = _lift([fast.step(j % n_att == 0) for j in range(n_pos)]), n, m
    done += 2
    if progress is not None:
        progress(done, total)
    # velocity and position loops: x through pitch, y through roll (quadcruise's ENU axes), z through the thrust
    alpha = (lambda b: b / (1.0 + b))(2.0 * math.pi * p["MPC_VELD_LP"] * Tp)
    for axis, via in (("x", "pitch"), ("y", "roll")):
        (F, G), n, _ = inner[via]
        c_v, c_p = np.eye(n)[3], np.eye(n)[4]
        outer = _outer(F, G / _G, c_v, c_p, (g[G_VEL_P], g[G_VEL_I], g[G_VEL_D], alpha, g[G_POS_P]), Tp)
        _add_outer(models, axis, outer, Tp)
    Av = np.array([[-vp[L.P_OMEGA], 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    Bv = np.array([[vp[L.P_OMEGA] * rg["accel"]], [0.0], [0.0]])
    Fz, Gz = zoh(Av, Bv, Tp)
    gz = (g[G_VEL_P + 2], g[G_VEL_I + 2], g[G_VEL_D + 2], alpha, g[G_POS_P + 2])
    _add_outer(models, "z", _outer(Fz, Gz.ravel(), np.eye(3)[1], np.eye(3)[2], gz, Tp), Tp)
    done = total
    if progress is not None:
        progress(done, total)
    setup = {
        "dt_s": dt,
        "attitude_period_s": Ta,
        "position_period_s": Tp,
        "torque_per_unit_Nm": rg["torque"],
        "vertical_accel_per_setpoint": rg["accel"],
        "hover_command": rg["hover_command"],
        "motor_bandwidth_rad_s": float(vp[L.P_OMEGA]),
        "inertia_kg_m2": list(map(float, inertia)),
    }
    return Px4Margins(models, controller, paper, setup)


def _add_outer(models, axis, outer, Tp):
    L_vel, T_vel, L_pos, T_pos = outer
    models[("velocity", axis)] = LoopModel(L_vel, T_vel, Tp, "acceleration setpoint [m/s^2]", "m/s")
    models[("position", axis)] = LoopModel(L_pos, T_pos, Tp, "velocity setpoint [m/s]", "m")

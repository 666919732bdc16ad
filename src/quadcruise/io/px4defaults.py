"""The PX4 parameters that quadcruise's PX4 loops use, with PX4 v1.15's defaults, units and ranges.

Read from PX4-Autopilot's parameter definitions of release v1.15 (``PARAM_DEFINE_*`` with
``@min``/``@max``/``@unit``): ``src/modules/mc_rate_control/mc_rate_control_params.c``,
``src/modules/mc_att_control/mc_att_control_params.c``,
``src/modules/mc_pos_control/multicopter_position_control_gain_params.c``,
``multicopter_position_control_limits_params.c`` and ``multicopter_position_control_params.c``;
the hover-thrust estimator's from ``src/modules/mc_hover_thrust_estimator/hover_thrust_estimator_params.yaml``.
A bound PX4 does not declare is ``None`` (no limit). Angles and rates are in PX4's own units
(deg, deg/s); the loops convert them (:func:`quadcruise.control.px4loops.px4_gains`).

Between releases: v1.15 has no ``MC_YAW_TQ_CUTOFF`` (the yaw torque low-pass came later) and
no ``MPC_ACC_DECOUPLE`` (v1.15 always decouples the tilt from the vertical acceleration, as
the later default 1 does); a file that sets them has them listed as unused.
"""

from __future__ import annotations

from typing import NamedTuple

__all__ = ["RELEASE", "Px4Param", "PX4_PARAMETERS", "FLOAT", "INT32"]

RELEASE = "v1.15"
"""The PX4 release whose defaults and ranges :data:`PX4_PARAMETERS` holds."""
FLOAT = 9
"""MAVLink ``MAV_PARAM_TYPE_REAL32``: a float parameter's type in a .params file."""
INT32 = 6
"""MAVLink ``MAV_PARAM_TYPE_INT32``: an integer parameter's type in a .params file."""


class Px4Param(NamedTuple):
    """One PX4 parameter as PX4 declares it.

    Parameters
    ----------
    default : float
        PX4's default (v1.15), in ``unit``.
    unit : str
        PX4's unit ("" for a gain in normalised torque or thrust per unit error).
    minimum, maximum : float or None
        PX4's ``@min`` and ``@max``; None where PX4 declares none.
    kind : int
        :data:`FLOAT` or :data:`INT32`.
    loop : str
        The loop that uses it: ``rate``, ``attitude`` or ``position``.
    """

    default: float
    unit: str
    minimum: float | None
    maximum: float | None
    kind: int
    loop: str


_TABLE = {
    # mc_rate_control_params.c
    "MC_ROLLRATE_P": Px4Param(0.15, "", 0.01, 0.5, FLOAT, "rate"),
    "MC_ROLLRATE_I": Px4Param(0.2, "", 0.0, None, FLOAT, "rate"),
    "MC_ROLLRATE_D": Px4Param(0.003, "", 0.0, 0.01, FLOAT, "rate"),
    "MC_ROLLRATE_FF": Px4Param(0.0, "", 0.0, None, FLOAT, "rate"),
    "MC_ROLLRATE_K": Px4Param(1.0, "", 0.01, 5.0, FLOAT, "rate"),
    "MC_RR_INT_LIM": Px4Param(0.3, "", 0.0, None, FLOAT, "rate"),
    "MC_PITCHRATE_P": Px4Param(0.15, "", 0.01, 0.6, FLOAT, "rate"),
    "MC_PITCHRATE_I": Px4Param(0.2, "", 0.0, None, FLOAT, "rate"),
    "MC_PITCHRATE_D": Px4Param(0.003, "", 0.0, None, FLOAT, "rate"),
    "MC_PITCHRATE_FF": Px4Param(0.0, "", 0.0, None, FLOAT, "rate"),
    "MC_PITCHRATE_K": Px4Param(1.0, "", 0.01, 5.0, FLOAT, "rate"),
    "MC_PR_INT_LIM": Px4Param(0.3, "", 0.0, None, FLOAT, "rate"),
    "MC_YAWRATE_P": Px4Param(0.2, "", 0.0, 0.6, FLOAT, "rate"),
    "MC_YAWRATE_I": Px4Param(0.1, "", 0.0, None, FLOAT, "rate"),
    "MC_YAWRATE_D": Px4Param(0.0, "", 0.0, None, FLOAT, "rate"),
    "MC_YAWRATE_FF": Px4Param(0.0, "", 0.0, None, FLOAT, "rate"),
    "MC_YAWRATE_K": Px4Param(1.0, "", 0.01, 5.0, FLOAT, "rate"),
    "MC_YR_INT_LIM": Px4Param(0.3, "", 0.0, None, FLOAT, "rate"),
    # mc_att_control_params.c
    "MC_ROLL_P": Px4Param(6.5, "1/s", 0.0, 12.0, FLOAT, "attitude"),
    "MC_PITCH_P": Px4Param(6.5, "1/s", 0.0, 12.0, FLOAT, "attitude"),
    "MC_YAW_P": Px4Param(2.8, "1/s", 0.0, 5.0, FLOAT, "attitude"),
    "MC_YAW_WEIGHT": Px4Param(0.4, "", 0.0, 1.0, FLOAT, "attitude"),
    "MC_ROLLRATE_MAX": Px4Param(220.0, "deg/s", 0.0, 1800.0, FLOAT, "attitude"),
    "MC_PITCHRATE_MAX": Px4Param(220.0, "deg/s", 0.0, 1800.0, FLOAT, "attitude"),
    "MC_YAWRATE_MAX": Px4Param(200.0, "deg/s", 0.0, 1800.0, FLOAT, "attitude"),
    # multicopter_position_control_gain_params.c
    "MPC_XY_P": Px4Param(0.95, "1/s", 0.0, 2.0, FLOAT, "position"),
    "MPC_Z_P": Px4Param(1.0, "1/s", 0.0, 1.5, FLOAT, "position"),
    "MPC_XY_VEL_P_ACC": Px4Param(1.8, "1/s", 1.2, 5.0, FLOAT, "position"),
    "MPC_XY_VEL_I_ACC": Px4Param(0.4, "1/s^2", 0.0, 60.0, FLOAT, "position"),
    "MPC_XY_VEL_D_ACC": Px4Param(0.2, "", 0.1, 2.0, FLOAT, "position"),
    "MPC_Z_VEL_P_ACC": Px4Param(4.0, "1/s", 2.0, 15.0, FLOAT, "position"),
    "MPC_Z_VEL_I_ACC": Px4Param(2.0, "1/s^2", 0.2, 3.0, FLOAT, "position"),
    "MPC_Z_VEL_D_ACC": Px4Param(0.0, "", 0.0, 2.0, FLOAT, "position"),
    # multicopter_position_control_limits_params.c
    "MPC_XY_VEL_MAX": Px4Param(12.0, "m/s", 0.0, 20.0, FLOAT, "position"),
    "MPC_Z_VEL_MAX_UP": Px4Param(3.0, "m/s", 0.5, 8.0, FLOAT, "position"),
    "MPC_Z_VEL_MAX_DN": Px4Param(1.5, "m/s", 0.5, 4.0, FLOAT, "position"),
    "MPC_TILTMAX_AIR": Px4Param(45.0, "deg", 20.0, 89.0, FLOAT, "position"),
    "MPC_THR_MIN": Px4Param(0.12, "norm", 0.05, 0.5, FLOAT, "position"),
    "MPC_THR_MAX": Px4Param(1.0, "norm", 0.0, 1.0, FLOAT, "position"),
    # multicopter_position_control_params.c
    "MPC_THR_HOVER": Px4Param(0.5, "norm", 0.1, 0.8, FLOAT, "position"),
    "MPC_THR_XY_MARG": Px4Param(0.3, "norm", 0.0, 0.5, FLOAT, "position"),
    "MPC_USE_HTE": Px4Param(1, "", 0, 1, INT32, "position"),
    "MPC_VELD_LP": Px4Param(5.0, "Hz", 0.0, 10.0, FLOAT, "position"),
    # takeoff (multicopter_position_control_params.c, _limits_params.c): the ramp, the tilt limit on the ground
    "MPC_TKO_RAMP_T": Px4Param(3.0, "s", 0.0, 5.0, FLOAT, "takeoff"),
    "MPC_TILTMAX_LND": Px4Param(12.0, "deg", 5.0, 89.0, FLOAT, "takeoff"),
    # mc_hover_thrust_estimator/hover_thrust_estimator_params.yaml
    "HTE_HT_NOISE": Px4Param(0.0036, "norm/s", 0.0001, 1.0, FLOAT, "hover estimator"),
    "HTE_ACC_GATE": Px4Param(3.0, "SD", 1.0, 10.0, FLOAT, "hover estimator"),
    "HTE_HT_ERR_INIT": Px4Param(0.1, "norm", 0.0, 1.0, FLOAT, "hover estimator"),
    "HTE_VXY_THR": Px4Param(10.0, "m/s", 1.0, 20.0, FLOAT, "hover estimator"),
    "HTE_VZ_THR": Px4Param(2.0, "m/s", 1.0, 10.0, FLOAT, "hover estimator"),
    "HTE_THR_RANGE": Px4Param(0.2, "norm", 0.01, 0.4, FLOAT, "hover estimator"),
    # sensors/vehicle_angular_velocity/imu_gyro_parameters.c
    "IMU_GYRO_CUTOFF": Px4Param(40.0, "Hz", 0.0, 1000.0, FLOAT, "filters"),
    "IMU_DGYRO_CUTOFF": Px4Param(30.0, "Hz", 0.0, 1000.0, FLOAT, "filters"),
    # sensors/vehicle_imu/imu_parameters.c: the rate of the integrated IMU, hence of EKF2's attitude
    "IMU_INTEG_RATE": Px4Param(200, "Hz", 100, 1000, INT32, "attitude"),
    # control_allocator/module.yaml, lib/mixer_module/params.c
    "MC_AIRMODE": Px4Param(0, "", 0, 2, INT32, "allocation"),
    "THR_MDL_FAC": Px4Param(0.0, "", 0.0, 1.0, FLOAT, "allocation"),
    "CA_ROTOR_COUNT": Px4Param(0, "", 0, 12, INT32, "allocation"),
}
for _i in range(12):  # CA_ROTOR${i}_*: position [m], thrust axis, thrust coefficient, moment ratio
    for _c in "XYZ":
        _TABLE[f"CA_ROTOR{_i}_P{_c}"] = Px4Param(0.0, "m", -100.0, 100.0, FLOAT, "allocation")
        _TABLE[f"CA_ROTOR{_i}_A{_c}"] = Px4Param(-1.0 if _c == "Z" else 0.0, "", -100.0, 100.0, FLOAT, "allocation")
    _TABLE[f"CA_ROTOR{_i}_CT"] = Px4Param(6.5, "", 0.0, 100.0, FLOAT, "allocation")
    _TABLE[f"CA_ROTOR{_i}_KM"] = Px4Param(0.05, "", -1.0, 1.0, FLOAT, "allocation")
PX4_PARAMETERS: dict[str, Px4Param] = dict(_TABLE)
"""Each parameter the loops use, by PX4's name: its v1.15 default, unit, range, type and loop."""

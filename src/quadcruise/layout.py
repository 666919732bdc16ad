"""The engine's data layout: named columns of the state, reference and command vectors,
the compiled signatures that controllers and missions must have, and :class:`Row`, the one
declaration of every packed row (these vectors, the vehicle parameters and external inputs,
a controller's gains and memory, a disturbance's parameters and memory).

Everything the compiled engine touches is a flat ``float64`` vector (one vehicle) or a
2-D array with a leading batch axis (N vehicles). The names below are the column indices;
use them instead of bare numbers, e.g. ``state[:, PHI]``.

A controller or mission written by a user plugs into the same cached engine as the
built-in ones if it is compiled with the signature given here::

    from numba import njit
    from quadcruise.layout import CONTROLLER_SIG

    @njit(CONTROLLER_SIG, cache=True)
    def my_controller(t, dt, x, ref, vp, gains, mem, cmd):
        ...

Units are SI throughout: metres, seconds, radians, newtons.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import types


@dataclass(frozen=True)
class Row:
    """One packed float64 row, declared once: an ordered list of named fields that yields the
    offsets, the packing and the column names. Unpack its offsets into module-level constants
    (``PD_KP, PD_KD = PD.offsets``), which numba folds into the machine code.

    Examples
    --------
    >>> pd = Row.of("pd gains", "kp", "kd", ("bias", 2), prefix="PD_")
    >>> pd.offsets, pd.size, pd.names
    ((0, 1, 2), 4, ('kp', 'kd', 'bias[0]', 'bias[1]'))
    >>> pd.pack({"kp": 3.0, "kd": 5.0, "bias": (1.0, 2.0)}).tolist()
    [3.0, 5.0, 1.0, 2.0]
    >>> pd.pack({"kp": 3.0, "kd": [5.0, 6.0]}, n=2, default=0.0).tolist()     # one value per vehicle
    [[3.0, 5.0, 0.0, 0.0], [3.0, 6.0, 0.0, 0.0]]
    >>> Row.of("more", "ki", parent=pd).offsets
    (4,)
    """

    name: str
    fields: tuple[tuple[str, int], ...]
    parent: Row | None = None
    prefix: str = ""

    @classmethod
    def of(cls, name: str, *fields: str | tuple[str, int], parent: Row | None = None, prefix: str = "") -> Row:
        """A row from its fields: a name, or (name, width) for a vector field."""
        spec = tuple((f, 1) if isinstance(f, str) else (f[0], int(f[1])) for f in fields)
        names = [f for f, _ in spec] + ([f for f, _ in parent.all_fields] if parent else [])
        if len(set(names)) != len(names) or any(w < 1 for _, w in spec):
            raise ValueError(f"{name}: field names must be unique and widths >= 1, got {fields}")
        return cls(name, spec, parent, prefix)

    @property
    def start(self) -> int:
        """Offset of this row's first own field (the parent's size, else 0)."""
        return self.parent.size if self.parent else 0

    @property
    def all_fields(self) -> tuple[tuple[str, int], ...]:
        """(name, width) of every field, the parent's first."""
        return (self.parent.all_fields if self.parent else ()) + self.fields

    @property
    def offsets(self) -> tuple[int, ...]:
        """Offset of each of this row's own fields (a vector field: its first entry)."""
        out, at = [], self.start
        for _, width in self.fields:
            out.append(at)
            at += width
        return tuple(out)

    @property
    def size(self) -> int:
        """Number of float64 entries of the whole row."""
        return self.start + sum(w for _, w in self.fields)

    @property
    def names(self) -> tuple[str, ...]:
        """One name per entry of the whole row, for tables and JSON (``name[i]`` in a vector)."""
        return tuple(f if w == 1 else f"{f}[{i}]" for f, w in self.all_fields for i in range(w))

    def pack(self, values: Mapping[str, Any], n: int | None = None, default: float | None = None) -> np.ndarray:
        """The row holding ``values`` (field -> number), or with ``n`` one row per vehicle; ``default`` fills
        a missing field."""
        widths = dict(self.all_fields)
        unknown, missing = set(values) - set(widths), set(widths) - set(values)
        if unknown or (missing and default is None):
            raise ValueError(f"{self.name}: unknown fields {sorted(unknown)}, missing {sorted(missing)}")
        rows = 1 if n is None else n
        out = np.full((rows, self.size), np.nan if default is None else float(default))
        at = 0
        for field, width in self.all_fields:
            if field in values:
                value = values[field]
                columns = (
                    [value]
                    if width == 1
                    else list(value.T if isinstance(value, np.ndarray) and value.ndim == 2 else value)
                )
                if len(columns) != width:
                    raise ValueError(f"{self.name}: field {field!r} takes {width} values, got {len(columns)}")
                for j, column in enumerate(columns):
                    out[:, at + j] = np.broadcast_to(column, (rows,))
            at += width
        return out[0] if n is None else out


# --- state: 16 columns -------------------------------------------------------------
# position and velocity in the earth frame (z up), the paper's Euler angles and body
# rates, and the four rotor thrusts (the actuator state): each column's name and unit.
_STATE_UNITS = {
    "x": "m",
    "y": "m",
    "z": "m",
    "vx": "m/s",
    "vy": "m/s",
    "vz": "m/s",
    "phi": "rad",
    "theta": "rad",
    "psi": "rad",
    "p": "rad/s",
    "q": "rad/s",
    "r": "rad/s",
    "F1": "N",
    "F2": "N",
    "F3": "N",
    "F4": "N",
}
STATE = Row.of("state", *_STATE_UNITS)
X, Y, Z, VX, VY, VZ, PHI, THETA, PSI, P, Q, R, F1, F2, F3, F4 = STATE.offsets
STATE_SIZE = STATE.size
STATE_NAMES = STATE.names
STATE_UNITS = tuple(_STATE_UNITS[name] for name in STATE_NAMES)

# --- reference: 11 columns -----------------------------------------------------------
# what a mission asks for at time t: position, velocity, acceleration, yaw and yaw rate.
# Tables name the columns ``x_ref``, ..., ``psi_dot_ref``.
REFERENCE = Row.of("reference", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az", "psi", "psi_dot", prefix="REF_")
REF_X, REF_Y, REF_Z, REF_VX, REF_VY, REF_VZ, REF_AX, REF_AY, REF_AZ, REF_PSI, REF_PSI_DOT = REFERENCE.offsets
REF_SIZE = REFERENCE.size
REF_NAMES = tuple(f"{name}_ref" for name in REFERENCE.names)

# --- command: 12 columns -------------------------------------------------------------
# what a controller returns each control period. Only the four duties drive the plant;
# the rest is for logging and metrics. The engine clips the duties to [0, 1] and counts
# the periods in which it had to (never silently).
COMMAND = Row.of(
    "command",
    *("u1", "u2", "u3", "u4"),  # PWM duties asked of rotors 1..4 [-]
    *("thrust", "tau_phi", "tau_theta", "tau_psi"),  # desired U1 [N], U2 [N], U3 [N], U4 [N m]
    *("phi_d", "theta_d", "psi_d"),  # attitude setpoints [rad]
    "flags",  # controller saturation bit mask
    prefix="CMD_",
)
(
    CMD_U1,
    CMD_U2,
    CMD_U3,
    CMD_U4,
    CMD_THRUST,
    CMD_TAU_PHI,
    CMD_TAU_THETA,
    CMD_TAU_PSI,
    CMD_PHI_D,
    CMD_THETA_D,
    CMD_PSI_D,
    CMD_FLAGS,
) = COMMAND.offsets
CMD_SIZE = COMMAND.size
_CMD_TABLE_NAMES = {"thrust": "U1_d", "tau_phi": "U2_d", "tau_theta": "U3_d", "tau_psi": "U4_d"}
CMD_NAMES = tuple(_CMD_TABLE_NAMES.get(name, name) for name in COMMAND.names)
"""The columns' names in tables: the field's, but U1_d..U4_d for the desired thrust and moments."""

# Bits a controller may set in cmd[CMD_FLAGS]; the engine counts periods with any bit set.
FLAG_TILT_LIMIT = 1  # a roll/pitch setpoint was limited to the tilt limit
FLAG_ASIN_CLIP = 2  # an inverse-model asin argument left [-1, 1] and was clipped
FLAG_THRUST_LIMIT = 4  # the collective thrust was limited
FLAG_INTEGRATOR_HOLD = 8  # anti-windup held an integrator

# --- vehicle parameter row: 21 columns -------------------------------------------------
# The physical parameters; k1..k6 (Section III of the paper) are derived from them when the
# row is built, and so are 1/m and 1/J, so the compiled step never divides; then the drag
# coefficients.
PARAMS = Row.of(
    "vehicle parameters",
    *("m", "jxx", "jyy", "jzz", "l", "k", "omega", "d", "g"),
    *("k1", "k2", "k3", "k4", "k5", "k6", "cd1", "cd2"),
    *("inv_m", "inv_jxx", "inv_jyy", "inv_jzz"),
    prefix="P_",
)
(
    P_M,
    P_JXX,
    P_JYY,
    P_JZZ,
    P_L,
    P_K,
    P_OMEGA,
    P_D,
    P_G,
    P_K1,
    P_K2,
    P_K3,
    P_K4,
    P_K5,
    P_K6,
    P_CD1,
    P_CD2,
    P_INV_M,
    P_INV_JXX,
    P_INV_JYY,
    P_INV_JZZ,
) = PARAMS.offsets
PARAM_SIZE = PARAMS.size

# --- compiled signatures ---------------------------------------------------------------
_f8 = types.float64
_vec = types.float64[::1]

#: ``controller(t, dt, x, ref, vp, gains, mem, cmd) -> None``
#: t: time at the start of the control period [s]; dt: its length [s]; x: the state the
#: controller sees (STATE_SIZE); ref: the mission's reference at t (REF_SIZE); vp: the
#: vehicle parameter row (PARAM_SIZE); gains: the controller's parameters (any length);
#: mem: the controller's memory, kept between periods (any length); cmd: output (CMD_SIZE).
CONTROLLER_SIG = types.void(_f8, _f8, _vec, _vec, _vec, _vec, _vec, _vec)
ControllerType = types.FunctionType(CONTROLLER_SIG)

#: ``mission(t, mp, ref) -> None``: writes the reference at time t [s] into ref (REF_SIZE);
#: mp is the mission's parameter vector.
MISSION_SIG = types.void(_f8, _vec, _vec)
MissionType = types.FunctionType(MISSION_SIG)

# --- external inputs: 13 columns ---------------------------------------------------------
# what a disturbance model supplies each control period (held over the period): an external
# force in the earth frame [N], a torque in the body frame [N m], the wind velocity in the
# earth frame [m/s] (it acts through the vehicle's drag) and each rotor's effectiveness
# (1 = healthy, 0.7 = lost 30 % of its thrust).
EXTERNAL = Row.of(
    "external inputs", "fx", "fy", "fz", "tx", "ty", "tz", "wx", "wy", "wz", "e1", "e2", "e3", "e4", prefix="EXT_"
)
EXT_FX, EXT_FY, EXT_FZ, EXT_TX, EXT_TY, EXT_TZ, EXT_WX, EXT_WY, EXT_WZ, EXT_E1, EXT_E2, EXT_E3, EXT_E4 = (
    EXTERNAL.offsets
)
EXT_SIZE = EXTERNAL.size

#: ``disturbance(t, dt, x, dp, dmem, rng, ext) -> None``: writes the external inputs held
#: over [t, t + dt] into ext (EXT_SIZE). dp: its parameters; dmem: its state (e.g. the
#: turbulence filters), kept between periods; rng: the vehicle's random generator state
#: (see :mod:`quadcruise.sim.rng`); x: the true state.
DISTURBANCE_SIG = types.void(_f8, _f8, _vec, _vec, _vec, types.uint64[::1], _vec)
DisturbanceType = types.FunctionType(DISTURBANCE_SIG)

# --- the observation stage: sensors and an estimator in the period ---------------------
#: ``observer(t, k, logging, x, op, omem, rng, seen, obs) -> None``: at the control instant t [s]
#: (period k of the grid), from the true state x (STATE_SIZE, the paper layout), sample the
#: vehicle's sensors and run its estimator, and write what the controller sees into ``seen``
#: (STATE_SIZE); with ``logging``, write the period's log row into ``obs`` (OBSERVATION_SIZE).
#: op: its parameters; omem: its memory, kept between periods (its first entries
#: :data:`OBSERVER_KERNEL`, written by the kernel); rng: its own generator state (uint64).
OBSERVER_SIG = types.void(_f8, types.int64, types.boolean, _vec, _vec, _vec, types.uint64[::1], _vec, _vec)
ObserverType = types.FunctionType(OBSERVER_SIG)

MAX_VIBRATING_ROTORS = 12
"""The rotors whose imbalance the IMU's vibration term carries (more are left still)."""
OBSERVER_KERNEL = Row.of(
    "observer memory, the kernel's part",
    ("force", 3),
    ("rate", 3),
    ("shake", 3),
    "vibration",
    ("spin", MAX_VIBRATING_ROTORS),
    ("phase", MAX_VIBRATING_ROTORS),
    prefix="OM_",
)
"""The first entries of an observer's memory, written by the kernel at the end of each period (at
period 0, at the start), from the plant's own derivative: the true specific force [m/s^2]
(acceleration minus gravity, FLU body frame) and the body's angular velocity [rad/s] (FLU), what
an IMU measures. (On the paper plant with its simplified kinematics, phi' = p, ..., the angular
velocity of the frame R(phi, theta, psi) is not (p, q, r): it is taken from the Euler rates.)
Then the rotor plant's vibration (:func:`quadcruise.sim.observe.rotor_shake`): the rotors'
imbalance acceleration [m/s^2] averaged over the period just ended (FLU), each rotor's amplitude
at hover [m/s^2] (written by the stage at switch-on; 0: none, nothing else is written), the
rotors' speeds [rad/s] at the period's end and their angles [rad] (drawn by the stage at
switch-on)."""
OM_FORCE, OM_RATE, OM_SHAKE, OM_VIBRATION, OM_SPIN, OM_PHASE = OBSERVER_KERNEL.offsets

_OBSERVATION_UNITS = {
    **{f"{name}_est": _STATE_UNITS[name] for name in ("x", "y", "z", "vx", "vy", "vz", "phi", "theta", "psi")},
    **{f"{name}_est": "rad/s" for name in ("p", "q", "r")},
    **{f"q{c}_est": "-" for c in "wxyz"},
    **{f"gyro_bias_{c}_est": "rad/s" for c in "xyz"},
    **{f"accel_bias_{c}_est": "m/s^2" for c in "xyz"},
    **{f"sd_{name}": unit for name, unit in (("x", "m"), ("y", "m"), ("z", "m"))},
    **{f"sd_{name}": "m/s" for name in ("vx", "vy", "vz")},
    **{f"sd_att_{c}": "rad" for c in "xyz"},
    **{f"sd_gyro_bias_{c}": "rad/s" for c in "xyz"},
    **{f"sd_accel_bias_{c}": "m/s^2" for c in "xyz"},
    "nees_pos": "-",
    "nees_vel": "-",
    "nees_att": "-",
    **{f"gyro_{c}": "rad/s" for c in "xyz"},
    **{f"accel_{c}": "m/s^2" for c in "xyz"},
    "imu_count": "-",
    **{f"gps_{c}": "m" for c in "xyz"},
    **{f"gps_v{c}": "m/s" for c in "xyz"},
    "gps_sample_t": "s",
    "gps_count": "-",
    "baro_alt": "m",
    "baro_count": "-",
    **{f"mag_{c}": "G" for c in "xyz"},
    "mag_count": "-",
    **{f"innov_gps_{c}": "m" for c in "xyz"},
    **{f"innov_gps_v{c}": "m/s" for c in "xyz"},
    "innov_baro": "m",
    "innov_heading": "rad",
    **{f"innov_var_gps_{c}": "m^2" for c in "xyz"},
    **{f"innov_var_gps_v{c}": "m^2/s^2" for c in "xyz"},
    "innov_var_baro": "m^2",
    "innov_var_heading": "rad^2",
    "nis_gps_pos": "-",
    "nis_gps_vel": "-",
    "nis_baro": "-",
    "nis_mag": "-",
}
OBSERVATION = Row.of("observation log", *_OBSERVATION_UNITS, prefix="O_")
"""One logged row of the observation stage: the estimate as the controller sees it (``*_est``:
position, velocity, ZYX Euler angles, body rates), its quaternion (w first, FLU body to ENU
world) and biases, the error state's standard deviations (``sd_*``), the NEES of position,
velocity and attitude against the truth at the last IMU sample (3 dof each), the last reading of
each sensor with a running count of its samples (``*_count``; ``gps_*`` the last fix fused, taken
at ``gps_sample_t``), and the last update's innovations (measured minus predicted), their
variances and NIS (negative: refused by the gate) per stream; NaN where a stream has none yet."""
OBSERVATION_SIZE = OBSERVATION.size
OBSERVATION_NAMES = OBSERVATION.names
OBSERVATION_UNITS = tuple(_OBSERVATION_UNITS[name] for name in OBSERVATION_NAMES)
_O = {name: j for j, name in enumerate(OBSERVATION_NAMES)}
O_X, O_VX, O_PHI, O_P, O_QW = _O["x_est"], _O["vx_est"], _O["phi_est"], _O["p_est"], _O["qw_est"]
O_BG, O_BA, O_SD, O_NEES = _O["gyro_bias_x_est"], _O["accel_bias_x_est"], _O["sd_x"], _O["nees_pos"]
O_GYRO, O_IMU_COUNT = _O["gyro_x"], _O["imu_count"]
O_GPS, O_GPS_T, O_GPS_COUNT = _O["gps_x"], _O["gps_sample_t"], _O["gps_count"]
O_BARO, O_BARO_COUNT, O_MAG, O_MAG_COUNT = _O["baro_alt"], _O["baro_count"], _O["mag_x"], _O["mag_count"]
O_INNOV, O_INNOV_VAR, O_NIS = _O["innov_gps_x"], _O["innov_var_gps_x"], _O["nis_gps_pos"]

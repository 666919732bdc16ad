"""``px4``: PX4's multicopter controller (release v1.15) with PX4's parameters, as an engine
controller (``CONTROLLER_SIG``), batched like the others.

Each control period, for one vehicle, in PX4's frames (NED world, FRD body; the state and the
mission's reference converted at the edge from ENU/FLU, :mod:`quadcruise.control.px4math`):

1. the gyro: the body rates through PX4's ``LowPassFilter2p`` at ``IMU_GYRO_CUTOFF`` (the
   sample rate is the control rate), and their backward difference through the D-term
   ``AlphaFilter`` at ``IMU_DGYRO_CUTOFF`` (:mod:`quadcruise.control.px4filters`);
2. the position loop (:func:`~quadcruise.control.px4loops.position_control`), decimated to
   ``position_rate`` (PX4's runs on each ``vehicle_local_position``, EKF2's 100 Hz with
   ``EKF2_PREDICT_US`` = 10 ms; every period when the control period is longer), its D term
   on the velocity differenced at that rate and low-passed at ``MPC_VELD_LP``
   (``BlockDerivative``); the mission's position, velocity and acceleration are the
   ``trajectory_setpoint``, its yaw and yaw rate the heading and its feed-forward; the thrust
   vector becomes the attitude setpoint (``bodyzToAttitude``) and the collective thrust;
3. the attitude loop (:func:`~quadcruise.control.px4loops.attitude_control`) at
   ``IMU_INTEG_RATE`` (PX4's runs on each ``vehicle_attitude``, which EKF2 publishes at the
   integrated IMU's rate; every period when the control period is longer), its rate setpoint
   held in between;
4. the rate loop (:func:`~quadcruise.control.px4loops.rate_control`), every period (PX4's
   runs at the gyro rate), its integral held in a direction the allocator saturated in the
   period before (``control_allocator_status``), and held while PX4's land detector says
   landed (only with ``takeoff``: other flights start airborne);
5. the allocation (:func:`~quadcruise.control.px4allocation.allocate_into`): the normalised
   torque and thrust through the ``CA_ROTOR*`` geometry's normalised pseudo-inverse with
   PX4's sequential desaturation (``MC_AIRMODE``), each rotor's relative thrust clipped to
   [0, 1], then the command through PX4's thrust model ``THR_MDL_FAC``;
6. the vehicle: each command u becomes the rotor's thrust ``f = T ((1 - a) u + a u^2)``
   (``thrust_curve`` a: 0 for the paper plant's duties, 1 for a rotor-plant vehicle whose
   speed is ``u w_max``; T = 4 K / n the rotor's full thrust), and the rotors' thrusts the
   wrench (T, Mx, My, Mz) of the vehicle's own rotor layout (``rotors``), handed to the engine
   as the duties of its "+" equivalent (for a quadrotor whose layout the controller knows,
   the engine's mixer gives back these very rotor thrusts).

With ``takeoff`` the flight starts on the ground in PX4's takeoff ramp and with
``hover_estimator`` PX4's hover-thrust estimator runs (:mod:`quadcruise.control.px4hover`): both
at the position loop (:func:`~quadcruise.control.px4kernel.px4_controller`); a NaN yaw setpoint
holds the current yaw, as PX4's ``PositionControl`` does.

PX4's default rate gains are for PX4's vehicles: in normalised torque, on a vehicle whose
full torque over inertia is far larger than its rotor lag allows (the paper's 800 rad/s^2
against 15 rad/s, :mod:`quadcruise.control.cascade`) they do not fly. So the controller a
name gives (``Px4()``, the registry's design for a rotor-plant vehicle) keeps every PX4
default but two that depend on the vehicle: ``rate_bandwidth`` > 0 designs the rate P, I, D
per unit inertia for that rotor lag (:func:`~quadcruise.control.cascade.rate_pid_design`)
and converts them to normalised torque with the vehicle row's full torque, and
``hover_from_vehicle`` sets ``MPC_THR_HOVER`` to the relative thrust that holds the vehicle
row's weight, and ``MPC_THR_MIN`` to at most half of it (room to descend; the paper vehicle
hovers at 7 % of its full thrust, the Qball-X4 at 3 %).
:meth:`Px4.from_params` flies PX4's parameters as they are (both off), and
:meth:`Px4.resolved` writes what the two give for a vehicle back as PX4 parameters.

Examples
--------
>>> import quadcruise as qc
>>> res = qc.fly("step", "px4", vehicle="iris", duration=6.0)
>>> res.status_text(), bool(abs(res.final_state[0, 0] - 1.0) < 0.05)
('finished', True)
"""

from __future__ import annotations

import dataclasses
import math
import os
import warnings
from collections.abc import Mapping

import numpy as np

from quadcruise.control.base import Controller
from quadcruise.control.cascade import rate_pid_design
from quadcruise.control.px4allocation import mix_matrix, rotor_effectiveness
from quadcruise.control.px4kernel import (
    MAX_ROTORS,
    PX4C_GAINS,
    PX4C_MEMORY,
    YAW_DESIGN_SHARE,
    px4_controller,
    resolve_gains,
)
from quadcruise.control.px4loops import G_RATE_D, G_RATE_I, G_RATE_P, G_THR_HOVER, G_THR_MIN, PX4_GAINS, px4_gains
from quadcruise.errors import InputError, ParameterWarning
from quadcruise.fields import Check, between
from quadcruise.fields import unit_field as _f
from quadcruise.io.px4defaults import INT32, PX4_PARAMETERS
from quadcruise.io.px4params import Px4Parameters, px4_constrained, read_params

__all__ = ["Px4", "px4_controller", "PX4C_GAINS", "PX4C_MEMORY", "MAX_ROTORS"]


def _x_quad() -> tuple:
    """PX4's quadrotor x, arm 1 m (FLU, direction: +1 turns the body's yaw positively):
    front right and rear left counter-clockwise (``CA_ROTOR*_KM`` > 0), then front left, rear right."""
    h = math.sqrt(0.5)
    return ((h, -h, 0.0, -1.0), (-h, h, 0.0, -1.0), (h, h, 0.0, 1.0), (-h, -h, 0.0, 1.0))


def _rotors_ok(value) -> bool:
    try:
        rows = [tuple(float(v) for v in r) for r in value]
    except (TypeError, ValueError):
        return False
    return len(rows) == 0 or (
        4 <= len(rows) <= MAX_ROTORS and all(len(r) == 4 and all(map(math.isfinite, r)) for r in rows)
    )


class _ParamsCheck(Check):
    """PX4's parameters as stored: a Px4Parameters as given; a path (a scenario file's
    ``params = "x500.params"``) read; a mapping (a result's record, ``{"values": {...}}``, or
    parameters by name) over PX4's defaults, each checked against PX4's range."""

    def convert(self, site, value):
        if isinstance(value, Px4Parameters):
            return value
        if isinstance(value, (str, os.PathLike)):
            return read_params(value)
        if isinstance(value, Mapping):
            values = value.get("values", value)
            if isinstance(values, Mapping):
                source = str(value.get("source", "defaults")) if "values" in value else "defaults"
                p = Px4Parameters.defaults().with_values(**{str(k): v for k, v in values.items()})
                return dataclasses.replace(p, source=source)
        site.fail(self.want, repr(value))


@dataclasses.dataclass(frozen=True)
class Px4(Controller):
    """PX4's multicopter controller (v1.15) with PX4's parameters (module docstring).

    Parameters
    ----------
    params : Px4Parameters
        PX4's parameters by name, PX4's units (:func:`quadcruise.io.px4params.read_params`);
        PX4 v1.15's defaults. A path is read, a mapping set over the defaults (a scenario
        file's ``[controller]`` ``params = "x500.params"``).
    rotors : tuple
        The vehicle's rotors (x, y, z [m], direction), FLU, in PX4's order (``CA_ROTOR0`` first),
        as :class:`~quadcruise.model.rotor_vehicle.RotorVehicle` gives them; () is PX4's
        quadrotor x scaled to the vehicle row's arm. The allocation uses ``CA_ROTOR*`` where
        ``CA_ROTOR_COUNT`` is set, else this layout.
    hover_from_vehicle : bool
        ``MPC_THR_HOVER`` from the vehicle row's weight over its full thrust (True), or the parameter.
    rate_bandwidth : float
        > 0: the rate P, I, D designed for a rotor lag of this bandwidth [rad/s] and converted to
        normalised torque with the vehicle row's full torque; 0: PX4's ``MC_*RATE_*`` as given.
    thrust_curve : float
        The flown vehicle's thrust per command, ``(1 - a) u + a u^2`` [-]: 0 the paper plant's
        duties, 1 a rotor-plant vehicle (speed ``u w_max``).
    position_rate : float
        The position loop's rate [Hz] (EKF2's 100 Hz).
    hover_estimator : bool
        Run PX4's hover-thrust estimator (:mod:`quadcruise.control.px4hover`) where ``MPC_USE_HTE``
        is 1, its estimate replacing ``MPC_THR_HOVER`` once valid and flying (``MPC_USE_HTE``,
        ``HTE_*``); off by default (flights then fly ``MPC_THR_HOVER`` as before).
    takeoff : bool
        Start on the ground at the first step of PX4's takeoff ramp (``MPC_TKO_RAMP_T``,
        ``MPC_TILTMAX_LND``), landed as PX4's land detector sees it until the thrust setpoint
        lifts (the rate integral held while landed), flying when the ramp ends
        (:func:`~quadcruise.control.px4kernel.px4_controller`). For a flight that starts on a
        ground (``px4-check --fly``, :func:`quadcruise.workflows.px4fly.fly_takeoff`), not from a hover.
    takeoff_speed_up : float
        The climb rate the ramp ends at [m/s] (the flight task's ``vehicle_constraints.speed_up``);
        0: ``MPC_Z_VEL_MAX_UP``.

    Examples
    --------
    >>> c = Px4()
    >>> c.gains().shape, c.memory().shape
    ((253,), (133,))
    >>> Px4(thrust_curve=2.0)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: px4 parameter 'thrust_curve' (the flown vehicle's thrust curve ...
    """

    name = "px4"
    memory_size = PX4C_MEMORY.size

    params: Px4Parameters = _f(
        unit="-",
        doc="PX4's parameters by name",
        check=_ParamsCheck("params", "PX4 parameters: a .ulg or .params path, or a mapping name -> value"),
        factory=Px4Parameters.defaults,
    )
    rotors: tuple = _f(
        (),
        "m",
        "the vehicle's rotors (x, y, z, direction), FLU",
        Check("rotors", "4 to 12 rows of 4 numbers", _rotors_ok),
    )
    hover_from_vehicle: bool = _f(True, "-", "MPC_THR_HOVER from the vehicle's weight", "flag")
    rate_bandwidth: float = _f(15.0, "rad/s", "rotor lag the rate gains are designed for (0: PX4's)", "nonneg")
    thrust_curve: float = _f(0.0, "-", "the flown vehicle's thrust curve (1 - a) u + a u^2", between(0.0, 1.0))
    position_rate: float = _f(100.0, "Hz", "position loop rate", "pos")
    hover_estimator: bool = _f(False, "-", "PX4's hover-thrust estimator (with MPC_USE_HTE = 1)", "flag")
    takeoff: bool = _f(False, "-", "start on the ground in PX4's takeoff ramp, with its land detector", "flag")
    takeoff_speed_up: float = _f(0.0, "m/s", "the takeoff ramp's target climb rate (0: MPC_Z_VEL_MAX_UP)", "nonneg")

    @property
    def function(self):
        """The compiled law, :func:`px4_controller` (``CONTROLLER_SIG``)."""
        return px4_controller

    @classmethod
    def from_params(cls, params, vehicle=None, **fields) -> Px4:
        """PX4 with the parameters of a log, a ``.params`` file or a mapping, as they are.

        Parameters
        ----------
        params : str, os.PathLike, Px4Parameters or Mapping
            A ULog or QGroundControl file (:func:`~quadcruise.io.px4params.read_params`), or
            parameters by name (PX4's defaults for the others).
        vehicle : RotorVehicle or Vehicle, optional
            The vehicle flown: a RotorVehicle gives its rotor layout and ``thrust_curve`` 1.
        **fields
            Other fields (``position_rate``, ...).

        Returns
        -------
        Px4
            ``hover_from_vehicle`` False and ``rate_bandwidth`` 0 unless given.

        Raises
        ------
        InputError
            A bad file or value (one line naming it), or ``CA_ROTOR*`` that do not fit the vehicle.

        Warns
        -----
        ParameterWarning
            Once, for a file read here: its notes (another release's log, older names), the
            values PX4 constrains (:func:`~quadcruise.io.px4params.px4_constrained`) and the
            parameters the loops do not use, as ``--params`` prints them. Parameters already
            read (a :class:`Px4Parameters`) are the caller's to tell.
        """
        from quadcruise.sim import plants

        if isinstance(params, Px4Parameters):
            p = params
        elif isinstance(params, Mapping):
            p = Px4Parameters.defaults().with_values(**{str(k): v for k, v in params.items()})
        else:
            p = read_params(params)
            told = [*p.notes, *(f"{p.source}: {note}" for note in px4_constrained(p)[1])]
            if p.unused:
                told.append(
                    f"{len(p.unused)} parameters of {p.source} are not used by the px4 controller: "
                    + ", ".join(p.unused)
                )
            if told:
                warnings.warn("\n".join(told), ParameterWarning, stacklevel=2)
        base = {"params": p, "hover_from_vehicle": False, "rate_bandwidth": 0.0}
        if vehicle is not None:  # what PX4's CA_ROTOR* and THR_MDL_FAC say of the vehicle's plant
            base.update(plants.of(vehicle).px4_fields(vehicle))
        base.update(fields)
        out = cls(**base)
        out.geometry()  # CA_ROTOR* checked against the vehicle, before any flight
        return out

    def geometry(self) -> tuple[np.ndarray, np.ndarray]:
        """The allocation's geometry and the vehicle's layout.

        Returns
        -------
        effectiveness : numpy.ndarray, shape (6, n)
            PX4's effectiveness matrix (``CA_ROTOR*``, else from ``rotors``: ``PX = x``,
            ``PY = -y``, ``KM = -direction``).
        layout : numpy.ndarray, shape (n, 4)
            ``rotors`` (or PX4's quadrotor x, arm 1), FLU.

        Raises
        ------
        InputError
            ``CA_ROTOR_COUNT`` other than the vehicle's rotors, or a ``CA_ROTOR`` on another
            side of the body or turning the other way than the vehicle's rotor of that number.
        """
        layout = np.array(self.rotors if self.rotors else _x_quad(), float)
        n = len(layout)
        p = self.params
        count = int(p["CA_ROTOR_COUNT"])
        if count == 0:
            pos = np.column_stack([layout[:, 0], -layout[:, 1], np.zeros(n)])
            axes = np.tile([0.0, 0.0, -1.0], (n, 1))
            return rotor_effectiveness(pos, axes, np.ones(n), -layout[:, 3] * 0.05), layout
        if count != n:
            had = f"the vehicle has {n} rotors" if self.rotors else "no rotor layout given: PX4's quadrotor x has 4"
            raise InputError(
                f"{p.source}: CA_ROTOR_COUNT = {count}, {had} (give the vehicle's own "
                "geometry, or set CA_ROTOR_COUNT = 0 to allocate on the vehicle's layout)"
            )
        pos = np.array([[p[f"CA_ROTOR{i}_P{c}"] for c in "XYZ"] for i in range(n)])
        axes = np.array([[p[f"CA_ROTOR{i}_A{c}"] for c in "XYZ"] for i in range(n)])
        ct = np.array([p[f"CA_ROTOR{i}_CT"] for i in range(n)])
        km = np.array([p[f"CA_ROTOR{i}_KM"] for i in range(n)])
        # a coordinate within a thousandth of the arm of an axis is on it (a file's -1e-8 is 0)
        tol = 1e-3 * max(float(np.max(np.hypot(layout[:, 0], layout[:, 1]))), float(np.max(np.hypot(*pos[:, :2].T))))
        side = lambda v: 0.0 if abs(v) <= tol else np.sign(v)  # noqa: E731
        for i in range(n):
            same = (
                side(pos[i, 0]) == side(layout[i, 0])
                and side(pos[i, 1]) == -side(layout[i, 1])
                and np.sign(km[i]) == -np.sign(layout[i, 3])
            )
            if not same:
                raise InputError(
                    f"{p.source}: CA_ROTOR{i} (PX {pos[i, 0]:g}, PY {pos[i, 1]:g} m FRD, KM {km[i]:g}) is not the "
                    f"vehicle's rotor {i + 1} (x {layout[i, 0]:g}, y {layout[i, 1]:g} m FLU, direction "
                    f"{layout[i, 3]:g}): PX4 numbers its rotors from 0 in the vehicle's order"
                )
        return rotor_effectiveness(pos, axes, ct, km), layout

    def gains(self) -> np.ndarray:
        """The parameter vector :func:`px4_controller` reads (:data:`PX4C_GAINS`).

        Returns
        -------
        numpy.ndarray
            :data:`PX4C_GAINS` (253) float64 entries: PX4's loops' gains in SI units, the
            allocation, the vehicle's layout, the filters and the flags (see the row).
        """
        p = px4_constrained(self.params)[0]  # MPC_THR_HOVER, MPC_TILTMAX_LND as PX4 constrains them
        eff, layout = self.geometry()
        n = len(layout)
        mix, scale = mix_matrix(eff)
        arm = float(np.mean(np.hypot(layout[:, 0], layout[:, 1])))
        rows = [0, 1, 2, 5]
        alloc = (eff[rows].T * scale[rows]).ravel()
        geom = np.column_stack([layout[:, 1] / arm, -layout[:, 0] / arm, layout[:, 3]]).ravel()
        pad = lambda v, width: np.concatenate([v, np.zeros(width * MAX_ROTORS - v.size)])  # noqa: E731
        rp, yaw = rate_pid_design(self.rate_bandwidth or 15.0), rate_pid_design(self.rate_bandwidth or 15.0, yaw=True)
        yaw = dataclasses.replace(yaw, kp=YAW_DESIGN_SHARE * yaw.kp, ki=YAW_DESIGN_SHARE * yaw.ki)
        values = dict(zip((f for f, _ in PX4_GAINS.fields), np.split(px4_gains(p), PX4_GAINS.offsets[1:]), strict=True))
        values = {k: (v[0] if v.size == 1 else v) for k, v in values.items()}
        values.update(
            n_rotors=n,
            mix=pad(mix.ravel(), 6),
            alloc=pad(alloc, 4),
            geom=pad(geom, 3),
            lo=np.zeros(MAX_ROTORS),
            hi=np.concatenate([np.ones(n), np.zeros(MAX_ROTORS - n)]),
            airmode=p["MC_AIRMODE"],
            thr_mdl_fac=p["THR_MDL_FAC"],
            thrust_curve=self.thrust_curve,
            gyro_cutoff=p["IMU_GYRO_CUTOFF"],
            dgyro_cutoff=p["IMU_DGYRO_CUTOFF"],
            veld_lp=p["MPC_VELD_LP"],
            pos_period=1.0 / self.position_rate,
            att_period=1.0 / p["IMU_INTEG_RATE"],
            hover_auto=float(self.hover_from_vehicle),
            designed=float(self.rate_bandwidth > 0.0),
            design=[rp.kp, rp.ki, rp.kd, rp.kp, rp.ki, rp.kd, yaw.kp, yaw.ki, yaw.kd],
            hte=float(self.hover_estimator and p["MPC_USE_HTE"] == 1),
            takeoff=float(self.takeoff),
            tko_ramp_t=p["MPC_TKO_RAMP_T"],
            tko_speed_up=self.takeoff_speed_up or p["MPC_Z_VEL_MAX_UP"],
            tilt_lnd=math.radians(p["MPC_TILTMAX_LND"]),
            hte_noise=p["HTE_HT_NOISE"],
            hte_gate=p["HTE_ACC_GATE"],
            hte_err_init=p["HTE_HT_ERR_INIT"],
            hte_vxy=p["HTE_VXY_THR"],
            hte_vz=p["HTE_VZ_THR"],
            hte_range=p["HTE_THR_RANGE"],
        )
        return PX4C_GAINS.pack(values)

    def loop_gains(self, vehicle) -> np.ndarray:
        """The loops' gains (:data:`~quadcruise.control.px4loops.PX4_GAINS`) this controller
        flies ``vehicle`` with: what the first period computes.

        Parameters
        ----------
        vehicle : Vehicle
            A paper vehicle (a rotor vehicle's :func:`~quadcruise.model.equivalent.paper_equivalent`).

        Returns
        -------
        numpy.ndarray
        """
        g = np.zeros(PX4_GAINS.size)
        resolve_gains(self.gains(), np.asarray(vehicle.rows()[0], float), g)
        return g

    def resolved(self, vehicle) -> Px4:
        """The same controller with its vehicle-dependent gains written as PX4 parameters
        (``MC_*RATE_P/I/D`` with ``MC_*RATE_K`` = 1, ``MPC_THR_HOVER``, ``MPC_THR_MIN``), both flags off.

        Parameters
        ----------
        vehicle : Vehicle
            The paper vehicle it flies (a rotor vehicle's paper equivalent).

        Returns
        -------
        Px4

        Raises
        ------
        InputError
            A resolved value outside PX4's range (named).
        """
        params = self.params.with_values(**self._design_values(vehicle))
        return dataclasses.replace(self, params=params, hover_from_vehicle=False, rate_bandwidth=0.0)

    def _design_values(self, vehicle) -> dict:
        """The vehicle-dependent gains as PX4 parameters, unchecked (:meth:`resolved`)."""
        g = self.loop_gains(vehicle)
        values = {}
        if self.rate_bandwidth > 0.0:
            for a, axis in enumerate(("ROLL", "PITCH", "YAW")):
                values[f"MC_{axis}RATE_K"] = 1.0
                for k, off in (("P", G_RATE_P), ("I", G_RATE_I), ("D", G_RATE_D)):
                    values[f"MC_{axis}RATE_{k}"] = float(g[off + a])
        if self.hover_from_vehicle:
            values["MPC_THR_HOVER"] = float(g[G_THR_HOVER])
            values["MPC_THR_MIN"] = float(g[G_THR_MIN])
        return values

    def log_parameters(self, vehicle) -> dict:
        """Every PX4 parameter this controller flies ``vehicle`` with, as a PX4 log holds them:
        :attr:`params` with the vehicle-dependent design written in (:meth:`resolved`), by
        PX4's names and types (``int`` for PX4's INT32, ``float`` else).

        A design outside PX4's range is written as it is: reading the log back
        (:func:`~quadcruise.io.px4params.read_params`) then refuses it, naming the parameter.

        Parameters
        ----------
        vehicle : Vehicle
            The paper vehicle it flies (a rotor vehicle's paper equivalent).

        Returns
        -------
        dict
            Name -> value.

        Examples
        --------
        >>> import quadcruise as qc
        >>> p = Px4(hover_from_vehicle=False, rate_bandwidth=0.0).log_parameters(qc.Vehicle.paper())
        >>> p["MC_ROLLRATE_P"], p["CA_ROTOR_COUNT"]
        (0.15, 0)
        """
        values = dict(self.params.values)
        values.update(self._design_values(vehicle))
        return {k: int(round(v)) if PX4_PARAMETERS[k].kind == INT32 else float(v) for k, v in values.items()}

"""What a plant is, once: :class:`Plant`, the description each plant module fills in
(:mod:`~quadcruise.sim.plants.paper`, :mod:`~quadcruise.sim.plants.rotor`).

A plant is the vehicle's dynamics as the engine flies them: its state, parameter and carry
layouts (``layout.Row``), its compiled kernel and the function that flies a batch through it in
pieces, what the controller and the log see of it (the paper layout), its own checks, the
columns it adds to a flight's log, how its vehicles' rows are built, and what it refuses and
why. Code outside ``sim/plants/`` asks a plant (:func:`quadcruise.sim.plants.of`) rather than
which plant it has.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.layout import Row


@dataclass(frozen=True, eq=False)
class Plant:
    """One plant, described once (its subclass holds the code that differs).

    Parameters
    ----------
    name : str
        ``"paper"`` or ``"rotor"``: the ``plant`` key of a vehicle file and of a flight's record.
    vehicle_class : type
        The class of its vehicles (``Vehicle``, ``RotorVehicle``).
    state, params : layout.Row
        Its state and its vehicle parameter row, as the compiled plant reads them.
    carry : layout.Row or None
        What its kernel carries from one call to the next ahead of the sensor ring buffer
        (None: the ring buffer alone).
    fly_pieces : callable
        ``fly_pieces(n, args, pieces_per_thread, after_piece, threads)``: a batch flown through
        the plant's compiled kernel (one vehicle or N) in pieces over numba's threads.
    kernel_args : type
        The kernel's arguments by name (:mod:`quadcruise.sim.kernel_args`).
    command : str
        What becomes of the controller's command (for docs and messages).
    saturation : str
        What its saturation time measures, as a warning says it.
    takes_speeds : bool
        Its open-loop replay takes rotor speeds [rad/s] (else duties).
    replay_step : float
        Its replay's default longest RK4 substep [s] (docs/vehicles.md, "Step").
    default_preset : str or None
        The preset of its default vehicle (``"paper"``: Table I), which bare ``KEY=VALUE`` fields
        of the command line change; None: it has none (they change the flown vehicle).
    refuses : mapping of str to str
        Options it refuses, each with the reason (:meth:`refuse`).
    drag_for_wind : bool
        Wind acts on its vehicles through drag they are given (``disturbances.with_drag``);
        else through aerodynamics of their own (:meth:`check_environment`).
    designs_gains : bool
        A controller given by name gets gains designed for the believed vehicle's motor
        bandwidth (the paper plant flies the controllers' defaults, designed for its vehicle).
    """

    name: str
    vehicle_class: type
    state: Row
    params: Row
    carry: Row | None
    fly_pieces: Callable
    kernel_args: type
    command: str
    saturation: str
    takes_speeds: bool
    replay_step: float
    default_preset: str | None = None
    refuses: Mapping[str, str] = field(default_factory=dict)
    drag_for_wind: bool = False
    designs_gains: bool = False

    def refuse(self, where: str, option: str, value: Any, label: str = "argument") -> None:
        """Raise one InputError line if ``option`` is given (truthy) and this plant refuses it.

        Parameters
        ----------
        where : str
            The caller, e.g. ``"fly()"``.
        option : str
            The option's name.
        value : Any
            Its value (None or False: not given).
        label : str
            ``"argument"`` or ``"field"``: how the caller names its options.

        Raises
        ------
        InputError
            ``"<where> <label> <option>: <why>"``.
        """
        if value and option in self.refuses:
            name = option if label == "argument" else f"'{option}'"
            raise InputError(f"{where} {label} {name}: {self.refuses[option]}")

    def refuse_sensors(self, where: str, sensors: Any) -> None:
        """Raise one InputError line if an IMU of ``sensors`` (a Sensors, a sequence of them, or
        anything else: nothing to check) has a vibration term this plant refuses.

        Parameters
        ----------
        where : str
            The caller and its argument, e.g. ``"fly() argument sensors"``.
        sensors : Any
            The sensor models.

        Raises
        ------
        InputError
            ``"<where>: imu field 'vibration': <why>"``.
        """
        for each in sensors if isinstance(sensors, (tuple, list)) else (sensors,):
            imu = getattr(each, "imu", None)
            self.refuse(f"{where}: imu", "vibration", imu is not None and imu.vibration > 0, label="field")

    # --- the vehicles -------------------------------------------------------------------
    def vehicles(self, vehicle: Any) -> tuple:
        """The flown vehicle(s) as a tuple.

        Parameters
        ----------
        vehicle : Vehicle, RotorVehicle or tuple of RotorVehicle
            ``fly``'s vehicle.

        Returns
        -------
        tuple
            One entry for one vehicle (a batched paper Vehicle is one), else one per vehicle.
        """
        return vehicle if isinstance(vehicle, tuple) else (vehicle,)

    def count(self, vehicle: Any) -> int | None:
        """How many vehicles ``vehicle`` holds.

        Parameters
        ----------
        vehicle : Vehicle, RotorVehicle or tuple of RotorVehicle
            ``fly``'s vehicle.

        Returns
        -------
        int or None
            None: one vehicle, flown by as many as asked.
        """
        return None

    def describe(self, vehicle: Any) -> str | None:
        """A report's words for a vehicle of this plant.

        Parameters
        ----------
        vehicle : Vehicle or RotorVehicle
            One vehicle.

        Returns
        -------
        str or None
            None where the plant needs no saying (the paper's).
        """
        return None

    def longest_step(self, vehicle: Any, dt: float) -> float:
        """The default longest RK4 substep at a control period.

        Parameters
        ----------
        vehicle : Vehicle or RotorVehicle
            The vehicle.
        dt : float
            The control period [s].

        Returns
        -------
        float
            [s]: the period itself here.
        """
        return dt

    def px4_fields(self, vehicle: Any) -> dict:
        """The fields of a PX4 controller built for the vehicle (``control.px4.Px4.from_params``).

        Parameters
        ----------
        vehicle : Vehicle or RotorVehicle
            The vehicle.

        Returns
        -------
        dict
            None here: the controller's own ("x" geometry, THR_MDL_FAC 0: thrust proportional to the duty).
        """
        return {}

    def file_fields(self, fields: dict) -> dict:
        """A vehicle file's ``[vehicle]`` table.

        Parameters
        ----------
        fields : dict
            The vehicle's fields (``to_dict``).

        Returns
        -------
        dict
            ``plant`` first, then the fields.
        """
        return {"plant": self.name, **fields}

    def n_rotors(self, vehicle: Any) -> int:
        """The vehicle's number of rotors.

        Parameters
        ----------
        vehicle : Vehicle or RotorVehicle
            The vehicle.

        Returns
        -------
        int
        """
        return vehicle.n_rotors

    def log_width(self, vehicles: tuple) -> int:
        """Columns a flight logs beyond the paper layout's: the plant's own state.

        Parameters
        ----------
        vehicles : tuple
            The flown vehicles (:meth:`vehicles`).

        Returns
        -------
        int
            0 here.
        """
        return 0

    def check_vehicles(self, vehicles: tuple) -> None:
        """The plant's own checks of its vehicles before a flight (none here).

        Parameters
        ----------
        vehicles : tuple
            The flown vehicles (:meth:`vehicles`).
        """

    def check_environment(self, vehicles: tuple, environment: Any) -> None:
        """Refuse disturbances the vehicles would not feel, in one InputError line (none here).

        Parameters
        ----------
        vehicles : tuple
            The flown vehicles (:meth:`vehicles`).
        environment : Environment, CustomDisturbance or None
            The disturbances.
        """

    def check_x0(self, vehicles: tuple, x0: np.ndarray, n: int) -> None:
        """Refuse paper-layout initial states the plant cannot start from, in one InputError line (none here).

        Parameters
        ----------
        vehicles : tuple
            The flown vehicles (:meth:`vehicles`).
        x0 : numpy.ndarray
            (16,) or (n, 16) paper-layout states.
        n : int
            Number of vehicles.
        """

    def equivalent(self, vehicles: tuple) -> Any:
        """The paper-layout vehicle the controller believes, whose hover starts a flight.

        Parameters
        ----------
        vehicles : tuple
            The vehicles (:meth:`vehicles`).

        Returns
        -------
        Vehicle
            A paper vehicle itself (one, or batched) here.
        """
        return vehicles[0]

    def record(self, vehicles: tuple) -> dict:
        """The flown vehicles as a flight's record holds them.

        Parameters
        ----------
        vehicles : tuple
            The flown vehicles (:meth:`vehicles`).

        Returns
        -------
        dict
        """
        return vehicles[0].to_dict()

    def controller_record(self, vehicle: Any) -> dict:
        """The controller's vehicle as a flight's record holds it.

        Parameters
        ----------
        vehicle : Vehicle or RotorVehicle
            The vehicle the controller believes.

        Returns
        -------
        dict
        """
        return vehicle.to_dict()

    def check_controller_vehicle(self, flown: tuple, believed: Any, where: str = "fly():") -> None:
        """Refuse a controller vehicle this plant's commands would not fit, in one InputError line.

        Parameters
        ----------
        flown : tuple
            The flown vehicles (:meth:`vehicles`).
        believed : Vehicle, RotorVehicle or None
            The vehicle the controller believes (None: each its own).
        where : str
            The start of the message.
        """
        if believed is not None and not isinstance(believed, self.vehicle_class):
            raise InputError(
                f"{where} vehicle and controller_vehicle must be of one plant: a RotorVehicle flown with a "
                "RotorVehicle as the controller's model, or a paper Vehicle with a paper Vehicle".lstrip()
            )

    def bandwidths(self, believed: tuple) -> list[float]:
        """The motor bandwidths a named controller is designed for (:attr:`designs_gains`).

        Parameters
        ----------
        believed : tuple
            The vehicles the controller believes.

        Returns
        -------
        list of float
            [rad/s], one per vehicle; none here.
        """
        return []

    # --- a flight -------------------------------------------------------------------------
    def flight(self, grid, vehicle, controller_vehicle, controller, gains, mission, mp, n, *, x0, paper_x0, meta, **kw):
        """The arrays of one flight of ``n`` vehicles.

        Parameters
        ----------
        grid : numpy.ndarray
            The control instants [s].
        vehicle, controller_vehicle : Vehicle, RotorVehicle, tuple or None
            The flown vehicle(s) and the one the controller believes.
        controller : compiled function
            The controller's law (``CONTROLLER_SIG``).
        gains : numpy.ndarray
            Its gains, one row or one per vehicle.
        mission : Mission
            The (first) mission.
        mp : numpy.ndarray
            Mission parameter rows.
        n : int
            Number of vehicles.
        x0 : numpy.ndarray or None
            The paper-layout initial states given (None: hovering at the mission's start).
        paper_x0 : numpy.ndarray
            The paper-layout initial states flown (``x0`` or the hover).
        meta : dict or None
            The flight's record, which the plant may add to.
        **kw : Any
            ``full_dynamics``.

        Returns
        -------
        tuple
            ``(args, options)``: the positional arguments of :func:`~quadcruise.sim.engine.simulate`
            (and of the Stepper) and the plant's own keywords.
        """
        raise NotImplementedError

    def check_arrays(self, where: str, args: tuple, options: dict) -> None:
        """Check the arrays given to :func:`quadcruise.simulate` for this plant, beyond what
        :meth:`fly` checks itself (none here: the paper plant's engine checks its own).

        Parameters
        ----------
        where : str
            The caller, e.g. ``"simulate()"``.
        args : tuple
            :meth:`flight`'s positional arguments, as given.
        options : dict
            The keywords given.

        Raises
        ------
        InputError
            One line naming the argument that does not fit the plant.
        """

    def fly(self, args: tuple, options: dict) -> Any:
        """The flight with its whole log (at ``log_every``).

        Parameters
        ----------
        args : tuple
            :meth:`flight`'s positional arguments.
        options : dict
            The engine's keywords with :meth:`flight`'s own.

        Returns
        -------
        SimResult
        """
        raise NotImplementedError

    # --- the Stepper (sim/stepper.py) -----------------------------------------------------
    def stepper_inputs(self, stepper, t_grid, x0, vp, gains, mp, vp_ctrl, shared: dict, own: dict) -> dict:
        """Check a Stepper's arrays and set the plant's own on it (its carry among them).

        Parameters
        ----------
        stepper : Stepper
            The Stepper being made.
        t_grid, x0, vp, gains, mp, vp_ctrl : array_like
            As the Stepper takes them.
        shared : dict
            The keywords of every plant (memories, disturbance, seed, sensors, ``max_step``).
        own : dict
            The plant's own keywords (``alloc``, ``psi0``, ``touchdown_speed``, ``full_dynamics``) and ``periods``.

        Returns
        -------
        dict
            :func:`~quadcruise.sim.inputs.batch_inputs`'s arrays.
        """
        raise NotImplementedError

    def observed(self, stepper) -> np.ndarray:
        """What the controller and the log see of a Stepper's state.

        Parameters
        ----------
        stepper : Stepper
            The Stepper.

        Returns
        -------
        numpy.ndarray
            (N, 16): the paper layout (here the state itself).
        """
        return stepper.state

    def restart(self, stepper, rows: np.ndarray, start: np.ndarray) -> None:
        """Set vehicles of a Stepper back to new initial states (their carry made afresh).

        Parameters
        ----------
        stepper : Stepper
            The Stepper.
        rows : numpy.ndarray
            The vehicles' indices.
        start : numpy.ndarray
            Their initial states, one row each.
        """
        raise NotImplementedError

    def step_args(self, stepper, shared: dict) -> tuple:
        """The kernel's arguments for one Stepper step.

        Parameters
        ----------
        stepper : Stepper
            The Stepper.
        shared : dict
            The arguments of every plant's kernel, by name.

        Returns
        -------
        tuple
            A :attr:`kernel_args`.
        """
        raise NotImplementedError

    def own_logs(self, stepper) -> tuple:
        """A Stepper's logs of the plant's own state, beyond the paper layout's.

        Parameters
        ----------
        stepper : Stepper
            The Stepper.

        Returns
        -------
        tuple of numpy.ndarray
            None here.
        """
        return ()

    def result_parts(self, stepper, logs: tuple, names: tuple) -> dict:
        """A SimResult's fields for the plant's own state.

        Parameters
        ----------
        stepper : Stepper
            The Stepper that flew.
        logs : tuple of numpy.ndarray
            The whole logs of :meth:`own_logs`.
        names : tuple of str
            The own state's column names.

        Returns
        -------
        dict
            None here.
        """
        return {}


__all__ = ["Plant"]

"""What a simulation returns: named arrays for N vehicles, their exit status, and the
configuration that produced them.

Examples
--------
>>> import quadcruise as qc
>>> res = qc.replay(qc.CommandSchedule(t=[0.0, 0.5], duties=[[0.0] * 4] * 2))
>>> res.n, res.ok.tolist(), res.status_text(0)
(1, [True], 'finished')
>>> round(float(res.state("z")[0, -1]), 4)   # free fall for 0.5 s: -g t^2 / 2
-1.2262
>>> list(res.to_pandas().columns[:4])
['vehicle', 't', 'x', 'y']
"""

from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.layout import CMD_NAMES, OBSERVATION_NAMES, REF_NAMES, STATE_NAMES
from quadcruise.metrics.summary import Summary
from quadcruise.sim.status import STATUS_REASONS, ExitStatus


@dataclass(frozen=True, eq=False)
class SimResult:
    """Logged flight of N vehicles.

    The engine builds it (:func:`quadcruise.simulate`, :func:`quadcruise.fly`, ...); the
    columns of the arrays are named in :mod:`quadcruise.layout`.

    Parameters
    ----------
    t : ndarray, shape (L,)
        Logged instants [s].
    states : ndarray, shape (N, L, 16)
        State at each instant (SI units of :data:`~quadcruise.layout.STATE_UNITS`; NaN
        after a vehicle stopped).
    commands : ndarray, shape (N, L, 12)
        Controller output computed at each instant (duties [-], U1..U3 [N], U4 [N m],
        attitude setpoints [rad], flags).
    references : ndarray, shape (N, L, 11)
        Mission reference at each instant ([m], [m/s], [m/s^2], [rad], [rad/s]).
    final_state : ndarray, shape (N, 16)
        State when each vehicle finished or stopped.
    status : ndarray of int, shape (N,)
        Exit status code, 0 = finished (see :class:`~quadcruise.ExitStatus`).
    t_stop : ndarray, shape (N,)
        Time each vehicle finished or stopped [s].
    memory : ndarray, shape (N, C)
        The controllers' memory at the end.
    duty_clipped_s : ndarray, shape (N,)
        Time [s] during which a commanded duty was clipped to [0, 1] (a rotor-plant vehicle:
        a commanded rotor speed held in [w_min, w_max]).
    controller_limited_s : ndarray, shape (N,)
        Time [s] during which the controller flagged a limit.
    meta : dict
        The configuration, seed and version that produced the result.
    disturbance_memory : ndarray, shape (N, D), optional
        The disturbance models' state at the end.
    rotor_states : ndarray, shape (N, L, 13 + n), optional
        A rotor-plant vehicle's own state at each instant (:mod:`quadcruise.model.rotor_plant`:
        position, velocity, quaternion, body rates, rotor speeds), beside ``states``, which
        hold it in the paper's layout (Euler angles, F1..F4 the thrusts of rotors 1..4);
        None for the paper's plant.
    rotor_final_state : ndarray, shape (N, 13 + n), optional
        The rotor state when each vehicle finished or stopped.
    rotor_names : tuple of str
        The columns of ``rotor_states``.
    observations : ndarray, shape (N, L, OBSERVATION_SIZE), optional
        A flight on sensors and an estimator: the log of its observation stage at each instant
        (:data:`~quadcruise.layout.OBSERVATION_NAMES`: the estimate as the controller saw it,
        ``x_est`` ..., its standard deviations, NEES, the sensors' readings, the innovations).
    """

    t: np.ndarray
    states: np.ndarray
    commands: np.ndarray
    references: np.ndarray
    final_state: np.ndarray
    status: np.ndarray
    t_stop: np.ndarray
    memory: np.ndarray
    duty_clipped_s: np.ndarray
    controller_limited_s: np.ndarray
    meta: dict = field(default_factory=dict)
    disturbance_memory: np.ndarray | None = None
    rotor_states: np.ndarray | None = None
    rotor_final_state: np.ndarray | None = None
    rotor_names: tuple = ()
    observations: np.ndarray | None = None

    @property
    def n(self) -> int:
        """Number of vehicles, N."""
        return self.states.shape[0]

    @property
    def ok(self) -> np.ndarray:
        """(N,) True where the vehicle flew its whole mission within every bound (status finished)."""
        return self.status == 0

    @property
    def stopped(self) -> np.ndarray:
        """(N,) True where the engine stopped the vehicle early (its later log rows are NaN).

        Returns
        -------
        numpy.ndarray of bool
        """
        return np.array([ExitStatus(int(code)).stopped for code in self.status], dtype=bool)

    def exit_status(self, i: int = 0) -> ExitStatus:
        """Vehicle i's exit status.

        Parameters
        ----------
        i : int
            The vehicle's index.

        Returns
        -------
        ExitStatus
            Its code and reason.
        """
        return ExitStatus(int(self.status[i]))

    def status_text(self, i: int = 0) -> str:
        """Why vehicle i stopped, and when.

        Parameters
        ----------
        i : int
            The vehicle's index.

        Returns
        -------
        str
            ``"finished"``, or the reason and the time, e.g. ``"diverged: body rate left
            the bound at t = 0.3120 s"``.
        """
        code = int(self.status[i])
        if code == 0:
            return STATUS_REASONS[0]
        return f"{STATUS_REASONS[code]} at t = {self.t_stop[i]:.4f} s"

    def state(self, name: str) -> np.ndarray:
        """The trace of one state, reference or command column, by name.

        Parameters
        ----------
        name : str
            A name of :data:`~quadcruise.layout.STATE_NAMES`, ``REF_NAMES`` or
            ``CMD_NAMES`` (e.g. ``"z"``, ``"x_ref"``, ``"u1"``), or of a flight on an estimator
            ``OBSERVATION_NAMES`` (``"x_est"``).

        Returns
        -------
        ndarray, shape (N, L)
            The column, in its SI unit (a view, not a copy).
        """
        tables = [(STATE_NAMES, self.states), (REF_NAMES, self.references), (CMD_NAMES, self.commands)]
        if self.observations is not None:
            tables.append((OBSERVATION_NAMES, self.observations))
        for names, arr in tables:
            if name in names:
                return arr[:, :, names.index(name)]
        known = ", ".join(n for names, _ in tables for n in names)
        raise InputError(f"unknown trace name {name!r}; known: {known}")

    def to_pandas(
        self, vehicle: int | None = None, *, references: bool = True, commands: bool = True, estimate: bool = True
    ):
        """The traces, long-form: one row per vehicle and logged instant (per-flight metrics: :meth:`metrics`).

        Parameters
        ----------
        vehicle : int, optional
            One vehicle's index; default: every vehicle.
        references : bool
            Include the reference columns.
        commands : bool
            Include the command columns.
        estimate : bool
            Include a flight's observation columns (``x_est`` ..., :data:`~quadcruise.layout.OBSERVATION_NAMES`),
            if it flew on an estimator.

        Returns
        -------
        pandas.DataFrame
            Columns ``vehicle``, ``t`` [s], the 16 state names, then (optionally) the
            reference and the command names; for a rotor-plant vehicle then its quaternion
            ``qw, qx, qy, qz`` and rotor speeds ``w1..wn`` [rad/s]; then, on an estimator, the
            estimate beside the truth (``x_est`` ...).
        """
        import pandas as pd

        picks = range(self.n) if vehicle is None else [vehicle]
        blocks = [self.states]
        names = list(STATE_NAMES)
        if references:
            blocks.append(self.references)
            names += REF_NAMES
        if commands:
            blocks.append(self.commands)
            names += CMD_NAMES
        if self.rotor_states is not None:
            extra = [j for j, name in enumerate(self.rotor_names) if name not in STATE_NAMES]
            blocks.append(self.rotor_states[:, :, extra])
            names += [self.rotor_names[j] for j in extra]
        if estimate and self.observations is not None:
            blocks.append(self.observations)
            names += OBSERVATION_NAMES
        data = np.concatenate(blocks, axis=2)[list(picks)]
        n_sel, n_log, _ = data.shape
        frame = pd.DataFrame(data.reshape(n_sel * n_log, -1), columns=names)
        frame.insert(0, "t", np.tile(self.t, n_sel))
        frame.insert(0, "vehicle", np.repeat(np.asarray(list(picks)), n_log))
        return frame

    def decimate(self, every: int) -> SimResult:
        """A result holding every ``every``-th logged instant (the end state stays exact).

        Parameters
        ----------
        every : int
            The step between the instants kept, >= 1.

        Returns
        -------
        SimResult
            With ``t``, ``states``, ``commands`` and ``references`` thinned; the rest shared.
        """
        if int(every) != every or every < 1:
            raise InputError(f"decimation step must be a positive integer, got {describe(every)}")
        keep = slice(None, None, int(every))
        return dataclasses.replace(
            self,
            t=self.t[keep],
            states=self.states[:, keep],
            commands=self.commands[:, keep],
            references=self.references[:, keep],
            rotor_states=None if self.rotor_states is None else self.rotor_states[:, keep],
            observations=None if self.observations is None else self.observations[:, keep],
        )

    def metrics(self, **kwargs):
        """Per-vehicle metrics as a DataFrame.

        Parameters
        ----------
        **kwargs
            Keywords of :func:`quadcruise.metrics.flight_metrics`: ``transient_axis``,
            ``transient_until``, and the conventions ``rise`` (``(0.1, 0.9)`` or
            ``(0.0, 1.0)``, ...) and ``settle_bands`` (``(0.02, 0.05)``, ...).

        Returns
        -------
        pandas.DataFrame
            One row per vehicle (see :func:`quadcruise.metrics.flight_metrics`); its
            ``attrs["conventions"]`` records the conventions.

        Examples
        --------
        >>> import quadcruise as qc
        >>> table = qc.fly("step", duration=4.0, log_every=10).metrics(rise=(0.0, 1.0), settle_bands=(0.02, 0.03))
        >>> [c for c in table.columns if c.startswith("settling")], table.attrs["conventions"]["rise"]
        (['settling_time_s', 'settling_time_3pct_s'], [0.0, 1.0])
        """
        from quadcruise.metrics.flight import flight_metrics

        return flight_metrics(self, **kwargs)

    def plot(self, vehicle: int = 0, **kwargs):
        """Figure of one vehicle's flight.

        Parameters
        ----------
        vehicle : int
            The vehicle's index.
        **kwargs
            Keywords of :func:`quadcruise.plots.plot_flight`.

        Returns
        -------
        matplotlib.figure.Figure
            See :func:`quadcruise.plots.plot_flight`.
        """
        from quadcruise.plots.flight import plot_flight

        return plot_flight(self, vehicle=vehicle, **kwargs)

    def to_ulog(self, path: str | os.PathLike, vehicle: int = 0, *, profile: str | None = None) -> Path:
        """Write one vehicle's flight as a PX4 log (ULog), in PX4's conventions (:mod:`quadcruise.sim.px4`).

        The topics are :func:`quadcruise.sim.px4.px4_topics`', at the rates of ``profile`` (at most
        the flight's log rate), with the setpoints PX4's viewers overlay
        (:mod:`quadcruise.sim.px4_setpoints`); pyulog, PX4 Flight Review and PlotJuggler read it.
        ``actuator_motors`` is each rotor's relative thrust, ``actuator_outputs`` the PWM signal
        through ``THR_MDL_FAC`` (PX4's meanings). The info messages ``quadcruise_control_rate_hz``
        and ``quadcruise_log_rate_hz`` give the controller's rate and the log's own (a flight
        logged every k-th period: the timestamps are those instants, and ``SDLOG_PROFILE`` does not
        claim the system-identification profile, which holds every command). A flight on sensor
        models adds their readings and its estimator's state and innovations, and its
        ``sensor_combined`` is the IMU model's (:mod:`quadcruise.sim.px4_estimator`).

        Parameters
        ----------
        path : str or os.PathLike
            The ``.ulg`` file, written whole or not at all.
        vehicle : int
            The vehicle's index.
        profile : {"default", "sysid"}, optional
            PX4's logging profile (:data:`quadcruise.sim.px4.PROFILES`): ``sysid`` writes the
            commands, rates, attitude and IMU at every logged instant, as a log to identify from
            needs (``quadcruise identify``); ``default`` at most at PX4's default rates. None:
            ``sysid`` for a flight of the ``sysid`` mission, else ``default``.

        Returns
        -------
        pathlib.Path
            The file written.

        Examples
        --------
        >>> import tempfile, quadcruise as qc
        >>> from pyulog import ULog
        >>> with tempfile.TemporaryDirectory() as folder:
        ...     log = ULog(str(qc.fly("hover", duration=1.0).to_ulog(Path(folder) / "hover.ulg")))
        >>> round(float(log.get_dataset("vehicle_local_position").data["z"][0]), 3)   # 1 m up: NED z = -1
        -1.0
        """
        from quadcruise._version import __version__
        from quadcruise.io.ulog import write_ulog
        from quadcruise.layout import CMD_PHI_D, CMD_U1
        from quadcruise.sim.px4 import (
            NOISE_STREAM,
            PROFILES,
            SYSID_PROFILE_BIT,
            duties_of,
            px4_topics,
            rotor_parameters,
        )
        from quadcruise.sim.px4_setpoints import pwm_parameters, setpoint_values

        if profile is None:
            profile = "sysid" if (self.meta.get("mission") or {}).get("kind") == "sysid" else "default"
        if profile not in PROFILES:
            raise InputError(f"to_ulog: profile must be one of {', '.join(PROFILES)}, got {profile!r}")
        rates_hz, profile_bits = PROFILES[profile]
        if isinstance(vehicle, bool) or not isinstance(vehicle, (int, np.integer)) or not 0 <= vehicle < self.n:
            raise InputError(f"to_ulog: vehicle must be an index in [0, {self.n}), got {describe(vehicle)}")
        if not str(path).endswith(".ulg"):
            raise InputError(f"to_ulog: a PX4 log's name ends in .ulg, got {str(path)!r}")
        rows = np.isfinite(self.states[vehicle]).all(axis=1)
        t, states, commands = self.t[rows], self.states[vehicle][rows], self.commands[vehicle][rows]

        def field_of(name, default):
            value = (self.meta.get("paper_equivalent") or self.meta.get("vehicle") or {}).get(name, default)
            return float(value[vehicle] if isinstance(value, (list, tuple, np.ndarray)) else value)

        sensors = self.meta.get("sensors") or {}
        std = np.zeros(states.shape[1])
        for key, first in (("position_std", 0), ("velocity_std", 3), ("angle_std", 6), ("rate_std", 9)):
            value = sensors.get(key, 0.0)
            std[first : first + 3] = value[vehicle] if isinstance(value, (list, tuple)) else value
        seed = self.meta.get("seed") or 0
        rng = np.random.default_rng([int(seed), int(vehicle), NOISE_STREAM])
        flown = self.meta.get("vehicle") or {}
        rotor_speeds, system_type = None, 2
        if self.rotor_states is not None and flown.get("plant") == "rotor":
            from quadcruise.model.rotor_plant import ROTOR_W1
            from quadcruise.sim.px4 import rotor_plant_parameters, rotor_speed_commands

            rotor_speeds = self.rotor_states[vehicle][rows][:, ROTOR_W1:]
            w_cmd, wanted = rotor_speed_commands(commands, flown, self.meta.get("controller_vehicle"), wanted=True)
            w_max, kf = float(flown["w_max"]), float(flown["kf"])
            signal, factor = w_cmd / w_max, 1.0  # thrust kf w^2 = CT x^2: THR_MDL_FAC 1
            desired = wanted / (kf * w_max**2)
            system_type = {6: 13, 8: 14}.get(rotor_speeds.shape[1], 2)
            params = rotor_plant_parameters(flown["rotors"], kf, float(flown["km"]), w_max)
        else:
            signal, factor = duties_of(commands), 0.0  # thrust K u: THR_MDL_FAC 0
            desired = commands[:, CMD_U1 : CMD_U1 + 4]
            params = rotor_parameters(field_of("l", 0.2), field_of("d", 0.0), field_of("K", 0.0))
        params.update(pwm_parameters(signal.shape[1], factor))
        setpoints = None
        if self.references is not None:
            attitude_d = commands[:, CMD_PHI_D : CMD_PHI_D + 3]
            setpoints = setpoint_values(self.references[vehicle][rows], attitude_d, desired, params)
        topics = px4_topics(
            t,
            states,
            signal,
            g=field_of("g", 9.81),
            thrust_factor=factor,
            noise_std=std,
            rng=rng,
            rates_hz=rates_hz,
            rotor_speeds=rotor_speeds,
            system_type=system_type,
            setpoints=setpoints,
        )
        if self.observations is not None and self.meta.get("sensor_models"):  # the sensors' own readings
            from quadcruise.layout import O_PHI
            from quadcruise.sim.px4 import attitude_ned_frd
            from quadcruise.sim.px4_estimator import estimator_topics

            obs = self.observations[vehicle][rows]
            euler = [np.nan_to_num(obs[:, O_PHI + j]) for j in range(3)]
            extra = estimator_topics(t, obs, self.meta["sensor_models"], attitude_ned_frd(*euler))
            replaced = {topic.name for topic in extra}
            topics = [topic for topic in topics if topic.name not in replaced] + extra
        info = {"sys_name": "quadcruise", "ver_sw": __version__, "ver_hw": "SIMULATION"}
        control_dt = float(self.meta.get("dt_s") or 0.0)
        log_dt = float(np.median(np.diff(t))) if len(t) > 1 else control_dt
        if control_dt > 0.0:  # the log's true rate: every command only when it logs every control period
            info["quadcruise_control_rate_hz"] = 1.0 / control_dt
            info["quadcruise_log_rate_hz"] = 1.0 / log_dt if log_dt > 0.0 else 0.0
            if log_dt > 1.000001 * control_dt:
                profile_bits &= ~SYSID_PROFILE_BIT
        params["SDLOG_PROFILE"] = profile_bits
        flown_px4 = self.meta.get("px4_parameters")  # the px4 controller's, as PX4 logs its own
        if flown_px4:
            from quadcruise.sim.px4 import controller_parameters

            kept, exact = controller_parameters(flown_px4)
            params.update(kept)
            info["quadcruise_px4_params"] = exact
        write_ulog(path, topics, info=info, parameters=params)
        return Path(path)

    def summary(self) -> Summary:
        """The headline numbers: vehicles by exit status, and the longest saturation times.

        Returns
        -------
        Summary
            Keys ``vehicles``, ``status`` (reason -> count), ``duty_clipped_s`` and
            ``controller_limited_s`` [s] (the most of any vehicle); prints as a few lines.

        Examples
        --------
        >>> import quadcruise as qc
        >>> s = qc.fly("hover", duration=0.5).summary()
        >>> s["status"]
        {'finished': 1}
        """
        reasons: dict[str, int] = {}
        for code in self.status:
            key = STATUS_REASONS[int(code)]
            reasons[key] = reasons.get(key, 0) + 1
        data = {
            "vehicles": self.n,
            "status": reasons,
            "duty_clipped_s": float(self.duty_clipped_s.max(initial=0.0)),
            "controller_limited_s": float(self.controller_limited_s.max(initial=0.0)),
        }
        lines = [f"{self.n:,} vehicle(s) over {float(self.t[-1]) if self.t.size else 0.0:g} s"]
        lines += [f"  {count:>8,}  {reason}" for reason, count in reasons.items()]
        lines.append(
            f"  {'rotor duties clipped' if self.rotor_states is None else 'rotor speed commands held'} for up to "
            f"{data['duty_clipped_s']:.3f} s; "
            f"controller limits active for up to {data['controller_limited_s']:.3f} s"
        )
        return Summary(data, "\n".join(lines))

    def write(self, out: str | os.PathLike, *, fmt: str = "csv", force: bool = False, metrics=None) -> Path:
        """Write the flight's folder, whole or not at all: the traces (``traces.csv`` or
        ``traces.parquet``), ``metrics.csv``, ``flight.png`` (and ``estimate.png`` after a flight
        on an estimator: :func:`~quadcruise.plots.estimate.plot_estimate`), the configuration
        (``quadcruise.json``: :attr:`meta`, and under ``metrics_conventions`` the conventions
        of the metrics written) and ``scenario.toml``, which ``quadcruise fly`` flies again to
        the same numbers (when the flight came from :func:`quadcruise.fly`).

        Parameters
        ----------
        out : str or path
            The folder. A non-empty folder that quadcruise did not write is refused unless ``force``.
        fmt : {"csv", "parquet"}
            Format of the traces.
        force : bool
            Replace a folder holding something else.
        metrics : pandas.DataFrame, optional
            :meth:`metrics` if already computed (saves computing them again), with the
            conventions it was computed with.

        Returns
        -------
        pathlib.Path
            The folder written.
        """
        from quadcruise.io.files import MARKER, atomic_dir, check_output_dir, check_table_format, write_table
        from quadcruise.metrics.estimate import flew_an_estimator
        from quadcruise.plots.flight import plot_flight, save_figure

        check_table_format(fmt)
        out = check_output_dir(out, force, inputs=[self.meta.get("scenario", {}).get("source")])
        metrics = self.metrics() if metrics is None else metrics
        with atomic_dir(out) as tmp:
            tmp = Path(tmp)
            write_table(self.to_pandas(), tmp / "traces", fmt)
            metrics.to_csv(tmp / "metrics.csv", index=False)
            save_figure(plot_flight(self), tmp / "flight.png")
            if flew_an_estimator(self):  # what the controller saw beside the truth
                from quadcruise.plots.estimate import plot_estimate

                save_figure(plot_estimate(self), tmp / "estimate.png")
            (tmp / MARKER).write_text(self.meta_json(metrics_conventions=metrics.attrs.get("conventions")) + "\n")
            if self.meta.get("workflow") == "fly" and "custom" not in (self.meta.get("environment") or {}):
                (tmp / "scenario.toml").write_text(self.scenario_toml())
        return out

    def scenario_toml(self) -> str:
        """The flight's configuration as a scenario file that ``quadcruise fly`` reads back.

        Returns
        -------
        str
            TOML: vehicle, controller and its gains, mission, disturbances, sensors, model
            error and simulation settings (see :mod:`quadcruise.io.scenario_file`).

        Examples
        --------
        >>> import quadcruise as qc
        >>> print(qc.fly("step", duration=2.0).scenario_toml().splitlines()[0])
        # written by quadcruise ... from a flight of nlpd on step; `quadcruise fly THIS_FILE` flies it again
        """
        from quadcruise.io.scenario_file import scenario_document, scenario_text, ulog_note

        scenario = self.meta.get("scenario") or {}
        doc = scenario_document(self.meta, title=scenario.get("title", ""))
        what = f"{self.meta.get('controller', {}).get('name', '?')} on {self.meta.get('mission', {}).get('kind', '?')}"
        header = (
            f"written by quadcruise {self.meta.get('version', '')} from a flight of {what}; "
            f"`quadcruise fly THIS_FILE` flies it again"
        )
        if self.meta.get("command_line"):
            header += "\nthe command line changed: " + " ".join(self.meta["command_line"])
        return scenario_text(doc, header=header + ulog_note(self.meta, "fly"))

    def meta_json(self, **extra) -> str:
        """The recorded configuration as JSON.

        Parameters
        ----------
        **extra
            More entries beside :attr:`meta` (None values are left out).

        Returns
        -------
        str
            :attr:`meta` (and ``extra``) as strict JSON, indented, keys sorted.
        """
        from quadcruise.io.plainjson import dumps

        return dumps({**self.meta, **{k: v for k, v in extra.items() if v is not None}}, indent=2, sort_keys=True)

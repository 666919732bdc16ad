"""What both plants' identification reads from a flight log before fitting: the rows fitted and
held out, the noise in the gyroscopic products, how the commands were logged, the log's facts
for the report; and the limits they are judged by (docs/identify.md).
"""

from __future__ import annotations

import math

import numpy as np

from quadcruise.io.flightlog import FlightLog

MIN_EXCITATION = 1e-3
"""The least excitation of an axis (:func:`_excitation`: the command combination's standard
deviation, relative to the mean command) for its parameters to be identifiable at all: below it,
whatever interval the residuals give reflects the absence of noise, not information."""
MIN_SIGNAL_SHARE = 0.99
"""The least share of a regressor's variance that must be signal, not noise, for its coefficient
to be identifiable (noise biases it toward zero, which the intervals do not cover; the bias
measured: docs/identify.md, "Known limitation")."""
SETTLE_TAUS = 6.0
"""Rotor time constants (of the base vehicle) left out at each segment's start, where the lag's
state is taken as settled on the first command (why 6: docs/identify.md, "Known limitation")."""
CAUTION_SHARE = 0.99
"""Below this share of signal (not jitter) in a moment command, the result carries a caution."""
MIN_FIT_S, MIN_HELD_S = 2.0, 0.5
"""The least airborne time fitted and held out [s] (after each segment's settling)."""
SYSID_PROFILE_BIT = 8
"""``SDLOG_PROFILE``'s bit for PX4's system-identification logging profile."""
STAGES = ("reading the log", "filtering", "fitting", "intervals", "validating")
"""The stages ``progress`` counts."""
WINDOW_S = 0.08
"""The Savitzky-Golay window [s] (at least 5 samples): about a third of the fastest rotor lag it
must pass (omega up to ~40 rad/s), and long enough to average gyro noise."""


def coupling_signal(flight: FlightLog, sig, rows: np.ndarray) -> dict[str, float]:
    """The share of the filtered gyroscopic products' variance that is not sensor noise.

    Each rate's white-noise level is read from its second differences (robust: median absolute
    deviation); the noise a product ``q r`` carries is ``E[q^2] s_r^2 + E[r^2] s_q^2 + s_q^2 s_r^2``,
    through the filter (times the sum of its squared weights)."""
    from quadcruise.sysid.equations import kernels

    noise = np.array([noise_level(flight.rates[:, j], flight.segment) for j in range(3)])
    gain = float(np.sum(kernels(sig.window, sig.dt)[1] ** 2))
    raw = flight.rates[rows]
    out = {}
    for name, (a, b), col in (("qr", (1, 2), 0), ("pr", (0, 2), 1)):
        noise_var = gain * (
            np.mean(raw[:, a] ** 2) * noise[b] ** 2
            + np.mean(raw[:, b] ** 2) * noise[a] ** 2
            + noise[a] ** 2 * noise[b] ** 2
        )
        total = float(np.var(sig.products[rows, col]))
        out[name] = max(0.0, 1.0 - noise_var / total) if total > 0 else 0.0
    return out


def noise_level(x: np.ndarray, segment: np.ndarray) -> float:
    """A white noise's standard deviation under a smooth signal: from second differences, robustly."""
    second = []
    for k in np.unique(segment):
        v = x[segment == k]
        second.append(v[2:] - 2 * v[1:-1] + v[:-2])
    d2 = np.concatenate(second)
    return 1.4826 * float(np.median(np.abs(d2 - np.median(d2)))) / np.sqrt(6.0)


def split_rows(flight: FlightLog, window: int, omega0: float, holdout: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows fitted and rows held out: the tail ``holdout`` of the samples is held out; each
    segment's first samples (the lag and filter settling) and last window are used by neither."""
    n = len(flight.t)
    dt = float(np.median(np.diff(flight.t)))
    settle = window + math.ceil(SETTLE_TAUS / (omega0 * dt))
    usable = np.zeros(n, bool)
    for k in np.unique(flight.segment):
        idx = np.flatnonzero(flight.segment == k)
        usable[idx[settle : len(idx) - window]] = True  # room for the doubled window too
    cut = round(n * (1.0 - holdout))
    fit_rows, held = usable.copy(), usable.copy()
    fit_rows[cut:] = False
    held[: cut + window] = False  # a window's gap: no filtered sample in both
    return fit_rows, held


def command_hold(flight: FlightLog, cmd_hz: float) -> str:
    """How the logged commands act between samples: ``"zero"`` (each held until the next) when
    the log holds every command its controller computed, else ``"linear"``.

    Every command is in the log when PX4's system-identification logging profile wrote it
    (``SDLOG_PROFILE`` bit :data:`SYSID_PROFILE_BIT`: the actuator commands at the rate the rate
    controller publishes them), or the log says its control rate (:func:`log_rates`) and the
    commands come at it, and the commands come at the rate of the grid (the body rates').
    A log that samples its commands more slowly (PX4's default profile) says only where they
    passed, and a line between the samples is the better guess.

    Parameters
    ----------
    flight : FlightLog
        The log read.
    cmd_hz : float
        The rate of its command topic [Hz].

    Returns
    -------
    {"zero", "linear"}

    Examples
    --------
    >>> log = FlightLog(source="x.ulg", t=np.arange(0.0, 1.0, 1e-3), segment=np.zeros(1000, int),
    ...                 u=np.zeros((1000, 4)), velocity=np.zeros((1000, 3)), quaternion=np.zeros((1000, 4)),
    ...                 rates=np.zeros((1000, 3)), parameters={"SDLOG_PROFILE": 9})
    >>> command_hold(log, 1000.0), command_hold(log, 250.0)
    ('zero', 'linear')
    """
    profile = int(flight.parameters.get("SDLOG_PROFILE", 0) or 0)
    grid_hz = 1.0 / float(np.median(np.diff(flight.t))) if len(flight.t) > 1 else 0.0
    control = log_rates(flight).get("quadcruise_control_rate_hz")
    every = profile & SYSID_PROFILE_BIT or (control is not None and cmd_hz >= 0.9 * float(control))
    return "zero" if every and cmd_hz >= 0.9 * grid_hz else "linear"


def command_rate(flight: FlightLog) -> float:
    """The rate [Hz] of the log's command topic (a CSV's rows).

    Parameters
    ----------
    flight : FlightLog
        The log read.

    Returns
    -------
    float
    """
    for key in ("actuator_motors", "actuator_outputs", "csv"):
        if key in flight.rates_hz and key in (flight.commands.split()[0], "csv"):
            return float(flight.rates_hz[key])
    return float(min(flight.rates_hz.values())) if flight.rates_hz else 0.0


def command_meaning(flight: FlightLog) -> tuple[str, float]:
    """What the logged commands ``u`` are, and the thrust curve that maps them to thrust.

    PX4's ``actuator_motors`` holds each motor's **relative thrust** (0-1): ``THR_MDL_FAC`` ``f`` acts
    after it, when the output module turns thrust into the signal ``x`` sent to the ESC,
    ``thrust = f x^2 + (1 - f) x`` (PX4 ``FunctionMotors::updateValues``, ``motor_params.c``). So
    ``actuator_motors`` is thrust (``("thrust", 0.0)``: linear), while ``actuator_outputs`` (PWM
    mapped to 0-1) and a CSV's ``u`` columns are the signal (``("signal", f)``, the log's
    ``THR_MDL_FAC``, else 0).

    Parameters
    ----------
    flight : FlightLog
        The log read.

    Returns
    -------
    tuple of (str, float)
        ``"thrust"`` or ``"signal"``, and ``f``.

    Examples
    --------
    >>> log = FlightLog(source="x.ulg", t=np.zeros(1), segment=np.zeros(1, int), u=np.zeros((1, 4)),
    ...                 velocity=np.zeros((1, 3)), quaternion=np.zeros((1, 4)), rates=np.zeros((1, 3)),
    ...                 parameters={"THR_MDL_FAC": 0.5}, commands="actuator_motors (normalised)")
    >>> command_meaning(log)
    ('thrust', 0.0)
    """
    f = float(flight.parameters.get("THR_MDL_FAC", 0.0) or 0.0)
    if flight.commands.split(" ")[0] == "actuator_motors" or "relative thrust" in flight.commands:
        return "thrust", 0.0  # (a reader that applied THR_MDL_FAC to actuator_outputs says so)
    return "signal", f


def log_rates(flight: FlightLog) -> dict:
    """What a ULog says of its own rates: ``IMU_GYRO_RATEMAX`` (PX4's rate loop runs on each gyro
    sample it publishes) and the information messages ``quadcruise_control_rate_hz`` and
    ``quadcruise_log_rate_hz`` (written by ``SimResult.to_ulog``); empty for a CSV.

    Parameters
    ----------
    flight : FlightLog
        The log read (its ``rate_info``, kept when it was read).

    Returns
    -------
    dict
    """
    return dict(flight.rate_info)


def log_info(flight: FlightLog, sig) -> dict:
    """What the report says of the log: source, airborne time, grid, topics' rates, geometry, parameters.

    Parameters
    ----------
    flight : FlightLog
        The log read.
    sig : Signals
        Its filtered signals (the grid's step).

    Returns
    -------
    dict
    """
    info = {
        "source": flight.source,
        "airborne_s": flight.duration,
        "segments": len(np.unique(flight.segment)),
        "samples": len(flight.t),
        "grid_hz": 1.0 / sig.dt,
        "commands": flight.commands,
        "resampling": flight.resampling,
        "topic_rates_hz": flight.rates_hz,
        "rotors": flight.n_rotors,
        "rotor_geometry": "log (CA_ROTOR*)" if flight.rotors is not None else "base vehicle ('+', arm l)",
        "parameters": flight.parameters,
    }
    if flight.hover_thrust is not None:
        info["px4_hover_thrust_estimate"] = float(np.median(flight.hover_thrust[1]))
    return info

"""``--sensors`` and ``--estimator``: the sensor models a vehicle carries and the filter between them
and the controller, from the command line's text (the scenario's ``[sensors]`` and ``[estimator]``
tables, :mod:`quadcruise.workflows.scenario_onboard`, read the same presets).

Examples
--------
>>> parse_sensors("imu=bmi088,gps,baro,mag").names()
('imu', 'gps', 'baro', 'mag')
>>> parse_estimator("ekf").latency_compensation
True
>>> parse_sensors("imu,lidar")
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: --sensors: unknown sensor 'lidar' (known: imu, gps, baro, mag)
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from quadcruise.errors import InputError

if TYPE_CHECKING:  # the estimator's modules load the engine: imported where a command needs them
    from quadcruise.estimation.stage import Ekf, Sensors

__all__ = ["onboard_options", "parse_estimator", "parse_sensors"]


def parse_sensors(text: str, option: str = "--sensors") -> Sensors:
    """The sensors of ``NAME[=PRESET],...`` (each preset ``typical`` when not given).

    Parameters
    ----------
    text : str
        E.g. ``imu,gps,baro,mag`` or ``imu=bmi088,gps``.
    option : str
        The option's name, for messages.

    Returns
    -------
    Sensors

    Raises
    ------
    InputError
        An empty list, an unknown sensor or preset, a sensor named twice.
    """
    from quadcruise.estimation.stage import PRESETS, SENSOR_NAMES
    from quadcruise.workflows.scenario_onboard import sensors_from_spec
    from quadcruise.workflows.scenario_values import Where

    spec: dict = {}
    for item in (part.strip() for part in text.split(",")):
        if not item:
            continue
        name, _, preset = (s.strip() for s in item.partition("="))
        if name not in SENSOR_NAMES:
            raise InputError(f"{option}: unknown sensor {name!r} (known: {', '.join(SENSOR_NAMES)})")
        if name in spec:
            raise InputError(f"{option}: sensor {name!r} named twice")
        preset = preset or "typical"
        if preset not in PRESETS[name]:
            raise InputError(f"{option}: unknown {name} preset {preset!r} (known: {', '.join(PRESETS[name])})")
        spec[name] = preset
    if not spec:
        raise InputError(f"{option}: no sensor named (known: {', '.join(SENSOR_NAMES)})")
    return sensors_from_spec(spec, Where(option))


def parse_estimator(text: str, option: str = "--estimator") -> Ekf | None:
    """The estimator of its name (:data:`~quadcruise.workflows.scenario_onboard.ESTIMATORS`).

    Parameters
    ----------
    text : str
        ``ekf`` or ``none``.
    option : str
        The option's name, for messages.

    Returns
    -------
    Ekf or None

    Raises
    ------
    InputError
        Another name.
    """
    from quadcruise.workflows.scenario_onboard import ESTIMATORS, estimator_from_spec
    from quadcruise.workflows.scenario_values import Where

    name = text.strip().lower()
    if name not in ESTIMATORS:
        raise InputError(f"{option}: unknown estimator {text!r} (known: {', '.join(ESTIMATORS)})")
    return estimator_from_spec({"kind": name}, Where(option))


def onboard_options(sensors_text: str | None, estimator_text: str | None, kwargs: dict) -> dict:
    """``fly``'s keywords with ``--sensors`` and ``--estimator`` applied (each replaces the
    scenario's), checked before any work: an estimator without the sensors it needs is refused.

    Parameters
    ----------
    sensors_text, estimator_text : str or None
        The options as given (None: not given).
    kwargs : dict
        :func:`quadcruise.fly`'s keywords so far (a scenario's ``sensors`` and ``estimator``).

    Returns
    -------
    dict
        ``kwargs`` with ``sensors`` and ``estimator`` set.

    Raises
    ------
    InputError
    """
    from quadcruise.estimation.stage import Sensors, check_estimator

    out = dict(kwargs)
    if sensors_text is not None:
        out["sensors"] = parse_sensors(sensors_text)
    if estimator_text is not None:
        out["estimator"] = parse_estimator(estimator_text)
        if out["estimator"] is None:
            out.pop("estimator")
    if out.get("estimator") is not None:
        sensors = out.get("sensors")
        check_estimator(sensors if isinstance(sensors, Sensors) else None, out["estimator"], "--estimator")
    return out

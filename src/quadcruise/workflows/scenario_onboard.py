"""A scenario's ``[sensors]`` and ``[estimator]`` tables (and ``fly --sensors``/``--estimator``,
which the command line turns into the same tables): the sensor models a vehicle carries, by
preset name and with any field changed, and the filter between them and the controller::

    [sensors]
    imu = "bmi088"                                  # a preset (quadcruise.estimation.stage.PRESETS)
    gps = { preset = "typical", latency = 0.2 }     # a preset with fields changed
    baro = { noise_std = 0.3 }                      # the typical preset with a field changed
    mag = "typical"

    [estimator]
    kind = "ekf"                                    # or "none": the sensors logged, the truth flown
    rate_cutoff = 30.0                              # any field of quadcruise.estimation.Ekf
    noise = { gyro_noise = 3e-4 }                   # the filter's own noise settings (EkfNoise)

Examples
--------
>>> sensors_from_spec({"imu": "bmi088", "gps": {"latency": 0.2}}).names()
('imu', 'gps')
>>> sensors_from_spec({"lidar": "typical"})
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: sensors: unknown key 'lidar' (known: baro, gps, imu, mag)
"""

from __future__ import annotations

import dataclasses

from quadcruise.errors import InputError
from quadcruise.estimation.run import EkfNoise
from quadcruise.estimation.stage import PRESETS, SENSOR_NAMES, Ekf, Sensors
from quadcruise.workflows.scenario_values import Where, check_keys

__all__ = ["ESTIMATORS", "estimator_from_spec", "sensors_from_spec"]

ESTIMATORS = ("ekf", "none")
"""The estimators by name: the error-state EKF, or none (the sensors logged, the truth flown)."""


def _model(where: Where, name: str, value):
    presets = PRESETS[name]
    if isinstance(value, str):
        if value not in presets:
            raise where.error(f"'{name}': unknown preset {value!r} (known: {', '.join(presets)})")
        return presets[value]
    if not isinstance(value, dict):
        raise where.error(f"'{name}' must be a preset's name or a table, e.g. {name} = {{ preset = \"typical\" }}")
    value = dict(value)
    preset = value.pop("preset", "typical")
    if preset not in presets:
        raise where.error(f"'{name}.preset': unknown preset {preset!r} (known: {', '.join(presets)})")
    base = presets[preset]
    check_keys(where, f"{name}.", value, {f.name for f in dataclasses.fields(base)})
    return where.wrap(dataclasses.replace, base, **value)


def sensors_from_spec(table: dict, where: Where | None = None) -> Sensors | None:
    """The sensors of a ``[sensors]`` table: each key a sensor's name, its value a preset's name
    or a table of fields (with an optional ``preset``, ``typical`` by default).

    Parameters
    ----------
    table : dict
        Sensor name -> preset name or table.
    where : Where, optional
        Where messages say the table is (the file and ``[sensors]``).

    Returns
    -------
    Sensors or None
        None for an empty table.

    Raises
    ------
    InputError
        An unknown sensor, preset or field, or a bad value (a negative noise density ...).
    """
    where = where or Where("sensors")
    if not isinstance(table, dict):
        raise where.error("must be a table")
    check_keys(where, "", table, set(SENSOR_NAMES))
    if not table:
        return None
    return where.wrap(Sensors, **{name: _model(where, name, value) for name, value in table.items()})


def estimator_from_spec(table: dict, where: Where | None = None) -> Ekf | None:
    """The estimator of an ``[estimator]`` table: ``kind`` (:data:`ESTIMATORS`), then the fields of
    :class:`~quadcruise.estimation.Ekf` (``noise`` a table of
    :class:`~quadcruise.estimation.EkfNoise`'s).

    Parameters
    ----------
    table : dict
        ``kind`` and the fields.
    where : Where, optional
        Where messages say the table is.

    Returns
    -------
    Ekf or None
        None for ``kind = "none"`` or an empty table.

    Raises
    ------
    InputError
        An unknown kind or field, or a bad value.

    Examples
    --------
    >>> estimator_from_spec({"kind": "ekf", "rate_cutoff": 30.0}).rate_cutoff
    30.0
    """
    where = where or Where("estimator")
    if not isinstance(table, dict):
        raise where.error("must be a table")
    if not table:
        return None
    table = dict(table)
    kind = table.pop("kind", None)
    if kind not in ESTIMATORS:
        raise where.error(f"'kind' must be one of {', '.join(ESTIMATORS)}, got {kind!r}")
    if kind == "none":
        if table:
            raise where.error(f'kind = "none" takes no other key, got {", ".join(table)}')
        return None
    check_keys(where, "", table, {f.name for f in dataclasses.fields(Ekf)})
    if "noise" in table:
        noise = table["noise"]
        if not isinstance(noise, dict):
            raise where.error("'noise' must be a table of the filter's noise settings")
        check_keys(where, "noise.", noise, {f.name for f in dataclasses.fields(EkfNoise)})
        table["noise"] = where.wrap(EkfNoise, **noise)
    return where.wrap(Ekf, **table)


def check_sensor_tables(where: Where, sensors: Sensors | None, noise) -> None:
    """Refuse ``[sensors]`` beside ``[disturbances] sensor_noise`` (the noise on the truth, which
    the sensors' estimate replaces).

    Parameters
    ----------
    where : Where
    sensors : Sensors or None
    noise : SensorNoise or None

    Raises
    ------
    InputError
    """
    if sensors is not None and noise is not None:
        raise InputError(
            f"{where.source}: [sensors] and [disturbances] sensor_noise: give one (the controller sees either the "
            "sensors' estimate or the truth with noise)"
        )

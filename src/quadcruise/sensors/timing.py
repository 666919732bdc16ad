"""When each sensor samples within the engine's control period: a sensor's period must be a
whole number of control periods (the engine steps at ``dt``), else it is refused in one line."""

from __future__ import annotations

from quadcruise.errors import InputError


def periods_per_sample(what: str, rate: float, dt: float) -> int:
    """How many control periods ``dt`` one sample of a sensor at ``rate`` spans.

    Parameters
    ----------
    what : str
        The sensor's name, for the message.
    rate : float
        Its sample rate [Hz], > 0.
    dt : float
        The control period [s], > 0.

    Returns
    -------
    int
        ``1 / (rate dt)``, a whole number >= 1.

    Raises
    ------
    InputError
        A rate above the control rate, or one whose period is not a whole number of ``dt``.

    Examples
    --------
    >>> periods_per_sample("gps", 10.0, 0.001)
    100
    >>> periods_per_sample("imu", 300.0, 0.001)
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: imu rate 300 Hz does not divide the control rate 1000 Hz
    """
    k = round(1.0 / (rate * dt))
    if k < 1 or abs(k * rate * dt - 1.0) > 1e-9:
        raise InputError(f"{what} rate {rate:g} Hz does not divide the control rate {1.0 / dt:g} Hz")
    return int(k)

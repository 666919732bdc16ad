"""The conventions of a metrics table: which rise-time levels and settling bands its columns
measure, how the second settling column is named, and what ``effort`` is. A table records them
in ``attrs["conventions"]`` (:func:`metric_conventions`), so that it says what it measured.

Examples
--------
>>> metric_conventions()["settling_columns"]
{'settling_time_s': 0.02, 'settling_time_5pct_s': 0.05}
"""

from __future__ import annotations

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError
from quadcruise.metrics.tracking import STEADY_BAND

__all__ = ["EFFORT_DEFINITION", "RISE_CONVENTIONS", "metric_conventions", "settling_column"]

EFFORT_DEFINITION = "integral of sum_i (u_i - u_hover)^2 dt over the four rotor duties, u_hover = m g / (4 K) [s]"
"""What the ``effort`` column measures, as the tables record it."""


def settling_column(band: float) -> str:
    """The name of the column of the settling time into ``band``, as a metrics table names its
    second band.

    Parameters
    ----------
    band : float
        The band, a fraction of the step (0.05 for 5 %).

    Returns
    -------
    str
        ``settling_time_<percent>pct_s``, the percent written with up to 6 significant digits
        and a ``p`` for the decimal point.

    Examples
    --------
    >>> settling_column(0.05), settling_column(0.03), settling_column(0.025)
    ('settling_time_5pct_s', 'settling_time_3pct_s', 'settling_time_2p5pct_s')
    """
    return f"settling_time_{format(100.0 * float(band), '.6g').replace('.', 'p')}pct_s"


RISE_CONVENTIONS = {"10-90": (0.1, 0.9), "0-100": (0.0, 1.0)}
"""The rise-time levels a name gives (``rise="0-100"``)."""


def metric_conventions(rise=(0.1, 0.9), settle_bands=(0.02, 0.05)) -> dict:
    """The conventions of a metrics table, checked: what its ``attrs["conventions"]`` records.

    Parameters
    ----------
    rise : (float, float) or {"10-90", "0-100"}
        Rise-time levels as fractions of the step: ``(0.1, 0.9)`` for 10-90 %, ``(0.0, 1.0)``
        for 0-100 %, or any ``0 <= low < high <= 1``; or one of :data:`RISE_CONVENTIONS`.
    settle_bands : float or sequence of one or two floats
        Settling bands as fractions of the step, each in (0, 1): the first is the
        ``settling_time_s`` column, the second (if only one is given: :data:`STEADY_BAND`,
        or 2 % when the first is that 5 %) the column :func:`settling_column` names; two
        equal bands are refused (they would print two identical columns).

    Returns
    -------
    dict
        ``rise`` and ``settle_bands`` (lists of two floats), ``settling_columns`` (column
        name -> band), ``steady_band`` (:data:`STEADY_BAND`) and ``effort``
        (:data:`EFFORT_DEFINITION`): plain values, ready for JSON.

    Raises
    ------
    InputError
        Levels or bands out of range, or not numbers.

    Examples
    --------
    >>> metric_conventions(rise="0-100", settle_bands=0.03)["settling_columns"]
    {'settling_time_s': 0.03, 'settling_time_5pct_s': 0.05}
    """
    if isinstance(rise, str):
        if rise not in RISE_CONVENTIONS:
            raise InputError(f"rise {rise!r}: choose one of {', '.join(RISE_CONVENTIONS)} or give two levels")
        rise = RISE_CONVENTIONS[rise]
    try:
        levels = tuple(float(v) for v in rise)
        bands = tuple(float(b) for b in np.atleast_1d(np.asarray(settle_bands, dtype=float)))
    except (TypeError, ValueError):
        raise InputError(
            f"rise levels and settle_bands must be numbers, got {describe(rise)}, {describe(settle_bands)}"
        ) from None
    if len(bands) == 1:  # the second column: 5 %, or 2 % beside a first 5 %
        bands = bands + ((0.02,) if bands[0] == STEADY_BAND else (STEADY_BAND,))
    if len(bands) == 2 and bands[0] == bands[1]:
        raise InputError(f"settle_bands: the two bands are the same ({bands[0]:g}): give two different bands, or one")
    if len(levels) != 2 or not 0.0 <= levels[0] < levels[1] <= 1.0:
        raise InputError(f"rise levels must satisfy 0 <= low < high <= 1, got {rise}")
    if len(bands) != 2 or not all(0.0 < b < 1.0 for b in bands):
        raise InputError(f"settle_bands must be one or two fractions in (0, 1), got {settle_bands}")
    return {
        "rise": list(levels),
        "settle_bands": list(bands),
        "settling_columns": {"settling_time_s": bands[0], settling_column(bands[1]): bands[1]},
        "steady_band": STEADY_BAND,
        "effort": EFFORT_DEFINITION,
    }

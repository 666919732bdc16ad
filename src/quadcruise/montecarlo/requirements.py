"""A user's own pass criteria for a Monte Carlo sweep: ``"metric<=value"`` and the like.

A requirement names one metric of the sweep's table (:data:`~quadcruise.montecarlo.schema.METRICS`),
a comparison (``<=``, ``<``, ``>=``, ``>``) and a number in the metric's unit. A flight meets
it if its value satisfies the comparison; an undefined value (NaN: a flight that stopped
early, a transient that never settled) does not meet it. A flight that misses any
requirement (and no earlier failure reason) fails as "failed a requirement".

Examples
--------
>>> req = Requirement.parse("steady_max_error_m <= 0.2")
>>> req.text, req.met(np.array([0.1, 0.3, np.nan])).tolist()
('steady_max_error_m<=0.2', [True, False, False])
>>> Requirement.parse("steady_max_error <= 0.2")      # doctest: +ELLIPSIS
Traceback (most recent call last):
    ...
quadcruise.errors.InputError: requirement 'steady_max_error <= 0.2': unknown metric 'steady_max_error'; choose ...
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from quadcruise.errors import InputError
from quadcruise.montecarlo.schema import METRICS

__all__ = ["Requirement", "parse_requirements"]

_OPERATORS = {"<=": operator.le, "<": operator.lt, ">=": operator.ge, ">": operator.gt}
_PATTERN = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(<=|>=|<|>)\s*([^<>=\s]+)\s*$")


@dataclass(frozen=True)
class Requirement:
    """One pass criterion: ``metric op value``.

    Parameters
    ----------
    metric : str
        A column of :data:`~quadcruise.montecarlo.schema.METRICS`.
    op : {"<=", "<", ">=", ">"}
        The comparison.
    value : float
        The bound, in the metric's unit.
    """

    metric: str
    op: str
    value: float

    @classmethod
    def parse(cls, text: str) -> Requirement:
        """A requirement from its text, ``"metric<=value"`` (spaces allowed).

        Parameters
        ----------
        text : str
            The requirement, e.g. ``"steady_max_error_m<=0.2"`` or ``"rmse_m < 0.5"``.

        Returns
        -------
        Requirement
            Checked: a known metric, one of the four comparisons, a finite number.

        Raises
        ------
        InputError
            One line naming the text and, for an unknown metric, the metrics available.
        """
        if not isinstance(text, str):
            raise InputError(f"a requirement is text such as 'steady_max_error_m<=0.2', got {text!r}")
        match = _PATTERN.match(text)
        if match is None:
            raise InputError(
                f"requirement {text!r}: expected METRIC<=VALUE (or <, >=, >), e.g. "
                f"steady_max_error_m<=0.2, with METRIC one of {', '.join(METRICS)}"
            )
        metric, op, number = match.groups()
        if metric not in METRICS:
            raise InputError(f"requirement {text!r}: unknown metric {metric!r}; choose one of {', '.join(METRICS)}")
        try:
            value = float(number)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise InputError(f"requirement {text!r}: {number!r} is not a finite number")
        return cls(metric, op, value)

    @property
    def text(self) -> str:
        """The requirement as text, without spaces: ``"steady_max_error_m<=0.2"``."""
        number = repr(self.value)
        return f"{self.metric}{self.op}{number[:-2] if number.endswith('.0') else number}"

    def met(self, values) -> np.ndarray:
        """Which values meet the requirement.

        Parameters
        ----------
        values : array_like
            Values of :attr:`metric`, one per flight.

        Returns
        -------
        ndarray of bool
            True where the value satisfies the comparison; False where it does not or is NaN.
        """
        v = np.asarray(values, dtype=float)
        with np.errstate(invalid="ignore"):
            return np.asarray(_OPERATORS[self.op](v, self.value), dtype=bool) & np.isfinite(v)


def parse_requirements(texts: str | Iterable[str] | None) -> tuple[Requirement, ...]:
    """Requirements from their texts, each checked.

    Parameters
    ----------
    texts : str, Requirement, iterable of them, or None
        One requirement, several, or none.

    Returns
    -------
    tuple of Requirement
        In the order given.

    Raises
    ------
    InputError
        For the first text that is not a requirement (see :meth:`Requirement.parse`).

    Examples
    --------
    >>> [r.text for r in parse_requirements(["rmse_m<0.5", "overshoot_pct <= 10"])]
    ['rmse_m<0.5', 'overshoot_pct<=10']
    """
    if texts is None:
        return ()
    if isinstance(texts, (str, Requirement)):
        texts = [texts]
    return tuple(t if isinstance(t, Requirement) else Requirement.parse(t) for t in texts)

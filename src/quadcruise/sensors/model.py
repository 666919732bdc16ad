"""What every sensor model shares: its parameters packed as one row, in its fields' order.

A sensor's compiled functions read that row at offsets unpacked from :meth:`SensorModel.layout`
(a :class:`quadcruise.layout.Row` of the dataclass's fields), so the fields, the packing and the
offsets are one declaration.

Examples
--------
>>> from quadcruise.sensors import Baro
>>> Baro.layout("B_").names, Baro(rate=10.0).row().tolist()
(('rate', 'noise_std', 'bias_init', 'drift'), [10.0, 0.1, 0.0, 0.0])
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from quadcruise.fields import Validated
from quadcruise.layout import Row


@dataclass(frozen=True)
class SensorModel(Validated):
    """A sensor's parameters (frozen, validated, with units): the base of each model."""

    name = "sensor"

    @classmethod
    def layout(cls, prefix: str) -> Row:
        """The row of the model's fields, in their order.

        Parameters
        ----------
        prefix : str
            The prefix of the offset constants (``"GPS_"``: ``GPS_RATE``, ...).

        Returns
        -------
        Row
        """
        return Row.of(cls.name, *(f.name for f in dataclasses.fields(cls)), prefix=prefix)

    def row(self) -> np.ndarray:
        """The parameters as the compiled functions take them (:meth:`layout`'s order).

        Returns
        -------
        numpy.ndarray
            float64, one entry a field.
        """
        return np.array([float(getattr(self, f.name)) for f in dataclasses.fields(self)])


__all__ = ["SensorModel"]

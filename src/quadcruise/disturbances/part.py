"""What the disturbance and sensor models share: fields that may hold one value per vehicle,
the batch size they imply, and ``to_dict``."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from quadcruise.errors import InputError
from quadcruise.fields import Validated, unit_field


def batch_field(*args: Any, **kw: Any):
    """A field with unit, doc and check (:func:`quadcruise.fields.unit_field`) that may hold one
    value per vehicle."""
    return unit_field(*args, batch=True, **kw)


@dataclass(frozen=True)
class Part(Validated):
    """A disturbance or sensor model: batch size and ``to_dict`` shared by the models;
    validation and ``units()`` come from :mod:`quadcruise.fields`. Each numeric field is a
    number or a 1-D array with one value per vehicle; a vector field is (x, y, z) of such, or
    an (N, 3) numpy array."""

    name = "part"

    def sizes(self) -> set:
        """Lengths of the per-vehicle arrays among the fields."""
        vals = [getattr(self, f.name) for f in dataclasses.fields(self)]
        return {u.shape[0] for v in vals for u in (v if isinstance(v, tuple) else (v,)) if isinstance(u, np.ndarray)}

    @staticmethod
    def one_size(sizes: set, what: str) -> int | None:
        """The one batch length among ``sizes`` (None if empty); InputError if they differ."""
        if len(sizes) > 1:
            raise InputError(f"{what} fields have different batch lengths {sorted(sizes)}")
        return next(iter(sizes), None)

    def to_dict(self) -> dict:
        """The model's name and fields as plain values (lists for arrays and vectors)."""

        def plain(v):
            return [plain(u) for u in v] if isinstance(v, tuple) else v.tolist() if isinstance(v, np.ndarray) else v

        return {"model": self.name, **{f.name: plain(getattr(self, f.name)) for f in dataclasses.fields(self)}}

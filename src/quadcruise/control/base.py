"""What every controller object offers the engine: a compiled function, its parameter
vector for a vehicle, and the size of its memory.

A controller is a frozen dataclass of gains with units; :meth:`Controller.gains` packs
them into the flat vector the compiled function reads. A user's own controller only needs
a function compiled with ``layout.CONTROLLER_SIG`` and these three members.
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar

import numpy as np


@dataclasses.dataclass(frozen=True)
class Controller:
    """Base class of the built-in controllers."""

    name: ClassVar[str] = "controller"
    memory_size: ClassVar[int] = 0

    @property
    def function(self):
        """The compiled function with ``CONTROLLER_SIG``."""
        raise NotImplementedError

    def gains(self) -> np.ndarray:
        """The flat float64 parameter vector of the compiled function."""
        raise NotImplementedError

    def memory(self) -> np.ndarray:
        """Initial memory: zeros."""
        return np.zeros(self.memory_size)

    def to_dict(self) -> dict[str, Any]:
        """Name and parameters, for result bundles."""
        out: dict[str, Any] = {"name": self.name}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            out[f.name] = dataclasses.asdict(value) if dataclasses.is_dataclass(value) else value
        return out

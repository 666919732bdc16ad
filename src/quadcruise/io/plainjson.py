"""What quadcruise records, as strict JSON.

Every document a command writes (``quadcruise.json``, ``metrics.json``, ``summary.json``,
``analysis.json``, a report's configuration) goes through :func:`plain`: numpy arrays and
numbers become lists and Python numbers, an undefined or infinite number (a settling time
that never came, an infinite gain margin) becomes ``null``, and an object with a
``to_dict()`` (a vehicle, a mission, a spec) or a dataclass becomes its fields. The output
is then valid JSON for any reader (``NaN`` is not).

>>> import numpy as np
>>> dumps({"t": np.float64(0.5), "settling_s": float("nan"), "x": np.arange(2)})
'{"t": 0.5, "settling_s": null, "x": [0, 1]}'
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import PurePath
from typing import Any

import numpy as np

__all__ = ["plain", "dumps"]


def plain(obj: Any) -> Any:
    """``obj`` as plain JSON values (see the module).

    Parameters
    ----------
    obj : Any
        Dicts (keys become strings), lists, tuples, numpy arrays and scalars, numbers,
        strings, None, paths, objects with a ``to_dict()`` and dataclass instances, nested.

    Returns
    -------
    Any
        Dicts, lists, str, int, float (finite), bool and None only.

    Raises
    ------
    TypeError
        For a value that has no JSON form.

    Examples
    --------
    >>> plain({1: (np.float32(0.5), float("inf"))})
    {'1': [0.5, None]}
    """
    if isinstance(obj, dict):
        return {str(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return plain(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if obj is None or isinstance(obj, str | int | float | bool):
        return obj
    if isinstance(obj, PurePath):
        return str(obj)
    if hasattr(obj, "to_dict"):
        return plain(obj.to_dict())
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return plain(dataclasses.asdict(obj))
    raise TypeError(f"cannot record {type(obj).__name__} as JSON")


def dumps(obj: Any, **kw: Any) -> str:
    """``json.dumps`` of :func:`plain` (strict: never NaN or Infinity).

    Parameters
    ----------
    obj : Any
        What to record (see :func:`plain`).
    **kw : Any
        Keywords of :func:`json.dumps` (``indent``, ``sort_keys``, ...).

    Returns
    -------
    str
        The JSON text.
    """
    return json.dumps(plain(obj), allow_nan=False, **kw)
